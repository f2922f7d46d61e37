#pragma once
/// \file The coupled step's guard against a fluid step that has gone unstable.
///
/// The time step is chosen from the velocities at its start (the CFL number bounds their motion
/// to cfl_number cells); the fluid step then sets the velocities the surface moves with. When
/// that step is unstable (a time step past what the scheme holds: far past the capillary limit,
/// or a CFL number the semi-implicit tension does not hold), a few vertices can come out at tens
/// of metres per second and cross many cells in one step. Left alone, the collision broad phase
/// then pairs nearly every element with every other (memory growing as the square of the mesh:
/// 24 GB at 128³ cells, found on `bubble_merge` with implicit tension at 4× and cfl_number 1.25).
/// The guard stops the step first, with the speed and where it happened.

#include <stdexcept>
#include <vector>

#include "tracker/mesh.h"

namespace meniscus::coupling {

/// Thrown by Simulation::step when the surface would move more than
/// unstable_motion_cells() cells in one step.
class UnstableStep : public std::runtime_error {
public:
    using std::runtime_error::runtime_error;
};

/// The motion in one step, in cells, above which a step counts as unstable: 4 × the CFL number,
/// at least 8 (a stable step moves the surface about cfl_number cells; merging and pinch-off
/// accelerate it within the step, by a few times at most).
double unstable_motion_cells(double cfl_number);

/// Throws UnstableStep when a live vertex of `mesh` moving at `velocities` (m/s, one per vertex)
/// for `dt` seconds would cross more than unstable_motion_cells(cfl_number) cells of edge `dx`;
/// the message names the speed, the distance in cells, the vertex's position and the keys that
/// set the step. Throws std::invalid_argument when the sizes do not match or dt, dx or
/// cfl_number is not positive.
void check_surface_motion(const tracker::SurfaceMesh& mesh,
                          const std::vector<tracker::Vec3>& velocities, double dt, double dx,
                          double cfl_number);

}  // namespace meniscus::coupling
