#pragma once
/// \file What a run will need, estimated from the scene before anything large is allocated:
/// memory (fluid grid, meshing grid, surface mesh, VDB narrow band) and time steps per frame.
/// `meniscus run` refuses a scene above its limits (exit 2) with the scene keys that drive the
/// estimate and the option that raises the limit, instead of allocating until the machine runs
/// out or stepping for days. The estimates are deliberately rough (factors of ~2): they exist to
/// catch the orders of magnitude a typo or a unit mistake makes.

#include "app/scene.h"

#include <string>
#include <vector>

namespace meniscus::app {

/// Limits a run is checked against (command line: --max-memory, --max-steps-per-frame).
struct ResourceLimits {
    double max_memory_bytes = 0.0;           ///< 0 = default_max_memory_bytes()
    double max_steps_per_frame = 100000.0;   ///< estimated time steps in one frame
    /// MPI ranks the fluid grid is split over (mpirun): the memory estimate is one rank's, the
    /// largest (rank 0, which also gathers the grids the VDB files need).
    int ranks = 1;
};

/// Half the machine's physical memory (bytes): the default of --max-memory.
double default_max_memory_bytes();

/// One contribution to the memory estimate.
struct MemoryPart {
    std::string what;  ///< e.g. "fluid grid 36 x 24 x 24 cells (/domain)"
    double bytes = 0.0;
    bool while_meshing = false;  ///< needed while meshing the shape (freed before stepping)
};

/// The estimate of a run.
struct ResourceEstimate {
    std::vector<MemoryPart> memory;
    double initial_triangles = 0.0;  ///< of the initial surface
    double steps_per_frame = 0.0;
    /// What sets the step (e.g. "the capillary limit 1.2e-5 s (/fluid/phases)").
    std::string step_limit;
    double edge_length = 0.0;  ///< ξ of the initial surface (m)
    /// Largest motion of a vertex in one step (m) and what sets it: collision handling costs
    /// grow steeply with the motion per step in edge lengths.
    double step_motion = 0.0;
    std::string step_motion_keys;
    std::string step_motion_fix;  ///< what to change to make it shorter
    /// The program's own memory plus the larger of the parts needed while meshing and those
    /// needed while stepping.
    double memory_bytes() const;
};

/// The surface a run starts from, as far as it is known before the tracker is built: a shape's
/// area from its closed form (meshing at /surface/edge_length), or a loaded mesh's size.
struct SurfaceSize {
    double area = 0.0;              ///< m²
    double triangles = 0.0;         ///< 0: from the area and the edge length
    bool from_mesh_file = false;    ///< true: no meshing grid
    /// The initial surface's bounding box (empty: unknown); bounds the speed of a rigid flow.
    tracker::Box3 bounds;
};

/// The surface size of `scene` when it has a shape (from_mesh_file false).
SurfaceSize shape_surface_size(const Scene& scene);

/// Estimates memory and steps per frame of `scene` with `surface`; `frame_dt` is the time per
/// frame (s). On `ranks` MPI ranks the fluid grid's part is one rank's slab with its ghost
/// layers, plus, with VDB output, the whole grid's velocities and pressure gathered on rank 0.
ResourceEstimate estimate_resources(const Scene& scene, const SurfaceSize& surface, double frame_dt,
                                    int ranks = 1);

/// Throws InputError (exit 2) naming the scene file, the keys behind the estimate and the
/// option that raises the limit when `estimate` exceeds `limits`.
void check_resources(const Scene& scene, const ResourceEstimate& estimate,
                     const ResourceLimits& limits);

/// Checks that doubles can resolve the scene where it is: its coordinates must be below
/// 1e12 times the finest length it asks for (edge length, fluid cell), and the fluid grid's
/// derived cell counts must fit. Throws InputError naming the keys.
void check_scene_scale(const Scene& scene);

/// Things a scene may mean but that will not do what it seems to (printed as warnings before
/// the run): curl-noise octaves finer than the edge length `xi` (m) of the initial surface.
std::vector<std::string> plausibility_warnings(const Scene& scene, double xi);

/// "1.5 GB", "320 MB" (powers of 1000).
std::string format_bytes(double bytes);

}  // namespace meniscus::app
