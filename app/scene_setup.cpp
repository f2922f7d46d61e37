#include "app/scene_setup.h"

#include "app/errors.h"
#include "app/resource_estimate.h"
#include "app/surface_checks.h"
#include "coupling/mesh_band.h"
#include "fluid/boundary.h"
#include "tracker/implicit_mesher.h"
#include "tracker/mesh_intersections.h"
#include "tracker/mesh_io.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>
#include <stdexcept>

namespace meniscus::app {

namespace {

using tracker::SurfaceMesh;
using tracker::Vec3;

/// Violations listed in an error message before "and N more".
constexpr size_t MAX_LISTED_VIOLATIONS = 5;
/// The fluid grid's cells per axis are ints; its arrays are indexed by their products.
constexpr double MAX_CELLS_PER_AXIS = 1 << 20;

/// Throws InputError listing the first intersecting triangle pairs, if any.
void check_intersection_free(const SurfaceMesh& mesh, const std::string& what) {
    const tracker::IntersectionReport r = tracker::find_self_intersections(mesh);
    if (r.intersection_free())
        return;
    std::ostringstream s;
    s << what << ": the surface intersects itself (" << r.triangle_pairs.size()
      << " triangle pairs), e.g.";
    for (size_t i = 0; i < r.triangle_pairs.size() && i < MAX_LISTED_VIOLATIONS; ++i)
        s << " (" << r.triangle_pairs[i].ti << ", " << r.triangle_pairs[i].tj << ")";
    throw InputError(s.str());
}

std::string format_length(double metres) {
    char text[32];
    std::snprintf(text, sizeof text, "%.4g m", metres);
    return text;
}

/// "/surface/edge_length 0.02 m", or how a fluid scene derived it from the grid.
std::string edge_length_keys(const Scene& scene) {
    if (scene.flow.type == "fluid" && scene.coupling.edge_length_cells > 0.0)
        return "edge length " + format_length(scene.surface.edge_length) +
               " (/coupling/edge_length_cells x /domain/size/0 / /domain/cells)";
    return "/surface/edge_length " + format_length(scene.surface.edge_length);
}

/// Total area of the triangles of `data` (m²).
double mesh_data_area(const tracker::MeshData& data) {
    double area = 0.0;
    for (const tracker::Triangle& t : data.triangles) {
        const Vec3& a = data.positions[static_cast<size_t>(t[0])];
        area += 0.5 * (data.positions[static_cast<size_t>(t[1])] - a)
                          .cross(data.positions[static_cast<size_t>(t[2])] - a)
                          .norm();
    }
    return area;
}

/// The initial surface's geometry and connectivity (labels still the default: liquid inside).
/// `preloaded`: the mesh file's contents when the caller has read them already.
SurfaceMesh build_initial_surface_geometry(const Scene& scene, std::string* report,
                                           double* nominal_xi,
                                           const tracker::MeshData* preloaded = nullptr) {
    if (scene.shape) {
        tracker::ImplicitMeshOptions options;
        options.edge_length = scene.surface.edge_length;
        options.remesh_iterations = scene.surface.remesh_iterations;
        options.crease = scene.surface.crease;
        options.cancel = scene.cancel;
        options.periods = scene_periods(scene);
        tracker::ImplicitMeshReport r;
        SurfaceMesh mesh;
        try {
            mesh = tracker::mesh_implicit_shape(*scene.shape, options, &r);
        } catch (const Cancelled&) {
            throw;
        } catch (const std::invalid_argument& e) {
            throw InputError(scene.source_path + ": /surface/shape at " + edge_length_keys(scene) +
                             ": " + e.what());
        } catch (const std::runtime_error& e) {
            throw InputError(scene.source_path + ": /surface/shape at " + edge_length_keys(scene) +
                             ": " + e.what());
        }
        check_intersection_free(
            mesh, scene.source_path + ": /surface/shape meshed at " + edge_length_keys(scene));
        if (report) {
            std::ostringstream s;
            s << "meshed shape: " << r.vertices << " vertices, " << r.triangles
              << " triangles, mean edge " << r.mean_edge_length << " m (requested "
              << scene.surface.edge_length << "), angles " << r.min_angle_degrees << "°–"
              << r.max_angle_degrees << "°";
            if (r.crease_splits > 0)
                s << ", " << r.crease_splits << " crease refinement splits around "
                  << r.crease_vertices << " crease vertices";
            *report = s.str();
        }
        if (nominal_xi)
            *nominal_xi = r.nominal_characteristic_length();
        return mesh;
    }
    const std::string& file = scene.surface.mesh_file;
    const tracker::MeshData data = preloaded ? tracker::MeshData{} : read_surface_file(scene);
    SurfaceMesh mesh = checked_surface_mesh(preloaded ? *preloaded : data, scene);
    if (report) {
        std::ostringstream s;
        s << "loaded " << file << ": " << mesh.count_live_vertices() << " vertices, "
          << mesh.count_live_triangles() << " triangles";
        *report = s.str();
    }
    return mesh;
}

/// /surface/inside: which phase the surface encloses.
void set_inside_labels(SurfaceMesh& mesh, const Scene& scene) {
    const tracker::LabelPair labels =
        scene.surface.inside == "gas" ? tracker::LabelPair{0, 1} : tracker::LabelPair{1, 0};
    for (int ti = 0; ti < mesh.num_triangles(); ++ti)
        if (mesh.triangle_alive(ti))
            mesh.set_labels(ti, labels);
}

/// Sets every face whose centre lies inside a region's shape to that region's velocity.
void apply_initial_velocity(const std::vector<VelocityRegion>& regions, fluid::MacGrid& grid,
                            const CancellationToken& cancel) {
    if (regions.empty())
        return;
    for (int axis = 0; axis < 3; ++axis) {
        fluid::Array3<double>& u = grid.velocity(axis);
        for (int k = 0; k < u.nk(); ++k) {
            cancel.throw_if_requested("setting the initial velocity");
            for (int j = 0; j < u.nj(); ++j)
                for (int i = 0; i < u.ni(); ++i) {
                    const Vec3 x = grid.face_centre(axis, i, j, k);
                    for (const VelocityRegion& r : regions)
                        if (r.shape->value(x) < 0.0)
                            u(i, j, k) = r.velocity[axis];
                }
        }
    }
}

/// Periodic faces with what does not wrap around the box yet: a surface read from a file (its
/// connectivity cannot close across the faces), inflow and outflow faces (the nozzle's mesh and
/// the clipping), semi-implicit surface tension. Throws InputError naming the face.
void check_periodic_faces(const Scene& scene) {
    static const char* const faces[3] = {"x_min", "y_min", "z_min"};
    int periodic = -1;
    for (int axis = 0; axis < 3; ++axis)
        if (scene.fluid.boundaries.periodic(axis) && periodic < 0)
            periodic = axis;
    if (periodic < 0)
        return;
    const std::string where =
        scene.source_path + ": /fluid/boundaries/" + faces[periodic] + ": periodic faces ";
    if (!scene.shape)
        throw InputError(where +
                         "need the surface as /surface/shape (a mesh file cannot be "
                         "closed across the box's faces)");
    if (scene.fluid.boundaries.inflow() || scene.fluid.boundaries.open())
        throw InputError(where + "are not available together with inflow or outflow faces yet");
    if (scene.coupling.simulation.implicit_tension > 0.0)
        throw InputError(where + "are not available with /coupling/implicit_tension yet");
    if (scene.fluid.boundaries.periodic(0) && scene.fluid.boundaries.periodic(1) &&
        scene.fluid.boundaries.periodic(2))
        throw InputError(where +
                         "may wrap two axes at most: the enclosed volume is measured "
                         "along an axis that does not wrap");
}

/// Each inflow lets in the phase the surface puts at its region's centre, half a cell inside
/// the box (a jet's or bubble's surface must reach through the face, or the box hold that phase
/// around the face). Throws InputError naming the inflow's phase otherwise.
void check_inflow_phases(const Scene& scene, const SurfaceMesh& mesh, const fluid::MacGrid& grid) {
    static const char* const faces[3][2] = {
        {"x_min", "x_max"}, {"y_min", "y_max"}, {"z_min", "z_max"}};
    const Vec3 lo = grid.origin();
    const Vec3 hi = lo + grid.dx() * Vec3(grid.nx(), grid.ny(), grid.nz());
    for (int axis = 0; axis < 3; ++axis)
        for (int side = 0; side < 2; ++side) {
            const fluid::FaceBoundary& face = scene.fluid.boundaries.face(axis, side);
            if (face.type != fluid::BoundaryType::inflow || face.inflow.speed == 0.0)
                continue;
            Vec3 centre = face.inflow.region == fluid::InflowRegion::disc ? face.inflow.centre
                                                                          : Vec3(0.5 * (lo + hi));
            centre[axis] = side == 0 ? lo[axis] + 0.5 * grid.dx() : hi[axis] - 0.5 * grid.dx();
            const int liquid = scene.coupling.simulation.rasterize.liquid_region;
            const bool liquid_there = coupling::region_at(mesh, centre, 0) == liquid;
            const bool liquid_in = face.inflow.phase == fluid::InflowPhase::liquid;
            if (liquid_there == liquid_in)
                continue;
            std::ostringstream s;
            s << scene.source_path << ": /fluid/boundaries/" << faces[axis][side]
              << "/inflow/phase: the inflow lets in " << (liquid_in ? "liquid" : "gas")
              << ", but the surface puts " << (liquid_there ? "liquid" : "gas") << " at ("
              << centre.x() << ", " << centre.y() << ", " << centre.z()
              << "), the middle of the inflow region half a cell inside the box; the "
              << (liquid_in ? "jet's" : "bubble's")
              << " surface must reach through the face (the part behind it is the nozzle)";
            throw InputError(s.str());
        }
}

}  // namespace

int fluid_cells_along(const Scene& scene, int axis) {
    const double dx = scene.domain.size.x() / scene.domain.cells;
    if (axis == 0)
        return scene.domain.cells;
    static const char* const keys[3] = {"/domain/size/0", "/domain/size/1", "/domain/size/2"};
    const double n = std::round(scene.domain.size[axis] / dx);
    if (!(n <= MAX_CELLS_PER_AXIS))
        throw InputError(scene.source_path + ": " + keys[axis] + ": " + std::to_string(n) +
                         " cells of the /domain cell size; at most " +
                         std::to_string(MAX_CELLS_PER_AXIS));
    return std::max(1, static_cast<int>(n));
}

tracker::MeshPeriods scene_periods(const Scene& scene) {
    tracker::MeshPeriods periods;
    if (scene.flow.type != "fluid")
        return periods;
    const double dx = scene.domain.size.x() / scene.domain.cells;
    for (int axis = 0; axis < 3; ++axis)
        if (scene.fluid.boundaries.periodic(axis)) {
            periods.origin[axis] = scene.domain.min[axis];
            periods.length[axis] = fluid_cells_along(scene, axis) * dx;
        }
    return periods;
}

tracker::TrackerOptions tracker_options(const Scene& scene, double nominal_xi) {
    tracker::TrackerOptions options = scene.tracker;
    if (options.characteristic_length == 0.0)
        options.characteristic_length = nominal_xi;
    options.cancel = scene.cancel;
    return options;
}

SurfaceMesh build_initial_surface(const Scene& scene, std::string* report, double* nominal_xi) {
    if (nominal_xi)
        *nominal_xi = 0.0;
    SurfaceMesh mesh = build_initial_surface_geometry(scene, report, nominal_xi);
    set_inside_labels(mesh, scene);
    return mesh;
}

SurfaceMesh checked_initial_surface(const Scene& scene, const ResourceLimits& limits,
                                    std::string* report, double* nominal_xi) {
    *nominal_xi = 0.0;
    SurfaceSize size;
    tracker::MeshData data;
    if (scene.shape) {
        size = shape_surface_size(scene);
        size.bounds = scene.shape->bounds();
    } else {
        data = read_surface_file(scene);
        size.from_mesh_file = true;
        size.triangles = static_cast<double>(data.triangles.size());
        size.area = mesh_data_area(data);
        for (const Vec3& p : data.positions)
            size.bounds.extend(p);
    }
    const double frame_dt = scene.time.end / scene.time.frames;
    check_resources(scene, estimate_resources(scene, size, frame_dt, limits.ranks), limits);
    check_scene_scale(scene);
    if (scene.shape) {
        const tracker::Box3 b = scene.shape->bounds();
        check_surface_meets_fluid_box(scene, b.min(), b.max(), "/surface/shape");
    }
    SurfaceMesh mesh =
        build_initial_surface_geometry(scene, report, nominal_xi, scene.shape ? nullptr : &data);
    if (!scene.shape) {
        Eigen::AlignedBox3d box;
        for (const Vec3& p : data.positions)
            box.extend(p);
        check_surface_meets_fluid_box(scene, box.min(), box.max(),
                                      "/surface/mesh_file " + scene.surface.mesh_file);
    }
    set_inside_labels(mesh, scene);
    return mesh;
}

coupling::Simulation make_fluid_simulation(const Scene& scene, SurfaceMesh initial,
                                           double nominal_xi,
                                           const fluid::RankCommunicator& ranks) {
    check_periodic_faces(scene);
    const double dx = scene.domain.size.x() / scene.domain.cells;
    fluid::FluidOptions options = scene.fluid;
    const int nz = fluid_cells_along(scene, 2);
    const bool distributed = ranks.size() > 1;
    if (!distributed) {
        options.pressure.iteration.cancel = scene.cancel;
        options.viscosity.iteration.cancel = scene.cancel;
    }
    // On several ranks a solve is never cancelled half-way (every rank must leave it together):
    // the run stops between steps instead (app/run.cpp).
    fluid::SlabDecomposition decomposition(nz);
    if (distributed) {
        try {
            decomposition = fluid::SlabDecomposition(
                nz, ranks.size(), fluid::FluidSolver::ghost_layers_needed(options),
                options.boundaries.periodic(2));
        } catch (const std::invalid_argument& e) {
            throw InputError(std::string("/domain: the grid's ") + std::to_string(nz) +
                             " cells along z cannot be split over " + std::to_string(ranks.size()) +
                             " MPI ranks (" + e.what() + ")");
        }
    }
    fluid::FluidSolver solver(scene.domain.cells, fluid_cells_along(scene, 1), nz, dx,
                              scene.domain.min, options, decomposition, ranks);
    apply_initial_velocity(scene.initial_velocity, solver.grid(), scene.cancel);
    // The velocity regions may have reached the box's faces.
    fluid::apply_boundary_velocity(solver.grid(), solver.grid_boundaries(), solver.time());
    solver.refresh_ghost_layers();
    check_inflow_phases(scene, initial, solver.grid());
    return coupling::Simulation(
        tracker::SurfaceTracker(std::move(initial), tracker_options(scene, nominal_xi)),
        std::move(solver), scene.coupling.simulation);
}

coupling::Simulation make_fluid_simulation(const Scene& scene, std::string* report) {
    double nominal_xi = 0.0;
    SurfaceMesh initial = build_initial_surface(scene, report, &nominal_xi);
    return make_fluid_simulation(scene, std::move(initial), nominal_xi);
}

}  // namespace meniscus::app
