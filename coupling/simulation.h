#pragma once
/// \file One coupled step of liquid/gas flow with an explicit interface (docs/architecture.md):
/// (1) Δt from CFL, the capillary limit (with the smaller of Δx and the mesh's mean edge
/// length) and the time left to the frame; (2) mesh → φ at cell centres and κ at crossed faces;
/// (3) the fluid step; (4) grid velocity → mesh vertices, plus the sub-grid surface-tension
/// velocity that damps mesh-scale wrinkles (subgrid_tension_velocities()); (5) the tracker's
/// improve(), change_topology() and collision-safe integrate(); (6) optional volume correction per
/// connected component (through merges and pinch-offs). At open faces of the box the mesh is held
/// behind inflows and clipped beyond outflows, and the volume correction's targets follow what
/// entered and left (open_boundaries.h).

#include "common/phase_clock.h"
#include "coupling/implicit_tension.h"
#include "coupling/interpolate.h"
#include "coupling/open_boundaries.h"
#include "coupling/rasterize.h"
#include "coupling/step_guard.h"
#include "coupling/surface_tension.h"
#include "coupling/volume_correction.h"
#include "fluid/fluid_solver.h"
#include "tracker/surface_tracker.h"

#include <array>
#include <limits>
#include <memory>
#include <string>
#include <utility>

namespace meniscus::coupling {

/// Largest capillary_safety with implicit surface tension.
constexpr double MAX_IMPLICIT_CAPILLARY_SAFETY = 20.0;

/// Options of the coupled step. Defaults here and nowhere else.
struct SimulationOptions {
    RasterizeOptions rasterize;
    SurfaceTensionOptions surface_tension;
    InterpolateOptions interpolate;
    OpenBoundaryOptions open_boundaries;  ///< the mesh at inflow and outflow faces
    bool volume_correction = true;  ///< restore each component's volume every step
    /// Safety factor on the capillary limit sqrt(ρ̄ h³ / (2πσ)), h = min(Δx, mean edge): in (0, 1]
    /// with explicit surface tension, up to MAX_IMPLICIT_CAPILLARY_SAFETY with implicit_tension.
    double capillary_safety = 1.0;
    /// Semi-implicit surface tension (Hysing 2006; coupling/implicit_tension.h): the fraction θ
    /// of the step ahead at which the surface's tension is taken, as a surface viscosity θσΔt in
    /// the viscous solve (0 = explicit, the default; at most 1). Each capillary mode then loses
    /// a factor 1/sqrt(1 + θ(ωΔt)²) of its amplitude per step instead of growing past the
    /// explicit limit, so capillary_safety may exceed 1; the price is that extra damping, about
    /// θω²Δt/2 for a mode of frequency ω (validate B4 at 3×: γ 0.78 against 0.05 1/s; B2 11.4
    /// against 1.45, 26.7 with the full form). The coupled viscous–pressure passes do not converge
    /// with the term (8 of 8): large runs are best done with the incremental scheme
    /// (docs/validation.md). θ = 1 is the validated value: θ = ½ let the capillary wave grow
    /// unstable at 3× the limit (max|u| 1.8 m/s against 0.1). Needs interpolate.method trilinear:
    /// with the one-sided vertex velocities a water drop in air (validate B2, 12 cells per
    /// diameter) at 3× the limit grew unstable within 4 ms whether the term sampled the grid as
    /// the one-sided method or trilinearly (max|u| 0.063 and 0.038 m/s against the explicit
    /// run's 0.024); with trilinear ones it stays within the explicit run's 0.025 for 25 ms.
    /// In two_phase mode the mesh then moves with the term's own density-weighted weights
    /// (term_vertex_velocities()), not with the plain trilinear vertex velocities.
    double implicit_tension = 0.0;
    /// Which surface stiffness the implicit term uses (implicit_tension.h): `normal` (only
    /// shape-changing motion is damped) or Hysing's `full` (the surface's stretching too, which
    /// immobilised bubble_merge's interfaces: its film did not drain).
    SurfaceTermForm implicit_tension_form = SurfaceTermForm::normal;
    void validate() const;  ///< throws std::invalid_argument naming the field
};

/// Which limit set a step's Δt.
enum class StepLimit { cfl, capillary, frame_end, max_dt };
const char* to_string(StepLimit limit);

/// Wall-clock and process-CPU seconds of the phases of a coupled step; `fluid` is split
/// further in SimulationStepReport::fluid.timings.
struct SimulationTimings {
    PhaseSeconds rasterize;          ///< mesh → φ on the grid (OpenVDB level set)
    PhaseSeconds curvature;          ///< κ on the faces the interface crosses, sub-grid tension
    PhaseSeconds fluid;              ///< FluidSolver::step
    PhaseSeconds interpolate;        ///< grid velocities → mesh vertices
    PhaseSeconds volume_correction;  ///< component matching and the volume-restoring motion
    PhaseSeconds tracker;            ///< improvement, topology changes, collision-safe motion
    PhaseSeconds total;

    /// Adds every phase of `other` (a frame's sum over its steps).
    SimulationTimings& operator+=(const SimulationTimings& other) {
        for (auto [mine, theirs] :
             {std::pair{&rasterize, &other.rasterize}, {&curvature, &other.curvature},
              {&fluid, &other.fluid}, {&interpolate, &other.interpolate},
              {&volume_correction, &other.volume_correction}, {&tracker, &other.tracker},
              {&total, &other.total}})
            *mine += *theirs;
        return *this;
    }
};

/// What one coupled step did.
struct SimulationStepReport {
    double dt = 0.0;
    StepLimit limit = StepLimit::max_dt;
    fluid::StepResult fluid;
    tracker::IntegrateResult integrate;
    tracker::ImproveReport improve;
    tracker::TopologyReport topology;
    VolumeReport volume;
    OpenBoundaryReport open_boundaries;  ///< mesh clipped at outflow faces, volume let in
    double max_vertex_speed = 0.0;  ///< m/s, interpolated
    SimulationTimings timings;
};

/// Periodic faces (issue 39): the surface mesh must wrap exactly where the fluid box is periodic
/// (SurfaceMesh::set_periods with the box's origin and lengths along those axes), and inflow or
/// outflow faces are not available with periodic ones yet. Throws std::invalid_argument naming
/// the axis and the conflict.
void check_periods(const tracker::SurfaceMesh& mesh, const fluid::MacGrid& grid,
                   const fluid::BoundaryOptions& boundaries);
/// The same for a box of `cells` cells of edge `dx` from `box_min`, periodic along the axes
/// whose faces in `boundaries` are (a distributed solver's whole box, FluidSolver::box_min()).
void check_periods(const tracker::SurfaceMesh& mesh, const Eigen::Vector3d& box_min,
                   const std::array<int, 3>& cells, double dx,
                   const fluid::BoundaryOptions& boundaries);

/// Owns the tracker and the fluid solver and steps them together. A periodic mesh is rasterized
/// and its curvature taken on its images around the box (periodic_images.h); vertex velocities
/// are sampled on the periodic grid.
///
/// With a FluidSolver split over MPI ranks (issue 40) every rank holds a Simulation and steps it
/// together with the others: the tracker is replicated (every rank moves the same mesh with the
/// same velocities, and a checksum of the vertex positions is compared across the ranks after
/// every step: a difference throws std::runtime_error), each rank rasterizes φ and κ on its own
/// block, and each vertex's velocity is interpolated by the rank owning the cell layer it lies
/// in and summed over the ranks. Not available there (throws std::invalid_argument naming the
/// field): inflow and outflow faces, implicit_tension.
class Simulation {
public:
    /// Throws std::invalid_argument on bad options or periods that do not match (check_periods).
    Simulation(tracker::SurfaceTracker tracker, fluid::FluidSolver fluid,
               const SimulationOptions& options);

    /// Advances by one step of at most `time_left` (s, the time left to the next frame; reported
    /// as StepLimit::frame_end when it binds) and at most `max_dt` (s, a scene's largest step;
    /// reported, like the fluid's own TimeStepOptions::max_dt, as StepLimit::max_dt). Throws
    /// std::invalid_argument unless both are > 0, and UnstableStep (step_guard.h) when the
    /// fluid step went unstable: the surface would cross many cells (the state is then that of
    /// the fluid after the step, the mesh before it).
    SimulationStepReport step(double time_left,
                              double max_dt = std::numeric_limits<double>::infinity());

    const tracker::SurfaceTracker& tracker() const { return *m_tracker; }
    const fluid::FluidSolver& fluid() const { return m_fluid; }
    double time() const { return m_time; }
    /// Per-vertex velocities of the last step interpolated from the grid (sized
    /// mesh().num_vertices()), m/s; without the sub-grid and volume-correction terms.
    const std::vector<tracker::Vec3>& vertex_velocities() const { return m_vertex_velocities; }
    /// Kinetic energy ½ Σ ρ u² dV over the grid's faces (J), liquid and gas by φ (collective on
    /// several ranks: the whole grid's).
    double kinetic_energy() const;
    /// Volumes that entered through inflow faces and were clipped off at outflow faces since the
    /// start of the run (m³; kept in the state).
    const BoundaryVolumes& boundary_volumes() const { return m_boundary_volumes; }

    /// Exact state for checkpoints: time, tracker, fluid, volume targets, the last vertex
    /// velocities, φ and the volumes through the open faces; a Simulation built from the same scene
    /// and given this state steps exactly as this one would. load_state() throws FormatError on
    /// truncated or mismatched data (then the simulation must not be stepped). On several ranks
    /// both are collective and the state is the one a single process would hold: rank 0's `out`
    /// gets the grid's fields gathered from every rank (the other ranks' `out` is not a state), and
    /// every rank loads the whole state and keeps its block, so a state resumes on any number of
    /// ranks.
    void save_state(BinaryWriter& out) const;
    void load_state(BinaryReader& in);

private:
    /// Adds the sub-grid surface-tension velocity (subgrid_tension_velocities(), rate from
    /// options.surface_tension) to `velocities`, each capped at a quarter edge per `dt`.
    void add_subgrid_tension(std::vector<tracker::Vec3>& velocities, double dt) const;
    /// How far beyond the box a periodic mesh is unrolled for the grid-side code (m).
    double unroll_margin(double mean_edge) const;
    /// Several ranks: keeps each vertex's velocity from the rank that owns it, on every rank.
    void combine_rank_velocities(std::vector<tracker::Vec3>& velocities) const;
    /// Several ranks: throws std::runtime_error unless every rank holds the same mesh.
    void check_replicated_mesh() const;

    std::unique_ptr<tracker::SurfaceTracker> m_tracker;  // stable address for the observer
    fluid::FluidSolver m_fluid;
    SimulationOptions m_options;
    std::unique_ptr<VolumeTracker> m_volumes;
    std::vector<tracker::Vec3> m_vertex_velocities;
    fluid::Array3<double> m_phi;  ///< φ of the last step, for the kinetic energy
    BoundaryVolumes m_boundary_volumes;
    double m_time = 0.0;
};

}  // namespace meniscus::coupling
