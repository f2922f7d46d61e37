#include "tracker/flows/flow_runner.h"

#include "tracker/flows/vertex_normal_motion.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include <utility>

namespace meniscus::tracker {

namespace {

NormalSpeed checked(NormalSpeed speed) {
    if (!speed)
        throw std::invalid_argument("speed: expected a callable normal speed");
    return speed;
}

}  // namespace

FaceOffsettingStepper::FaceOffsettingStepper(NormalSpeed speed,
                                             const FaceOffsettingOptions& offsetting,
                                             const InversionLimitOptions& inversion)
    : m_speed(checked(std::move(speed))), m_offsetting(offsetting), m_inversion(inversion) {
    offsetting.validate();
    inversion.validate();
}

FlowStep FaceOffsettingStepper::step(const SurfaceMesh& mesh, double t, double dt_max) const {
    const std::vector<double> speeds(static_cast<size_t>(mesh.num_triangles()), m_speed(t));
    FaceOffsetStep s = face_offset_step(mesh, speeds, dt_max, m_offsetting, m_inversion);
    return {std::move(s.displacements), s.dt, s.shortened};
}

VertexNormalStepper::VertexNormalStepper(NormalSpeed speed, const InversionLimitOptions& inversion)
    : m_speed(checked(std::move(speed))), m_inversion(inversion) {
    inversion.validate();
}

FlowStep VertexNormalStepper::step(const SurfaceMesh& mesh, double t, double dt_max) const {
    FlowStep s{vertex_normal_displacements(mesh, m_speed(t), dt_max), dt_max, false};
    const double fraction = max_non_inverting_step_fraction(mesh, s.displacements, m_inversion);
    if (fraction < 1.0) {  // displacements are linear in Δt
        for (Vec3& d : s.displacements)
            d *= fraction;
        s.dt *= fraction;
        s.shortened = true;
    }
    return s;
}

MeanCurvatureStepper::MeanCurvatureStepper(const MeanCurvatureFlowOptions& options)
    : m_options(options) {
    options.validate();
}

FlowStep MeanCurvatureStepper::step(const SurfaceMesh& mesh, double /*t*/, double dt_max) const {
    const double cfl = mean_curvature_time_step(mesh, m_options);
    const double dt = std::min(dt_max, cfl);
    return {mean_curvature_displacements(mesh, dt, m_options), dt, cfl < dt_max};
}

FlowStep VelocityFieldStepper::step(const SurfaceMesh& mesh, double t, double dt_max) const {
    return {rk4_displacements(mesh, *m_field, t, dt_max, m_cancel), dt_max, false};
}

double move_vertices(SurfaceMesh& mesh, const std::vector<Vec3>& displacements, double dt) {
    if (displacements.size() != static_cast<size_t>(mesh.num_vertices()))
        throw std::invalid_argument("displacements: expected one per vertex slot");
    for (int vi = 0; vi < mesh.num_vertices(); ++vi)
        if (mesh.vertex_alive(vi))
            mesh.set_position(vi, mesh.position(vi) + displacements[static_cast<size_t>(vi)]);
    return dt;
}

void FlowRunOptions::validate() const {
    if (!(max_dt > 0.0) || !std::isfinite(max_dt))
        throw std::invalid_argument("max_dt: expected a finite number > 0 (s)");
    if (!(min_dt_fraction > 0.0 && min_dt_fraction < 1.0))
        throw std::invalid_argument("min_dt_fraction: expected a number in (0, 1)");
    if (max_steps < 1)
        throw std::invalid_argument("max_steps: expected an integer >= 1");
}

FlowRunReport run_flow(SurfaceMesh& mesh, const FlowStepper& stepper, double t_begin, double t_end,
                       const FlowRunOptions& options, const FlowIntegrator& integrator,
                       const BetweenSteps& between_steps) {
    options.validate();
    if (!std::isfinite(t_begin) || !std::isfinite(t_end) || !(t_end > t_begin))
        throw std::invalid_argument("t_end: expected a finite time after t_begin");
    if (!integrator)
        throw std::invalid_argument("integrator: expected a callable");

    FlowRunReport report;
    report.t = t_begin;
    report.min_dt = std::numeric_limits<double>::infinity();
    const double min_advance = options.min_dt_fraction * options.max_dt;
    while (report.t < t_end) {
        if (report.steps >= options.max_steps) {
            report.stop = FlowRunStop::max_steps;
            break;
        }
        if (between_steps)
            between_steps(mesh, report.t);
        const double remaining = t_end - report.t;
        // Take the last bit in one step rather than leaving a sliver of time behind.
        const double offered = remaining <= options.max_dt * (1.0 + options.min_dt_fraction)
                                   ? remaining
                                   : options.max_dt;
        const FlowStep step = stepper.step(mesh, report.t, offered);
        if (!(step.dt >= min_advance) && step.dt < remaining) {
            report.stop = FlowRunStop::step_stalled;
            break;
        }
        const double advanced = integrator(mesh, step.displacements, step.dt);
        ++report.steps;
        report.shortened_steps += step.shortened;
        report.partial_steps += advanced < step.dt;
        report.min_dt = std::min(report.min_dt, advanced);
        report.max_dt = std::max(report.max_dt, advanced);
        // Land exactly on t_end when the whole remaining interval was taken.
        report.t = advanced >= remaining ? t_end : report.t + advanced;
        if (!(advanced >= min_advance) && report.t < t_end) {
            report.stop = FlowRunStop::step_stalled;
            break;
        }
    }
    if (report.steps == 0)
        report.min_dt = 0.0;
    return report;
}

}  // namespace meniscus::tracker
