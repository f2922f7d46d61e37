#pragma once
/// \file What a scene becomes before its first step: the initial surface (meshed from its shape
/// or read from its mesh file, checked, labelled), the tracker's options, and for a fluid scene
/// the coupled simulation (grid, fluid at rest but for the /initial_velocity regions).

#include "app/resource_estimate.h"
#include "app/scene.h"
#include "coupling/simulation.h"
#include "tracker/mesh.h"
#include "tracker/surface_tracker.h"

#include <string>

namespace meniscus::app {

/// Builds the initial surface of a scene (meshing its shape or loading and validating its mesh
/// file). Throws InputError naming the file and the failed check for a bad mesh file.
/// `nominal_xi` gets the tracker's ξ when the mesh was refined around creases (its mean edge
/// length before that refinement), else 0: measure it from the mesh.
tracker::SurfaceMesh build_initial_surface(const Scene& scene, std::string* report = nullptr,
                                           double* nominal_xi = nullptr);
/// Cells of the fluid grid along `axis`: /domain/cells along x, the /domain size over the cell
/// size (rounded, at least 1) along y and z. Throws InputError past MAX_CELLS_PER_AXIS.
int fluid_cells_along(const Scene& scene, int axis);
/// The box a fluid scene's surface wraps around (issue 39): along each axis whose
/// /fluid/boundaries are periodic, the grid's extent from /domain/min; none for other scenes.
tracker::MeshPeriods scene_periods(const Scene& scene);

/// The scene's tracker options with ξ set to `nominal_xi` unless the scene fixes it (or
/// `nominal_xi` is 0).
tracker::TrackerOptions tracker_options(const Scene& scene, double nominal_xi);

/// The initial surface of `meniscus run`, after every check that can be made before the large
/// allocations: the scene's scale, a surface that meets the fluid box, and the estimated memory
/// and steps per frame against `limits` (InputError naming the keys and the option to raise).
tracker::SurfaceMesh checked_initial_surface(const Scene& scene, const ResourceLimits& limits,
                                             std::string* report, double* nominal_xi);

/// The coupled simulation of a fluid scene from its initial surface (see below). On several
/// `ranks` (a run under mpirun) this rank's part of it: the grid split into slabs of z-layers
/// (fluid/slab_decomposition.h) with the ghost layers the fluid step needs, the mesh replicated.
coupling::Simulation make_fluid_simulation(
    const Scene& scene, tracker::SurfaceMesh initial, double nominal_xi,
    const fluid::RankCommunicator& ranks = fluid::RankCommunicator::self());

/// The coupled simulation of a fluid scene as `meniscus run` sets it up: the grid from /domain
/// (cubic cells, /domain/cells along x), the initial surface from /surface (build_initial_surface(),
/// whose `report` it passes on), the fluid at rest except for the /initial_velocity regions.
/// Throws what build_initial_surface() and the fluid solver throw.
coupling::Simulation make_fluid_simulation(const Scene& scene, std::string* report = nullptr);

}  // namespace meniscus::app
