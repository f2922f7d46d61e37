#include "tracker/remesh/improve.h"

#include <chrono>

namespace meniscus::tracker {

namespace {

void accumulate(FlipReport& total, const FlipReport& r) {
    total.flips += r.flips;
    total.sweeps += r.sweeps;
    total.refused_existing_edge += r.refused_existing_edge;
    total.refused_volume += r.refused_volume;
    total.refused_normal += r.refused_normal;
    total.refused_intersection += r.refused_intersection;
    total.refused_point_in_tetrahedron += r.refused_point_in_tetrahedron;
    total.seconds += r.seconds;
}

}  // namespace

ImproveReport improve_mesh(SurfaceMesh& mesh, const RemeshOptions& options,
                           const ImproveContext& context) {
    options.validate();
    context.validate();
    const auto start = std::chrono::steady_clock::now();
    ImproveReport report;
    if (options.split)
        report.split = split_long_edges(mesh, options, context);
    if (options.flip)
        accumulate(report.flip, flip_edges(mesh, options, context));
    if (options.collapse)
        report.collapse = collapse_short_edges(mesh, options, context);
    if (context.allow_topology_changes)
        report.separation =
            separate(mesh, context.separation, context.collision_safety, context.xi);
    if (options.flip && options.collapse)
        accumulate(report.flip, flip_edges(mesh, options, context));
    if (options.smooth && options.smoothing_iterations > 0)
        report.smooth = smooth_null_space(mesh, options, context);
    report.seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return report;
}

}  // namespace meniscus::tracker
