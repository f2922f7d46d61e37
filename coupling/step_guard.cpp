#include "coupling/step_guard.h"

#include <algorithm>
#include <cmath>
#include <sstream>

namespace meniscus::coupling {

namespace {

constexpr double CFL_MULTIPLE = 4.0;
constexpr double MIN_UNSTABLE_CELLS = 8.0;

}  // namespace

double unstable_motion_cells(double cfl_number) {
    return std::max(MIN_UNSTABLE_CELLS, CFL_MULTIPLE * cfl_number);
}

void check_surface_motion(const tracker::SurfaceMesh& mesh,
                          const std::vector<tracker::Vec3>& velocities, double dt, double dx,
                          double cfl_number) {
    if (velocities.size() != static_cast<std::size_t>(mesh.num_vertices()))
        throw std::invalid_argument("check_surface_motion: one velocity per vertex is needed");
    if (!(dt > 0.0) || !(dx > 0.0) || !(cfl_number > 0.0))
        throw std::invalid_argument("check_surface_motion: dt, dx and cfl_number must be positive");
    int fastest = -1;
    double top_speed = 0.0;
    for (int v = 0; v < mesh.num_vertices(); ++v) {
        if (!mesh.vertex_alive(v))
            continue;
        const double speed = velocities[static_cast<std::size_t>(v)].norm();
        if (std::isnan(speed)) {  // fails every comparison: it counts as the fastest
            fastest = v;
            top_speed = speed;
            break;
        }
        if (fastest < 0 || speed > top_speed) {
            fastest = v;
            top_speed = speed;
        }
    }
    const double limit = unstable_motion_cells(cfl_number);
    const double cells = top_speed * dt / dx;
    if (fastest < 0 || cells <= limit)
        return;
    const tracker::Vec3& x = mesh.position(fastest);
    std::ostringstream message;
    message << "the fluid step went unstable: a surface vertex at (" << x.x() << ", " << x.y()
            << ", " << x.z() << ") m would move " << cells << " cells (" << top_speed << " m/s for "
            << dt << " s), more than " << limit
            << " in one step; shorten the step (/fluid/cfl_number, "
               "/coupling/capillary_safety, or /coupling/implicit_tension off)";
    throw UnstableStep(message.str());
}

}  // namespace meniscus::coupling
