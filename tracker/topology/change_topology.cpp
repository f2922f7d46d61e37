#include "tracker/topology/change_topology.h"

#include <chrono>

namespace meniscus::tracker {

TopologyReport change_topology(SurfaceMesh& mesh, const TopologyOptions& options,
                               const TopologyContext& context) {
    options.validate();
    context.validate();
    const auto start = std::chrono::steady_clock::now();
    TopologyReport report;
    if (options.allow_merging)
        report.merge = merge_proximal_edges(mesh, options, context);
    if (options.allow_separation)
        report.separation =
            separate(mesh, options.separation, context.collision_safety, context.xi);
    report.seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return report;
}

}  // namespace meniscus::tracker
