#include "fluid/forces.h"

namespace meniscus::fluid {

void apply_gravity(MacGrid& grid, const Eigen::Vector3d& gravity, double dt,
                   const BoundaryOptions& boundaries) {
    for (int axis = 0; axis < 3; ++axis) {
        const double increment = dt * gravity[axis];
        if (increment == 0.0) {
            continue;
        }
        Array3<double>& faces = grid.velocity(axis);
        const int n_axis = grid.cells(axis);
        // Outflow faces are momentum unknowns like interior ones, and so are both copies of a
        // periodic face; walls and inflows are fixed.
        const bool open_min =
            boundaries.at(axis, 0) == BoundaryType::outflow || boundaries.periodic(axis);
        const bool open_max =
            boundaries.at(axis, 1) == BoundaryType::outflow || boundaries.periodic(axis);
        for (int k = 0; k < faces.nk(); ++k) {
            for (int j = 0; j < faces.nj(); ++j) {
                for (int i = 0; i < faces.ni(); ++i) {
                    const int along = axis == 0 ? i : (axis == 1 ? j : k);
                    if ((along != 0 || open_min) && (along != n_axis || open_max)) {
                        faces(i, j, k) += increment;
                    }
                }
            }
        }
    }
}

}  // namespace meniscus::fluid
