#include "tracker/remesh/improve.h"

#include <chrono>

namespace meniscus::tracker {

ImproveReport improve_mesh(SurfaceMesh& mesh, const RemeshOptions& options,
                           const ImproveContext& context) {
    options.validate();
    context.validate();
    const auto start = std::chrono::steady_clock::now();
    ImproveReport report;
    // Smoothing first, so that the length-driven operations have the last word: the mesh leaves
    // with every splittable edge ≤ α and every collapsible edge ≥ β unless a collapse was
    // refused. (The paper lists smoothing last; within a time loop the cycle is the same.)
    if (options.smooth && options.smoothing_iterations > 0)
        report.smooth = smooth_null_space(mesh, options, context);
    if (options.split)
        report.split = split_long_edges(mesh, options, context);
    if (options.flip)
        report.flip = flip_edges(mesh, options, context);
    if (options.collapse)
        report.collapse = collapse_short_edges(mesh, options, context);
    if (context.allow_topology_changes)
        report.separation =
            separate(mesh, context.separation, context.collision_safety, context.xi);
    report.seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return report;
}

}  // namespace meniscus::tracker
