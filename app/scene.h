#pragma once
/// \file Scene files: JSON (SI units) read into options structs. Every key has its default in
/// the struct below and nowhere else; `meniscus scene-reference` prints them all.

#include "common/cancellation.h"
#include "coupling/simulation.h"
#include "fluid/fluid_solver.h"
#include "tracker/flows/curl_noise.h"
#include "tracker/flows/face_offsetting.h"
#include "tracker/flows/flow_errors.h"
#include "tracker/flows/mean_curvature.h"
#include "tracker/flows/velocity_field.h"
#include "tracker/implicit_mesher.h"
#include "tracker/implicit_shape.h"
#include "tracker/surface_tracker.h"

#include <Eigen/Core>

#include <string>

namespace meniscus::app {

/// Where the initial surface comes from: an implicit shape tree or a mesh file.
struct SurfaceOptions {
    double edge_length = 0.02;  ///< requested mean edge length ξ of the generated mesh (m)
    std::string mesh_file;      ///< OBJ/PLY path, relative to the scene file (instead of shape)
    int remesh_iterations = 8;  ///< isotropic remeshing passes when meshing a shape
    tracker::CreaseRefinementOptions crease;  ///< refinement around the shape's creases
    /// Which phase the shape encloses: "liquid" (drops, pools: region labels {1, 0}) or "gas"
    /// (bubbles in a liquid that fills the rest: labels {0, 1}).
    std::string inside = "liquid";
    /// The mesh_file is an open surface (paper §4.4): boundary edges are allowed (and never
    /// split, flipped, collapsed or merged). Geometric flows only; implicit shapes are closed.
    bool open = false;
};

/// Motion in the normal direction (paper §4.1, docs/validation.md A1).
struct NormalSpeedOptions {
    /// "face_offsetting" (Jiao's entropy-satisfying scheme) or "vertex_normals" (area-weighted
    /// vertex normals; the paper's non-converging comparison).
    std::string method = "face_offsetting";
    double speed = 0.2;  ///< along the outward normal (m/s; negative shrinks)
    /// The speed flips sign at this time (s): +speed before, −speed from then on (A1: 1 s).
    /// 0 = never reverses.
    double reversal_time = 0.0;
    tracker::FaceOffsettingOptions face_offsetting;  ///< used by method face_offsetting
    tracker::InversionLimitOptions inversion;        ///< step limit of both methods
};

/// An exact solution to measure the surface against at every frame (docs/validation.md A1, A2).
struct ExactSolutionOptions {
    /// "none", "two_sphere_normal_flow" (A1: two balls of `radius` around `center0`/`center1`
    /// under /flow/normal_speed with speed > 0; the exact entropy solution of
    /// tracker::TwoSphereNormalFlow), "sphere_mean_curvature" (a ball of `radius` around
    /// `center0` under mean-curvature flow: R(t) = sqrt(R₀² − 4t)) or "rigid_motion" (under
    /// /flow/type rigid, the initial surface carried by the exact rigid map; any shape).
    std::string type = "none";
    Eigen::Vector3d center0 = Eigen::Vector3d(-0.25, 0.0, 0.0);  ///< m
    Eigen::Vector3d center1 = Eigen::Vector3d(0.25, 0.0, 0.0);   ///< m (two spheres only)
    double radius = 0.2;                                         ///< initial radius (m)
    /// Surface error sampling (tracker::surface_error): m² samples per triangle.
    tracker::SurfaceErrorOptions sampling;
};

/// The motion that drives the surface: the coupled fluid or one of the paper's geometric flows
/// (§4).
struct FlowOptions {
    /// "fluid" (the coupled Navier–Stokes solver moves the surface), "enright" (paper §4.3),
    /// "normal_speed" (§4.1), "mean_curvature" (§4.2), "curl_noise" (§4.3), "rigid" (rotation
    /// and translation), "expression" (a user's analytic field) or "none" (the surface stays
    /// still).
    std::string type = "enright";
    double period = 3.0;  ///< Enright period T: velocity modulated by sin(2πt/T) (s)
    NormalSpeedOptions normal_speed;
    tracker::MeanCurvatureFlowOptions mean_curvature;
    tracker::CurlNoiseOptions curl_noise;
    tracker::RigidMotionOptions rigid;
    tracker::ExpressionFieldOptions expression;
    ExactSolutionOptions exact;
};

/// The fluid's box: cubic cells, `cells` of them along x.
struct DomainOptions {
    Eigen::Vector3d min = Eigen::Vector3d::Zero();           ///< min corner (m)
    Eigen::Vector3d size = Eigen::Vector3d::Constant(0.01);  ///< edge lengths (m)
    int cells = 32;  ///< cells along x; dx = size.x / cells, other axes rounded to whole cells
};

/// Scene-level coupling choices beside the library's SimulationOptions.
struct CouplingOptions {
    /// Tracker target edge length in grid cells: when > 0, /surface/edge_length becomes
    /// edge_length_cells · dx.
    double edge_length_cells = 1.0;
    coupling::SimulationOptions simulation;
};

/// A region of the initial flow that moves with a given velocity: every velocity face whose
/// centre lies inside `shape` gets that component of `velocity` (later regions win).
struct VelocityRegion {
    tracker::ShapePtr shape;
    Eigen::Vector3d velocity = Eigen::Vector3d::Zero();  ///< m/s
};

/// Simulated time and frames.
struct TimeOptions {
    double end = 3.0;  ///< simulated end time (s)
    int frames = 30;   ///< frames written after the initial one, evenly spaced in time
    double dt = 0.01;  ///< maximum time step (s); steps are shortened to land on frame times
    /// Geometric flows: false lets steps run past frame times (a frame is then written after
    /// the first step that reaches its time, at that step's time), so the sequence of steps
    /// is the one `meniscus validate` takes; the end time is still hit exactly.
    bool land_on_frames = true;
};

/// What is written every frame (README "Output"; the run's meniscus.json describes it).
struct OutputOptions {
    bool ply = true;                 ///< surface_NNNN.ply (binary little-endian)
    bool ply_velocity = true;        ///< per-vertex velocity (vx, vy, vz) in the PLY
    bool obj = false;                ///< surface_NNNN.obj as well
    bool vdb = true;                 ///< fields_NNNN.vdb with `surface` and `density`
    double voxel_size = 0.0;         ///< VDB voxel size (m); 0 = half the surface edge length
    double half_width_voxels = 3.0;  ///< narrow-band half width of `surface` (voxels)
    double density_ramp_voxels = 2.0;  ///< width of `density`'s step across the surface (voxels)
    bool vdb_velocity = true;          ///< fluid scenes: grid `vel` in the VDB
    bool vdb_pressure = true;          ///< fluid scenes: grid `pressure` in the VDB
    /// Unit of every length written (PLY and OBJ positions, velocities, VDB transforms and
    /// distances): "m", "cm" or "mm". Millimetres by default: Blender's Cycles renders the
    /// shipped fluid scenes' ~0.1 mm voxels only when they are not ~1e-4 units small.
    std::string length_unit = "mm";
    /// Write the run's checkpoint (checkpoint.bin, for `meniscus run --resume`) with every Nth
    /// frame and the last; 0 = never.
    int checkpoint_every = 1;
};

/// A whole scene.
struct Scene {
    std::string name = "scene";
    std::string description;
    SurfaceOptions surface;
    tracker::ShapePtr shape;  ///< set when the scene gives /surface/shape
    tracker::TrackerOptions tracker;
    FlowOptions flow;
    DomainOptions domain;
    fluid::FluidOptions fluid;
    CouplingOptions coupling;
    std::vector<VelocityRegion> initial_velocity;
    TimeOptions time;
    OutputOptions output;
    std::string source_path;  ///< the file it was read from
    std::string source_text;  ///< its text (a checkpoint keeps it; a resume compares it)
    /// Stops meshing and stepping (set by run_scene() from its stop flag; never by the file).
    CancellationToken cancel;
};

/// Reads and validates a scene file. Throws SceneError ("<file>: <json path>: <problem>") for
/// unreadable files, JSON syntax errors, unknown keys, wrong types and out-of-range values.
Scene load_scene(const std::string& path);
/// Parses a scene from JSON text; `source` names it in errors, `base_dir` resolves mesh_file.
Scene parse_scene(const std::string& json_text, const std::string& source,
                  const std::string& base_dir);
/// The A1 exact solution a scene with /flow/exact/type two_sphere_normal_flow describes: its
/// spheres, /flow/normal_speed/speed, and the reversal time (`end_time` when the speed never
/// reverses, so the balls grow throughout a run ending then).
tracker::TwoSphereNormalFlow two_sphere_normal_flow(const Scene& scene, double end_time);
/// Markdown reference of every scene key: type, default, unit, meaning.
std::string scene_reference_markdown();

}  // namespace meniscus::app
