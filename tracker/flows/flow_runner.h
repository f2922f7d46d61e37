#pragma once
/// \file Driving a geometric flow over a time interval (paper §4): step-size control per flow
/// and a pluggable integration callback, so that the collision-safe SurfaceTracker::integrate
/// (and remeshing / topology changes between steps) can be slotted in by the caller.
///
/// A FlowStepper proposes displacements for one step from the current mesh: its own step
/// control decides the step length (face offsetting: the inversion limit; mean curvature: the
/// CFL limit; velocity fields: the fixed step with RK4). run_flow() loops: optional
/// `between_steps` hook (improve(), change_topology(), …), stepper, integrator, until t_end.

#include "tracker/flows/face_offsetting.h"
#include "tracker/flows/mean_curvature.h"
#include "tracker/flows/velocity_field.h"
#include "tracker/mesh.h"

#include <functional>
#include <vector>

namespace meniscus::tracker {

/// Displacements a stepper proposes for one step.
struct FlowStep {
    std::vector<Vec3> displacements;  ///< per vertex slot (m); zero for dead vertices
    double dt = 0.0;                  ///< step length they correspond to (s), ≤ the offered one
    bool shortened = false;           ///< the stepper's own limit cut the offered step
};

/// One flow's displacement provider and step control.
class FlowStepper {
public:
    virtual ~FlowStepper() = default;
    /// Displacements over [t, t + dt] with dt ≤ dt_max (dt_max > 0) for the current mesh.
    virtual FlowStep step(const SurfaceMesh& mesh, double t, double dt_max) const = 0;
};

/// Normal speed (m/s, along the outward normal) as a function of time (s).
using NormalSpeed = std::function<double(double t)>;

/// Motion in the normal direction by face offsetting (§4.1); the step is shortened so that no
/// triangle inverts (face_offset_step). The speed is sampled at the start of each step:
/// split runs at speed discontinuities (A1: run [0, 1] and [1, 2] separately).
class FaceOffsettingStepper final : public FlowStepper {
public:
    explicit FaceOffsettingStepper(NormalSpeed speed, const FaceOffsettingOptions& offsetting = {},
                                   const InversionLimitOptions& inversion = {});
    FlowStep step(const SurfaceMesh& mesh, double t, double dt_max) const override;

private:
    NormalSpeed m_speed;
    FaceOffsettingOptions m_offsetting;
    InversionLimitOptions m_inversion;
};

/// Motion in the normal direction by area-weighted vertex normals (§4.1, for comparison), with
/// the same inversion limit as face offsetting so both runs take comparable steps.
class VertexNormalStepper final : public FlowStepper {
public:
    explicit VertexNormalStepper(NormalSpeed speed, const InversionLimitOptions& inversion = {});
    FlowStep step(const SurfaceMesh& mesh, double t, double dt_max) const override;

private:
    NormalSpeed m_speed;
    InversionLimitOptions m_inversion;
};

/// Motion by mean curvature (§4.2): forward Euler (or Heun, MeanCurvatureFlowOptions) with
/// dt = min(dt_max, CFL limit).
class MeanCurvatureStepper final : public FlowStepper {
public:
    explicit MeanCurvatureStepper(const MeanCurvatureFlowOptions& options = {});
    FlowStep step(const SurfaceMesh& mesh, double t, double dt_max) const override;

private:
    MeanCurvatureFlowOptions m_options;
};

/// Advection through a velocity field (§4.3: Enright, curl noise): classical RK4 with the
/// offered step. The field is not owned and must outlive the stepper.
class VelocityFieldStepper final : public FlowStepper {
public:
    /// `cancel` is checked per vertex (rk4_displacements()).
    explicit VelocityFieldStepper(const VelocityField& field, CancellationToken cancel = {})
        : m_field(&field), m_cancel(cancel) {}
    FlowStep step(const SurfaceMesh& mesh, double t, double dt_max) const override;

private:
    const VelocityField* m_field;
    CancellationToken m_cancel;
};

/// Moves the mesh by `displacements` over a step of `dt` seconds and returns the time actually
/// advanced, in (0, dt] (a collision-safe integrator may apply only part of the motion:
/// return dt × its motion fraction). Wrap SurfaceTracker::integrate as
/// `[&](SurfaceMesh&, const auto& d, double dt) { velocities = d / dt; return
/// tracker.integrate(velocities, dt).time_advanced; }` with run_flow on tracker.mesh().
using FlowIntegrator =
    std::function<double(SurfaceMesh& mesh, const std::vector<Vec3>& displacements, double dt)>;

/// Called before each step with the current time (remeshing, topology changes, output).
using BetweenSteps = std::function<void(SurfaceMesh& mesh, double t)>;

/// The default FlowIntegrator: x += d for every live vertex (no collision handling); returns dt.
double move_vertices(SurfaceMesh& mesh, const std::vector<Vec3>& displacements, double dt);

/// Options of run_flow().
struct FlowRunOptions {
    double max_dt = 0.005;  ///< step offered to the stepper (s, > 0); RK4 flows use it as is
    /// Stop (not completed) when a step would advance less than this fraction of max_dt
    /// (a stalled inversion limit or integrator); in (0, 1).
    double min_dt_fraction = 1e-6;
    int max_steps = 1000000;  ///< bound on the number of steps (≥ 1)
    void validate() const;    ///< throws std::invalid_argument naming the field
};

/// Why run_flow() returned.
enum class FlowRunStop {
    reached_end,   ///< t_end reached
    step_stalled,  ///< a step advanced less than min_dt_fraction · max_dt
    max_steps,     ///< max_steps taken before t_end
};

/// What run_flow() did.
struct FlowRunReport {
    FlowRunStop stop = FlowRunStop::reached_end;
    double t = 0.0;           ///< time reached (s)
    int steps = 0;            ///< integrator calls
    int shortened_steps = 0;  ///< steps the stepper's own limit shortened
    int partial_steps = 0;    ///< steps the integrator applied only in part
    double min_dt = 0.0;      ///< shortest time advanced by one step (s)
    double max_dt = 0.0;      ///< longest (s)
};

/// Runs `stepper` on `mesh` from t_begin to t_end (> t_begin): each step offers
/// min(max_dt, t_end − t) to the stepper, hands its displacements to `integrator` and advances
/// t by what the integrator reports. `between_steps` (if set) runs before every step. Throws
/// std::invalid_argument on invalid options or interval; a stalled run is reported, not thrown.
FlowRunReport run_flow(SurfaceMesh& mesh, const FlowStepper& stepper, double t_begin, double t_end,
                       const FlowRunOptions& options = {},
                       const FlowIntegrator& integrator = move_vertices,
                       const BetweenSteps& between_steps = {});

}  // namespace meniscus::tracker
