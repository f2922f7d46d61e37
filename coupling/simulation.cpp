#include "coupling/simulation.h"

#include "coupling/implicit_tension.h"
#include "coupling/periodic_images.h"
#include "tracker/mesh_measures.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace meniscus::coupling {

namespace {

/// Cap on a vertex's sub-grid displacement per step, in mesh edge lengths: the damping is meant
/// for mesh-scale wrinkles; a sliver's outsized cotangent weights must not throw a vertex far.
constexpr double MAX_SUBGRID_STEP_EDGES = 0.25;

const char* const AXIS_NAMES[3] = {"x", "y", "z"};

}  // namespace

void check_periods(const tracker::SurfaceMesh& mesh, const fluid::MacGrid& grid,
                   const fluid::BoundaryOptions& boundaries) {
    const tracker::MeshPeriods& periods = mesh.periods();
    for (int a = 0; a < 3; ++a)
        if (grid.periodic()[static_cast<size_t>(a)] != boundaries.periodic(a) && periods.any())
            throw std::invalid_argument(std::string("periods: the grid and the boundaries "
                                                    "disagree on a periodic ") +
                                        AXIS_NAMES[a]);
    check_periods(mesh, grid.origin(), {grid.nx(), grid.ny(), grid.nz()}, grid.dx(), boundaries);
}

void check_periods(const tracker::SurfaceMesh& mesh, const Eigen::Vector3d& box_min,
                   const std::array<int, 3>& cells, double dx,
                   const fluid::BoundaryOptions& boundaries) {
    const tracker::MeshPeriods& periods = mesh.periods();
    for (int a = 0; a < 3; ++a) {
        const std::string axis = AXIS_NAMES[a];
        const bool box = boundaries.periodic(a);
        if (box != periods.wraps(a))
            throw std::invalid_argument(
                box ? "periods: the fluid box is periodic along " + axis +
                          " but the surface mesh does not wrap around it (SurfaceMesh::set_periods)"
                    : "periods: the surface mesh wraps around " + axis +
                          " but the fluid box is not periodic along it");
        if (!box)
            continue;
        const double length = dx * cells[static_cast<size_t>(a)];
        if (std::abs(periods.length[a] - length) > 1e-9 * length ||
            std::abs(periods.origin[a] - box_min[a]) > 1e-9 * length)
            throw std::invalid_argument("periods: the surface mesh's period along " + axis +
                                        " is not the fluid box's (origin and length must match)");
    }
    if (periods.any())
        for (int a = 0; a < 3; ++a)
            for (const fluid::BoundaryType type : {boundaries.at(a, 0), boundaries.at(a, 1)})
                if (type == fluid::BoundaryType::inflow || type == fluid::BoundaryType::outflow)
                    throw std::invalid_argument(
                        "periods: inflow and outflow faces are not available together with "
                        "periodic faces yet (the clipping and the nozzle's mesh do not wrap)");
}

void SimulationOptions::validate() const {
    rasterize.validate();
    surface_tension.validate();
    interpolate.validate();
    open_boundaries.validate();
    if (!(implicit_tension >= 0.0 && implicit_tension <= 1.0))
        throw std::invalid_argument("implicit_tension: expected a number in [0, 1]");
    if (implicit_tension_form != SurfaceTermForm::normal &&
        implicit_tension_form != SurfaceTermForm::full)
        throw std::invalid_argument("implicit_tension_form: expected normal or full");
    if (implicit_tension > 0.0 && interpolate.method != VelocityInterpolation::trilinear)
        throw std::invalid_argument(
            "implicit_tension: needs the trilinear vertex velocities (velocity_interpolation "
            "trilinear)");
    if (implicit_tension == 0.0 && !(capillary_safety > 0.0 && capillary_safety <= 1.0))
        throw std::invalid_argument(
            "capillary_safety: expected a number in (0, 1] with explicit surface tension "
            "(above 1 needs implicit_tension > 0)");
    if (!(capillary_safety > 0.0 && capillary_safety <= MAX_IMPLICIT_CAPILLARY_SAFETY))
        throw std::invalid_argument("capillary_safety: expected a number in (0, " +
                                    std::to_string(MAX_IMPLICIT_CAPILLARY_SAFETY) + "]");
}

const char* to_string(StepLimit limit) {
    switch (limit) {
        case StepLimit::cfl:
            return "cfl";
        case StepLimit::capillary:
            return "capillary";
        case StepLimit::frame_end:
            return "frame_end";
        case StepLimit::max_dt:
            return "max_dt";
    }
    return "unknown";
}

Simulation::Simulation(tracker::SurfaceTracker tracker, fluid::FluidSolver fluid,
                       const SimulationOptions& options)
    : m_tracker(std::make_unique<tracker::SurfaceTracker>(std::move(tracker))),
      m_fluid(std::move(fluid)),
      m_options(options) {
    m_options.validate();
    check_periods(m_tracker->mesh(), m_fluid.box_min(), m_fluid.box_cells(), m_fluid.grid().dx(),
                  m_fluid.options().boundaries);
    if (m_fluid.blocks().distributed()) {
        const fluid::BoundaryOptions& b = m_fluid.options().boundaries;
        if (b.open() || b.inflow())
            throw std::invalid_argument(
                "boundaries: inflow and outflow faces are not available on several MPI ranks yet "
                "(the mesh's clipping and the nozzle need the whole box)");
        if (m_options.implicit_tension > 0.0)
            throw std::invalid_argument(
                "implicit_tension: not available on several MPI ranks yet; use explicit surface "
                "tension (0)");
    }
    if (m_tracker->mesh().periodic() && m_options.implicit_tension > 0.0)
        throw std::invalid_argument(
            "implicit_tension: not available with periodic faces (the surface viscosity does "
            "not wrap around the box); use explicit surface tension (0)");
    if (m_options.volume_correction)
        m_volumes = std::make_unique<VolumeTracker>(m_tracker->mesh());
    m_vertex_velocities.assign(static_cast<size_t>(m_tracker->mesh().num_vertices()),
                               tracker::Vec3::Zero());
}

SimulationStepReport Simulation::step(double time_left, double max_dt) {
    if (!(time_left > 0.0) || !(max_dt > 0.0))
        throw std::invalid_argument("Simulation::step: time_left and max_dt must be > 0");
    SimulationStepReport report;
    tracker::SurfaceMesh& mesh = m_tracker->mesh();
    const fluid::MacGrid& grid = m_fluid.grid();

    // (1) Time step.
    const fluid::TimeStepLimits limits = m_fluid.time_step_limits();
    const fluid::PhaseOptions& phases = m_fluid.options().phases;
    // (An empty mesh — everything left through outflow faces — has no edge length.)
    const tracker::EdgeLengthStats edges = tracker::edge_length_stats(mesh);
    const double h = edges.count > 0 ? std::min(grid.dx(), edges.mean) : grid.dx();
    const bool two_phase = m_fluid.options().mode == fluid::FluidMode::two_phase;
    const double rho_mean =
        two_phase ? 0.5 * (phases.rho_liquid + phases.rho_gas) : 0.5 * phases.rho_liquid;
    const double capillary = phases.sigma > 0.0
                                 ? m_options.capillary_safety *
                                       std::sqrt(rho_mean * h * h * h / (2.0 * M_PI * phases.sigma))
                                 : std::numeric_limits<double>::infinity();
    report.dt = m_fluid.options().time_step.max_dt;
    report.limit = StepLimit::max_dt;
    const auto bind = [&](double candidate, StepLimit limit) {
        if (candidate < report.dt) {
            report.dt = candidate;
            report.limit = limit;
        }
    };
    bind(limits.cfl, StepLimit::cfl);
    bind(capillary, StepLimit::capillary);
    bind(max_dt, StepLimit::max_dt);
    bind(time_left, StepLimit::frame_end);

    // (2) Mesh → grid.
    SimulationTimings& timings = report.timings;
    PhaseClock clock;
    // A periodic mesh is seen by the grid-side code unrolled: its images around the box, far
    // enough out that the band, the curvature's smoothing rings and the seam faces see a whole
    // surface (periodic_images.h).
    UnrolledMesh unrolled;
    if (mesh.periodic())
        unrolled = unroll_periodic_mesh(mesh, unroll_margin(edges.mean));
    const tracker::SurfaceMesh& grid_mesh = mesh.periodic() ? unrolled.mesh : mesh;
    RasterizeResult raster = rasterize_mesh(grid_mesh, grid, m_options.rasterize);
    clock.lap_into(timings.rasterize);
    fluid::InterfaceInput interface;
    face_curvatures(grid_mesh, grid, raster, m_options.surface_tension, interface);
    interface.phi = std::move(raster.phi);
    const bool implicit_term = m_options.implicit_tension > 0.0 && phases.sigma > 0.0;
    if (implicit_term) {
        // Sampled by face density (implicit_tension.h); free-surface gas faces carry no mass.
        interface.surface_viscosity = build_surface_viscosity(
            mesh, grid, m_options.implicit_tension * phases.sigma * report.dt,
            m_options.interpolate, m_fluid.options().boundaries, &interface.phi, phases.rho_liquid,
            two_phase ? phases.rho_gas : 0.0, m_options.implicit_tension_form);
    }
    clock.lap_into(timings.curvature);

    // (3) Fluid.
    report.fluid = m_fluid.step(report.dt, interface);
    m_phi = interface.phi;
    clock.lap_into(timings.fluid);

    // (5, first half) Mesh improvement and topology changes happen before velocities are set.
    if (m_volumes) {
        m_volumes->begin_step();
        clock.lap_into(timings.volume_correction);
    }
    // The nozzle's mesh behind an inflow face stays where it is (open_boundaries.h).
    const fluid::BoundaryOptions& boundaries = m_fluid.options().boundaries;
    std::vector<std::uint8_t> held;
    if (boundaries.inflow())
        held = held_vertices(mesh, grid, boundaries);
    report.improve = m_tracker->improve(held.empty() ? nullptr : &held);
    report.open_boundaries = apply_open_boundaries(mesh, grid, boundaries, m_fluid.time(),
                                                   report.dt, m_options.rasterize.liquid_region,
                                                   m_options.open_boundaries, m_volumes.get());
    m_boundary_volumes += report.open_boundaries.volumes;
    report.topology = m_tracker->change_topology();  // compacts
    clock.lap_into(timings.tracker);
    if (m_volumes) {
        report.volume = m_volumes->match_components();
        clock.lap_into(timings.volume_correction);
    }

    // (4) Grid → mesh.
    if (implicit_term && two_phase) {
        // As the implicit term saw the surface move (implicit_tension.h). (Free-surface gas
        // faces hold the liquid's velocity extrapolated, not modes of their own: the mesh reads
        // them as it does without the term.)
        m_vertex_velocities = term_vertex_velocities(mesh, m_fluid.grid(), m_options.interpolate,
                                                     m_fluid.grid_boundaries(), m_phi,
                                                     phases.rho_liquid, phases.rho_gas);
    } else {
        m_vertex_velocities = interpolate_vertex_velocities(
            m_fluid.grid(), mesh, m_options.interpolate, m_fluid.grid_boundaries());
    }
    if (m_fluid.blocks().distributed())
        combine_rank_velocities(m_vertex_velocities);
    if (boundaries.inflow())
        held = held_vertices(mesh, grid, boundaries);  // renumbered since
    for (size_t v = 0; v < held.size(); ++v)
        if (held[v])
            m_vertex_velocities[v] = tracker::Vec3::Zero();
    const std::vector<std::uint8_t>* pinned = held.empty() ? nullptr : &held;
    for (const tracker::Vec3& v : m_vertex_velocities)
        report.max_vertex_speed = std::max(report.max_vertex_speed, v.norm());
    clock.lap_into(timings.interpolate);

    // (6) Volume correction rides on the collision-safe motion; (5) integrate.
    std::vector<tracker::Vec3> velocities = m_vertex_velocities;
    add_subgrid_tension(velocities, report.dt);
    clock.lap_into(timings.curvature);
    if (m_volumes) {
        m_volumes->add_correction(velocities, report.dt, pinned);
        clock.lap_into(timings.volume_correction);
    }
    check_surface_motion(mesh, velocities, report.dt, grid.dx(),
                         m_fluid.options().time_step.cfl_number);
    report.integrate = m_tracker->integrate(velocities, report.dt, pinned);
    clock.lap_into(timings.tracker);
    if (m_fluid.blocks().distributed())
        check_replicated_mesh();
    for (const PhaseSeconds* phase :
         {&timings.rasterize, &timings.curvature, &timings.fluid, &timings.interpolate,
          &timings.volume_correction, &timings.tracker})
        timings.total += *phase;
    m_time += report.integrate.time_advanced;
    return report;
}

void Simulation::combine_rank_velocities(std::vector<tracker::Vec3>& velocities) const {
    // Each vertex belongs to the rank owning the cell layer its z lies in (wrapped around a
    // periodic z, clamped to the end layers beyond the box's z walls); the others' values are
    // dropped and the owners' summed over the ranks. The owner's block covers the vertex's
    // interpolation stencil (FluidSolver::ghost_layers_needed() ≥ 2).
    const fluid::BlockContext& blocks = m_fluid.blocks();
    const fluid::SlabDecomposition& d = blocks.decomposition();
    const tracker::SurfaceMesh& mesh = m_tracker->mesh();
    const double z0 = m_fluid.box_min().z(), dx = m_fluid.grid().dx();
    // The replicated meshes must agree before the reduction is sized by them.
    const double vertices = static_cast<double>(velocities.size());
    if (blocks.max(vertices) != blocks.min(vertices))
        throw std::runtime_error(
            "Simulation: the ranks' copies of the surface mesh differ in their vertex count (the "
            "replicated tracker was not deterministic)");
    std::vector<double> flat(3 * velocities.size(), 0.0);
    for (size_t v = 0; v < velocities.size(); ++v) {
        if (!mesh.vertex_alive(static_cast<int>(v)))
            continue;
        // Clamped on a periodic z too: the tracker keeps positions in [z0, z0 + L), but the
        // division may round a position just below z0 + L up to layer nz.
        const int layer = std::clamp(
            static_cast<int>(std::floor((mesh.position(static_cast<int>(v)).z() - z0) / dx)), 0,
            d.layers() - 1);
        if (d.owner(layer) != blocks.rank())
            continue;
        for (int a = 0; a < 3; ++a)
            flat[3 * v + static_cast<size_t>(a)] = velocities[v][a];
    }
    blocks.ranks().sum_in_place(flat);
    for (size_t v = 0; v < velocities.size(); ++v)
        velocities[v] = tracker::Vec3(flat[3 * v], flat[3 * v + 1], flat[3 * v + 2]);
}

void Simulation::check_replicated_mesh() const {
    // A checksum of the live vertex positions and the mesh's size: equal on every rank while the
    // replicated tracker stays deterministic.
    const tracker::SurfaceMesh& mesh = m_tracker->mesh();
    double sum = static_cast<double>(mesh.num_vertices()) + 1e3 * mesh.num_triangles();
    for (int v = 0; v < mesh.num_vertices(); ++v)
        if (mesh.vertex_alive(v)) {
            const tracker::Vec3& x = mesh.position(v);
            sum += (1.0 + 1e-3 * (v % 97)) * (x.x() + 2.0 * x.y() + 3.0 * x.z());
        }
    const fluid::BlockContext& blocks = m_fluid.blocks();
    if (blocks.max(sum) != blocks.min(sum))
        throw std::runtime_error(
            "Simulation: the ranks' copies of the surface mesh differ after a step (the "
            "replicated tracker was not deterministic)");
}

double Simulation::unroll_margin(double mean_edge) const {
    // The band, plus a ring per smoothing pass and per cotangent stencil, plus a cell for the
    // seam faces' lo cells (half a cell beyond the box).
    const double h = std::max(m_fluid.grid().dx(), mean_edge);
    return (m_options.rasterize.half_width_cells + m_options.surface_tension.smoothing_passes +
            4.0) *
           h;
}

void Simulation::add_subgrid_tension(std::vector<tracker::Vec3>& velocities, double dt) const {
    const SurfaceTensionOptions& options = m_options.surface_tension;
    const fluid::PhaseOptions& phases = m_fluid.options().phases;
    const tracker::SurfaceMesh& mesh = m_tracker->mesh();
    if (options.subgrid_rate == 0.0 || phases.sigma == 0.0 || mesh.count_live_triangles() == 0)
        return;
    // D = β h² / t_h with t_h = sqrt(ρ̄ h³ / (2πσ)), the capillary time of the mesh scale h.
    const double h = tracker::edge_length_stats(mesh).mean;
    const double rho_mean = m_fluid.options().mode == fluid::FluidMode::two_phase
                                ? 0.5 * (phases.rho_liquid + phases.rho_gas)
                                : 0.5 * phases.rho_liquid;
    const double t_h = std::sqrt(rho_mean * h * h * h / (2.0 * M_PI * phases.sigma));
    const double diffusivity = options.subgrid_rate * h * h / t_h;
    // Only vertices inside the fluid box (see subgrid_tension_velocities()).
    const tracker::Vec3 lo = m_fluid.box_min();
    const tracker::Vec3 hi = m_fluid.box_max();
    std::vector<char> inside(static_cast<size_t>(mesh.num_vertices()), 0);
    for (int vi = 0; vi < mesh.num_vertices(); ++vi) {
        if (!mesh.vertex_alive(vi))
            continue;
        const tracker::Vec3& x = mesh.position(vi);
        inside[static_cast<size_t>(vi)] =
            (x.array() >= lo.array()).all() && (x.array() <= hi.array()).all() ? 1 : 0;
    }
    const std::vector<tracker::Vec3> subgrid = subgrid_tension_velocities(
        mesh, diffusivity, options.subgrid_resolved_passes, options.subgrid_filter_order, inside);
    const double max_speed = MAX_SUBGRID_STEP_EDGES * h / dt;
    for (size_t v = 0; v < velocities.size(); ++v) {
        const double speed = subgrid[v].norm();
        velocities[v] += speed > max_speed ? (max_speed / speed) * subgrid[v] : subgrid[v];
    }
}

double Simulation::kinetic_energy() const {
    const fluid::MacGrid& grid = m_fluid.grid();
    const fluid::PhaseOptions& phases = m_fluid.options().phases;
    const bool two_phase = m_fluid.options().mode == fluid::FluidMode::two_phase;
    const double cell_volume = grid.dx() * grid.dx() * grid.dx();
    const auto density = [&](int i, int j, int k) {
        if (m_phi.size() == 0)
            return phases.rho_liquid;
        const double phi = m_phi(std::clamp(i, 0, grid.nx() - 1), std::clamp(j, 0, grid.ny() - 1),
                                 std::clamp(k, 0, grid.nz() - 1));
        return phi < 0.0 ? phases.rho_liquid : (two_phase ? phases.rho_gas : 0.0);
    };
    // On several ranks each sums the faces of its own layers (the last rank also the top
    // z-faces of a walled box).
    const fluid::BlockContext& blocks = m_fluid.blocks();
    const fluid::SlabDecomposition& d = blocks.decomposition();
    const int rank = blocks.rank();
    const int k_begin = blocks.distributed() ? d.owned_begin(rank) - d.local_begin(rank) : 0;
    double energy = 0.0;
    for (int axis = 0; axis < 3; ++axis) {
        const fluid::Array3<double>& u = grid.velocity(axis);
        const bool top = axis == 2 && !d.periodic() && rank == d.ranks() - 1;
        const int k_end =
            blocks.distributed() ? d.owned_end(rank) - d.local_begin(rank) + (top ? 1 : 0) : u.nk();
        for (int k = k_begin; k < k_end; ++k)
            for (int j = 0; j < u.nj(); ++j)
                for (int i = 0; i < u.ni(); ++i) {
                    // Face between cells (i−1) and i along `axis`: average their densities.
                    const int ia = axis == 0 ? i - 1 : i, ja = axis == 1 ? j - 1 : j,
                              ka = axis == 2 ? k - 1 : k;
                    const double rho = 0.5 * (density(ia, ja, ka) + density(i, j, k));
                    energy += 0.5 * rho * u(i, j, k) * u(i, j, k) * cell_volume;
                }
    }
    return blocks.distributed() ? blocks.sum(energy) : energy;
}

void Simulation::save_state(BinaryWriter& out) const {
    out.put(m_time);
    m_tracker->save_state(out);
    m_fluid.save_state(out);
    out.put<std::uint8_t>(m_volumes ? 1 : 0);
    if (m_volumes)
        m_volumes->save_state(out);
    out.put_vector(m_vertex_velocities);
    // φ of this rank's block; on several ranks the whole grid's, gathered on rank 0 (the fluid
    // state is the whole grid's likewise; see FluidSolver::save_state).
    out.put<std::uint8_t>(m_phi.size() > 0 ? 1 : 0);
    if (m_phi.size() > 0)
        fluid::save_array(out, m_fluid.blocks().distributed()
                                   ? m_fluid.blocks().gather_whole(m_phi, fluid::LayerKind::cells)
                                   : m_phi);
    for (double v : {m_boundary_volumes.liquid_in, m_boundary_volumes.gas_in,
                     m_boundary_volumes.liquid_out, m_boundary_volumes.gas_out})
        out.put(v);
}

void Simulation::load_state(BinaryReader& in) {
    const double time = in.get<double>();
    if (!std::isfinite(time) || time < 0.0)
        throw FormatError("simulation state: the time is not a number >= 0");
    m_tracker->load_state(in);
    m_fluid.load_state(in);
    const std::uint8_t has_volumes = in.get<std::uint8_t>();
    if (has_volumes != (m_volumes ? 1 : 0))
        throw FormatError("simulation state: volume correction was " +
                          std::string(has_volumes ? "on" : "off") + " when it was saved");
    if (m_volumes)
        m_volumes->load_state(in);
    std::vector<tracker::Vec3> velocities = in.get_vector<tracker::Vec3>();
    if (velocities.size() != static_cast<size_t>(m_tracker->mesh().num_vertices()))
        throw FormatError("simulation state: the vertex velocities do not match the mesh");
    const std::uint8_t has_phi = in.get<std::uint8_t>();
    fluid::Array3<double> phi;
    if (has_phi) {
        const fluid::MacGrid& g = m_fluid.grid();
        const fluid::BlockContext& blocks = m_fluid.blocks();
        phi.resize(g.nx(), g.ny(),
                   blocks.distributed() ? blocks.whole_layers(fluid::LayerKind::cells) : g.nz());
        fluid::load_array(in, phi, "simulation state: phi");
        if (blocks.distributed())
            phi = blocks.block_of(phi, fluid::LayerKind::cells);
    }
    BoundaryVolumes through;
    for (double* v : {&through.liquid_in, &through.gas_in, &through.liquid_out, &through.gas_out}) {
        *v = in.get<double>();
        if (!std::isfinite(*v) || *v < 0.0)
            throw FormatError("simulation state: a volume through the open faces is not >= 0");
    }
    m_vertex_velocities = std::move(velocities);
    m_phi = std::move(phi);
    m_boundary_volumes = through;
    m_time = time;
}

}  // namespace meniscus::coupling
