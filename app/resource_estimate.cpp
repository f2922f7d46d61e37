#include "app/resource_estimate.h"

#include "fluid/fluid_solver.h"

#include "app/errors.h"

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <sstream>

namespace meniscus::app {

namespace {

// Bytes per element: peak resident memory above the program's own ~50 MB, measured on large
// cases (a drop_merge grid of 128 x 85 x 85 cells: 450 MB; a sphere meshed into 280 000
// triangles: 1.0 GB while meshing, 630 MB while stepping; a VDB band of 1.9e7 voxels: 800 MB)
// and rounded up by about a fifth.
/// The program itself: libraries, thread pools, the scene.
constexpr double PROGRAM_BYTES = 60e6;
/// Fluid scenes, per grid cell: velocities and their advection copies, pressure, φ, the
/// Poisson and viscosity systems, PCG and multigrid vectors, the rasterized band.
constexpr double FLUID_BYTES_PER_CELL = 600.0;
/// Per triangle of the surface: mesh connectivity, broad phase, remeshing and collision work.
constexpr double TRACKER_BYTES_PER_TRIANGLE = 2500.0;
/// Meshing a shape: φ at every node of the marching grid (spacing 0.7 ξ).
constexpr double MESHING_BYTES_PER_NODE = 8.0;
constexpr double MESHING_SPACING_FRACTION = 0.7;
/// Per triangle of the raw marching-tetrahedra surface (about 4 per spacing² of area): the
/// mesh with its adjacency, the crossing table and the isotropic remesher's work.
constexpr double MESHING_BYTES_PER_RAW_TRIANGLE = 800.0;
constexpr double RAW_TRIANGLES_PER_SPACING_SQUARED = 4.0;
/// Per active voxel of the VDB narrow band: meshToLevelSet's distance and index grids and the
/// density copy.
constexpr double VDB_BYTES_PER_VOXEL = 50.0;
/// Dense fluid grids in the VDB (vel, pressure) per cell.
constexpr double VDB_BYTES_PER_FLUID_CELL = 40.0;
/// Triangles of a mesh with mean edge length ξ per m² of surface: 1 / (√3/4 ξ²).
constexpr double EQUILATERAL_AREA_FACTOR = 0.4330127018922193;
/// Motion per step beyond this many edge lengths makes collision handling's candidate sets
/// explode (A1's two spheres at ξ = 0.01: 2 steps of 1 ξ take 1 s, of 10 ξ 37 s, of 30 ξ 245 s;
/// the shipped scenes move at most 2.5 ξ per step, Enright).
constexpr double MAX_STEP_MOTION_EDGES = 5.0;
/// Peak over mean speed of the flows without a closed-form maximum.
constexpr double ENRIGHT_MAX_SPEED = 2.45;  ///< |u| ≤ sqrt(2² + 1 + 1) on the unit cube
constexpr double CURL_NOISE_PEAK_OVER_RMS = 4.0;
/// Doubles resolve a length ℓ at coordinates up to about ℓ · 1e12 with room for the exact
/// predicates and differences of nearby positions.
constexpr double MAX_COORDINATE_TO_LENGTH = 1e12;
/// The fluid solver stores cell counts as int and indexes arrays with int products.
constexpr double MAX_CELLS_PER_AXIS = 1 << 20;

double domain_dx(const Scene& scene) {
    return scene.domain.size.x() / scene.domain.cells;
}

/// Cells along each axis as make_fluid_simulation() rounds them (in double: no overflow).
Eigen::Vector3d domain_cells(const Scene& scene) {
    const double dx = domain_dx(scene);
    return Eigen::Vector3d(scene.domain.cells, std::max(1.0, std::round(scene.domain.size.y() / dx)),
                           std::max(1.0, std::round(scene.domain.size.z() / dx)));
}

std::string format_number(double v) {
    char text[32];
    std::snprintf(text, sizeof text, "%.3g", v);
    return text;
}

double vdb_voxel_size(const Scene& scene) {
    return scene.output.voxel_size > 0.0 ? scene.output.voxel_size
                                         : 0.5 * scene.surface.edge_length;
}

/// How /surface/edge_length came about, for messages.
std::string edge_length_origin(const Scene& scene) {
    if (scene.flow.type == "fluid" && scene.coupling.edge_length_cells > 0.0)
        return "/surface/edge_length = /coupling/edge_length_cells x the cell size of /domain = " +
               format_number(scene.surface.edge_length) + " m";
    return "/surface/edge_length " + format_number(scene.surface.edge_length) + " m";
}

}  // namespace

double default_max_memory_bytes() {
    const long pages = sysconf(_SC_PHYS_PAGES), page_size = sysconf(_SC_PAGE_SIZE);
    if (pages <= 0 || page_size <= 0)
        return 4e9;
    return 0.5 * static_cast<double>(pages) * static_cast<double>(page_size);
}

double ResourceEstimate::memory_bytes() const {
    double meshing = 0.0, running = 0.0;
    for (const MemoryPart& p : memory)
        (p.while_meshing ? meshing : running) += p.bytes;
    return PROGRAM_BYTES + std::max(meshing, running);
}

std::string format_bytes(double bytes) {
    const char* units[] = {"bytes", "kB", "MB", "GB", "TB", "PB"};
    int u = 0;
    while (bytes >= 1000.0 && u < 5 && std::isfinite(bytes)) {
        bytes /= 1000.0;
        ++u;
    }
    if (!std::isfinite(bytes))
        return "more than can be counted";
    return format_number(bytes) + " " + units[u];
}

SurfaceSize shape_surface_size(const Scene& scene) {
    SurfaceSize s;
    if (scene.shape) {
        constexpr double INF = std::numeric_limits<double>::infinity();
        s.area = scene.shape->surface_area(
            tracker::Box3(Eigen::Vector3d::Constant(-INF), Eigen::Vector3d::Constant(INF)));
    }
    return s;
}

ResourceEstimate estimate_resources(const Scene& scene, const SurfaceSize& surface, double frame_dt,
                                    int ranks) {
    ResourceEstimate e;
    const double xi = scene.surface.edge_length;
    e.initial_triangles = surface.triangles > 0.0
                              ? surface.triangles
                              : surface.area / (EQUILATERAL_AREA_FACTOR * xi * xi);
    e.edge_length = scene.tracker.characteristic_length > 0.0 ? scene.tracker.characteristic_length
                    : surface.from_mesh_file && surface.triangles > 0.0
                        ? std::sqrt(surface.area / (EQUILATERAL_AREA_FACTOR * surface.triangles))
                        : xi;
    const std::string surface_keys =
        surface.from_mesh_file ? "/surface/mesh_file" : "/surface/shape, " + edge_length_origin(scene);
    e.memory.push_back({"surface mesh of about " + format_number(e.initial_triangles) +
                            " triangles (" + surface_keys + ")",
                        e.initial_triangles * TRACKER_BYTES_PER_TRIANGLE});

    if (!surface.from_mesh_file && scene.shape) {
        const double h = MESHING_SPACING_FRACTION * xi;
        const tracker::Box3 b = scene.shape->bounds();
        double nodes = 1.0;
        for (int i = 0; i < 3; ++i)
            nodes *= std::ceil(b.sizes()[i] / h) + 5.0;
        const double raw = RAW_TRIANGLES_PER_SPACING_SQUARED * surface.area / (h * h);
        e.memory.push_back({"meshing grid of " + format_number(nodes) + " nodes (the bounds of "
                                "/surface/shape at " + edge_length_origin(scene) + ")",
                            nodes * MESHING_BYTES_PER_NODE + raw * MESHING_BYTES_PER_RAW_TRIANGLE,
                            true});
    }

    if (scene.output.vdb) {
        const double voxel = vdb_voxel_size(scene);
        const double voxels = surface.area * 2.0 * scene.output.half_width_voxels / (voxel * voxel);
        e.memory.push_back({"VDB narrow band of about " + format_number(voxels) +
                                " voxels (/output/voxel_size " + format_number(voxel) +
                                " m, /output/half_width_voxels " +
                                format_number(scene.output.half_width_voxels) + ")",
                            voxels * VDB_BYTES_PER_VOXEL});
    }

    if (scene.flow.type == "fluid") {
        const Eigen::Vector3d n = domain_cells(scene);
        const double cells = n.prod();
        if (ranks > 1) {
            // One rank's slab of z-layers with its ghost layers (at most 2 × 5 with MacCormack at
            // CFL 1; fluid::FluidSolver::ghost_layers_needed()), and on rank 0 the whole grid's
            // velocities and pressure gathered for the VDB (4 doubles per cell).
            const double layers =
                std::min(n.z(), std::ceil(n.z() / ranks) +
                                    2.0 * fluid::FluidSolver::ghost_layers_needed(scene.fluid));
            const double rank_cells = n.x() * n.y() * layers;
            e.memory.push_back(
                {"one of " + std::to_string(ranks) + " MPI ranks' slab of the fluid grid of " +
                     format_number(n.x()) + " x " + format_number(n.y()) + " x " +
                     format_number(n.z()) + " cells (/domain): " + format_number(layers) +
                     " z-layers",
                 rank_cells * FLUID_BYTES_PER_CELL +
                     (scene.output.vdb ? cells * (VDB_BYTES_PER_FLUID_CELL + 32.0) : 0.0)});
        } else {
            e.memory.push_back({"fluid grid of " + format_number(n.x()) + " x " +
                                    format_number(n.y()) + " x " + format_number(n.z()) +
                                    " cells (/domain)",
                                cells * FLUID_BYTES_PER_CELL +
                                    (scene.output.vdb ? cells * VDB_BYTES_PER_FLUID_CELL : 0.0)});
        }
        // Steps: dt = min(max_dt, capillary, CFL) (coupling::Simulation::step), the capillary
        // limit with the smaller of dx and the edge length, the CFL limit with the initial speed
        // plus what gravity adds over the frame.
        const fluid::PhaseOptions& p = scene.fluid.phases;
        const double dx = domain_dx(scene);
        const double h = std::min(dx, xi);
        const double rho_mean = scene.fluid.mode == fluid::FluidMode::two_phase
                                    ? 0.5 * (p.rho_liquid + p.rho_gas)
                                    : 0.5 * p.rho_liquid;
        double dt = scene.fluid.time_step.max_dt;
        e.step_limit = "/fluid/max_dt " + format_number(dt) + " s";
        if (p.sigma > 0.0) {
            const double capillary = scene.coupling.simulation.capillary_safety *
                                     std::sqrt(rho_mean * h * h * h / (2.0 * M_PI * p.sigma));
            if (!(capillary >= dt)) {
                dt = capillary;
                e.step_limit = "the capillary limit sqrt(rho h^3 / (2 pi sigma)) = " +
                               format_number(capillary) +
                               " s (/fluid/phases: rho_liquid, rho_gas, sigma; h = " +
                               format_number(h) + " m from /domain and /surface/edge_length)";
            }
        }
        double speed = 0.0;
        for (const VelocityRegion& r : scene.initial_velocity)
            speed = std::max(speed, r.velocity.norm());
        const double gravity = scene.fluid.gravity.norm();
        // CFL steps over the frame: ∫ (speed + g t) / (cfl dx) dt.
        const double cfl_steps = frame_dt * (speed + 0.5 * gravity * frame_dt) /
                                 (scene.fluid.time_step.cfl_number * dx);
        const double fixed_steps = frame_dt / dt;
        e.steps_per_frame = fixed_steps + cfl_steps;
        e.step_motion = scene.fluid.time_step.cfl_number * dx;
        e.step_motion_keys = "/fluid/cfl_number " + format_number(scene.fluid.time_step.cfl_number) +
                             " cells of " + format_number(dx) + " m (/domain)";
        e.step_motion_fix = "lower /fluid/cfl_number";
        if (!(cfl_steps <= fixed_steps))
            e.step_limit = "the CFL limit with /initial_velocity (up to " + format_number(speed) +
                           " m/s) and /fluid/gravity (" + format_number(gravity) +
                           " m/s^2) in cells of " + format_number(dx) +
                           " m (/domain), /fluid/cfl_number " +
                           format_number(scene.fluid.time_step.cfl_number);
    } else {
        double dt = scene.time.dt;
        e.step_limit = "/time/dt " + format_number(dt) + " s";
        if (scene.flow.type == "mean_curvature") {
            // Step ≤ cfl_number · (shortest edge)², edges down to β = min_edge_fraction · ξ.
            const double beta = scene.tracker.remesh.min_edge_fraction * xi;
            const double cfl = scene.flow.mean_curvature.cfl_number * beta * beta;
            if (cfl < dt) {
                dt = cfl;
                e.step_limit = "the mean-curvature limit cfl_number x (shortest edge)^2 = " +
                               format_number(cfl) + " s (/flow/mean_curvature/cfl_number, " +
                               "/tracker/remesh/min_edge_fraction, " +
                               edge_length_origin(scene) + ")";
            }
        } else if (scene.flow.type == "normal_speed") {
            // The inversion limit lets a vertex move about a short edge per step.
            const double beta = scene.tracker.remesh.min_edge_fraction * xi;
            const double limit = beta / std::abs(scene.flow.normal_speed.speed);
            if (limit < dt) {
                dt = limit;
                e.step_limit = "the inversion limit (about one short edge per step: " +
                               format_number(limit) + " s with /flow/normal_speed/speed " +
                               format_number(scene.flow.normal_speed.speed) + " m/s)";
            }
        }
        e.steps_per_frame = frame_dt / dt;
        double speed = 0.0;
        std::string speed_keys;
        if (scene.flow.type == "normal_speed") {
            speed = std::abs(scene.flow.normal_speed.speed);
            speed_keys = "/flow/normal_speed/speed";
        } else if (scene.flow.type == "enright") {
            speed = ENRIGHT_MAX_SPEED;
            speed_keys = "the Enright field's peak speed";
        } else if (scene.flow.type == "curl_noise") {
            speed = CURL_NOISE_PEAK_OVER_RMS * scene.flow.curl_noise.rms_speed;
            speed_keys = "/flow/curl_noise/rms_speed (peaks about 4x)";
        } else if (scene.flow.type == "rigid" && !surface.bounds.isEmpty()) {
            // |v + ω × (x − c(t))| ≤ |v| + |ω| |x − c(t)|, and |x − c(t)| keeps its initial
            // value (the motion turns x about c(t)): the farthest corner of the initial bounds.
            const tracker::RigidMotionOptions& r = scene.flow.rigid;
            double reach = 0.0;
            for (int corner = 0; corner < 8; ++corner)
                reach = std::max(reach, (surface.bounds.corner(static_cast<tracker::Box3::CornerType>(
                                             corner)) - r.center).norm());
            speed = r.velocity.norm() + r.angular_velocity.norm() * reach;
            speed_keys = "/flow/rigid (|velocity| + |angular_velocity| x the surface's distance "
                         "from /flow/rigid/center)";
        }
        // The offered step: an expanding surface is not shortened by the inversion limit.
        const double offered = scene.time.dt;
        e.step_motion = speed * offered;
        e.step_motion_keys = speed_keys + " " + format_number(speed) + " m/s over /time/dt " +
                             format_number(offered) + " s";
        e.step_motion_fix = "shorten /time/dt to at most " +
                            format_number(MAX_STEP_MOTION_EDGES * e.edge_length / speed) + " s";
    }
    return e;
}

void check_resources(const Scene& scene, const ResourceEstimate& estimate,
                     const ResourceLimits& limits) {
    const double max_memory =
        limits.max_memory_bytes > 0.0 ? limits.max_memory_bytes : default_max_memory_bytes();
    const double memory = estimate.memory_bytes();
    if (!(memory <= max_memory)) {
        std::ostringstream s;
        s << scene.source_path << ": the run would need about " << format_bytes(memory)
          << " of memory, more than the limit of " << format_bytes(max_memory) << ":";
        for (const MemoryPart& p : estimate.memory)
            s << "\n  " << format_bytes(p.bytes) << " for the " << p.what
              << (p.while_meshing ? " (while meshing)" : "");
        s << "\n  " << format_bytes(PROGRAM_BYTES) << " for the program itself"
          << "\ncheck those values, or raise the limit with --max-memory GB";
        throw InputError(s.str());
    }
    if (!(estimate.step_motion <= MAX_STEP_MOTION_EDGES * estimate.edge_length)) {
        std::ostringstream s;
        s << scene.source_path << ": a time step would move the surface by up to "
          << format_number(estimate.step_motion) << " m (" << estimate.step_motion_keys << "), "
          << format_number(estimate.step_motion / estimate.edge_length)
          << " edge lengths of " << format_number(estimate.edge_length)
          << " m; collision handling needs steps of at most "
          << format_number(MAX_STEP_MOTION_EDGES) << " edge lengths: " << estimate.step_motion_fix;
        throw InputError(s.str());
    }
    if (!(estimate.steps_per_frame <= limits.max_steps_per_frame)) {
        std::ostringstream s;
        s << scene.source_path << ": a frame (" << format_number(scene.time.end / scene.time.frames)
          << " s, /time/end over /time/frames) would take about "
          << format_number(estimate.steps_per_frame) << " time steps, set by "
          << estimate.step_limit << "; the limit is " << format_number(limits.max_steps_per_frame)
          << " steps per frame: check those values, or raise the limit with "
             "--max-steps-per-frame N";
        throw InputError(s.str());
    }
}

std::vector<std::string> plausibility_warnings(const Scene& scene, double xi) {
    std::vector<std::string> warnings;
    if (scene.flow.type == "curl_noise") {
        const tracker::CurlNoiseOptions& c = scene.flow.curl_noise;
        const double finest = c.base_wavelength / std::pow(c.lacunarity, c.octaves - 1);
        if (finest < xi)
            warnings.push_back(
                "/flow/curl_noise: the finest octave's wavelength (" + format_number(finest) +
                " m: base_wavelength over lacunarity^(octaves - 1)) is shorter than the edge "
                "length " + format_number(xi) +
                " m; the mesh cannot follow it, so it acts as noise that keeps remeshing and "
                "collision handling busy");
    }
    return warnings;
}

void check_scene_scale(const Scene& scene) {
    const auto fail = [&](const std::string& what) { throw InputError(scene.source_path + ": " + what); };
    const double xi = scene.surface.edge_length;
    if (scene.shape) {
        const tracker::Box3 b = scene.shape->bounds();
        double extent = 0.0;
        for (int i = 0; i < 3; ++i)
            for (double c : {b.min()[i], b.max()[i]})
                if (std::isfinite(c))
                    extent = std::max(extent, std::abs(c));
        if (!(extent <= MAX_COORDINATE_TO_LENGTH * xi))
            fail("/surface/shape reaches " + format_number(extent) +
                 " m from the origin, too far for double precision to resolve " +
                 edge_length_origin(scene) + " (at most " +
                 format_number(MAX_COORDINATE_TO_LENGTH) + " edge lengths): move it nearer the "
                 "origin or use a larger edge length");
    }
    if (scene.flow.type != "fluid")
        return;
    const double dx = domain_dx(scene);
    const Eigen::Vector3d lo = scene.domain.min, hi = scene.domain.min + scene.domain.size;
    const double extent = std::max(lo.cwiseAbs().maxCoeff(), hi.cwiseAbs().maxCoeff());
    if (!(extent <= MAX_COORDINATE_TO_LENGTH * dx))
        fail("/domain reaches " + format_number(extent) +
             " m from the origin, too far for double precision to resolve its cells of " +
             format_number(dx) + " m (/domain/size/0 over /domain/cells): move /domain/min "
             "nearer the origin");
    const Eigen::Vector3d n = domain_cells(scene);
    for (int axis = 1; axis < 3; ++axis)
        if (!(n[axis] <= MAX_CELLS_PER_AXIS))
            fail("/domain/size/" + std::to_string(axis) + ": " + format_number(n[axis]) +
                 " cells of " + format_number(dx) + " m (/domain/size/0 over /domain/cells); at "
                 "most " + format_number(MAX_CELLS_PER_AXIS) + " per axis");
}

}  // namespace meniscus::app
