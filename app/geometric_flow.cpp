#include "app/geometric_flow.h"

#include "app/errors.h"
#include "tracker/mesh_measures.h"

#include <cmath>
#include <sstream>
#include <stdexcept>

namespace meniscus::app {

using tracker::SurfaceMesh;

GeometricFlow make_flow(const FlowOptions& flow, const CancellationToken& cancel) {
    // "fluid" scenes never get here (run_fluid_scene).
    GeometricFlow g;
    if (flow.type == "enright" || flow.type == "curl_noise" || flow.type == "rigid" ||
        flow.type == "expression") {
        if (flow.type == "enright")
            g.field = std::make_unique<tracker::EnrightField>(flow.period);
        else if (flow.type == "curl_noise")
            g.field = std::make_unique<tracker::CurlNoiseField>(flow.curl_noise);
        else if (flow.type == "rigid")
            g.field = std::make_unique<tracker::RigidMotionField>(flow.rigid);
        else
            g.field = std::make_unique<tracker::ExpressionField>(flow.expression);
        g.stepper = std::make_unique<tracker::VelocityFieldStepper>(*g.field, cancel);
    } else if (flow.type == "normal_speed") {
        const NormalSpeedOptions& n = flow.normal_speed;
        const double speed = n.speed, reversal = n.reversal_time;
        const tracker::NormalSpeed normal_speed = [speed, reversal](double t) {
            return reversal > 0.0 && t >= reversal ? -speed : speed;
        };
        if (n.method == "face_offsetting")
            g.stepper = std::make_unique<tracker::FaceOffsettingStepper>(
                normal_speed, n.face_offsetting, n.inversion);
        else
            g.stepper = std::make_unique<tracker::VertexNormalStepper>(normal_speed, n.inversion);
        if (reversal > 0.0)
            g.breakpoints.push_back(reversal);
    } else if (flow.type == "mean_curvature") {
        g.stepper = std::make_unique<tracker::MeanCurvatureStepper>(flow.mean_curvature);
    }
    return g;
}

tracker::FlowStep flow_step(const tracker::FlowStepper& stepper, const SurfaceMesh& mesh, double t,
                            double dt, const Scene& scene) {
    try {
        return stepper.step(mesh, t, dt);
    } catch (const std::domain_error& e) {
        throw InputError(scene.source_path + ": /flow/expression/" + e.what() +
                         ": the field must be finite wherever the surface goes");
    }
}

ExactSolution::ExactSolution(const Scene& scene, double end_time)
    : m_options(scene.flow.exact),
      m_two_spheres(two_sphere_normal_flow(scene, end_time)),
      m_rigid(scene.flow.rigid),
      m_source(scene.source_path) {}

void ExactSolution::check_end(double end_time) const {
    if (m_options.type == "rigid_motion")
        return;  // never vanishes
    const double vanishes =
        m_options.type == "two_sphere_normal_flow"
            ? m_two_spheres.reversal_time +
                  (m_two_spheres.initial_radius +
                   m_two_spheres.speed * m_two_spheres.reversal_time) /
                      m_two_spheres.speed
            : 0.25 * m_options.radius * m_options.radius;
    if (end_time < vanishes)
        return;
    std::ostringstream s;
    s << m_source << ": /flow/exact: the run ends at t = " << end_time
      << " s, when the exact surface no longer exists (it vanishes at t = " << vanishes
      << " s): use fewer --frames";
    throw InputError(s.str());
}

void ExactSolution::check_initial(const SurfaceMesh& mesh, double xi) {
    if (m_options.type == "rigid_motion") {
        m_initial = mesh;
        return;
    }
    const tracker::SurfaceError e = error(mesh, 0.0);
    const double volume = tracker::enclosed_volume(mesh), exact = initial_volume();
    if (e.vertex_linf <= INITIAL_VERTEX_TOLERANCE * xi &&
        std::abs(volume - exact) <= INITIAL_VOLUME_TOLERANCE * exact)
        return;
    std::ostringstream s;
    s << m_source << ": /flow/exact: the initial surface is not the exact "
      << m_options.type << " solution at t = 0 (vertices up to " << e.vertex_linf
      << " m off it, allowed " << INITIAL_VERTEX_TOLERANCE * xi << "; volume " << volume
      << " m³, exact " << exact << "): make /surface/shape the same sphere(s)";
    throw InputError(s.str());
}

nlohmann::json ExactSolution::stats(const SurfaceMesh& mesh, double t) const {
    if (m_options.type == "rigid_motion")
        return rigid_motion_stats(mesh, t);
    const tracker::SurfaceError e = error(mesh, t);
    nlohmann::json j = {{"type", m_options.type},
                        {"linf", e.linf},
                        {"l1", e.l1},
                        {"vertex_linf", e.vertex_linf},
                        {"vertex_l1", e.vertex_l1}};
    if (m_options.type == "sphere_mean_curvature")
        j["radius"] = tracker::sphere_mean_curvature_radius(m_options.radius, t);
    return j;
}

void ExactSolution::save_state(BinaryWriter& out) const {
    if (m_options.type == "rigid_motion")
        m_initial.save_state(out);
}

void ExactSolution::load_state(BinaryReader& in) {
    if (m_options.type == "rigid_motion")
        m_initial.load_state(in);
}

nlohmann::json ExactSolution::rigid_motion_stats(const SurfaceMesh& mesh, double t) const {
    SurfaceMesh exact = m_initial;
    for (int vi = 0; vi < exact.num_vertices(); ++vi)
        if (exact.vertex_alive(vi))
            exact.set_position(vi, m_rigid.position(exact.position(vi), t));
    const tracker::HausdorffDistance h =
        tracker::hausdorff_distance(mesh, exact, m_options.sampling);
    return {{"type", m_options.type},
            {"hausdorff", h.symmetric},
            {"linf", h.a_to_b.linf},
            {"l1", h.a_to_b.l1},
            {"vertex_linf", h.a_to_b.vertex_linf},
            {"vertex_l1", h.a_to_b.vertex_l1},
            {"exact_to_surface_linf", h.b_to_a.linf},
            {"exact_to_surface_l1", h.b_to_a.l1}};
}

tracker::SurfaceError ExactSolution::error(const SurfaceMesh& mesh, double t) const {
    if (m_options.type == "two_sphere_normal_flow")
        return tracker::two_sphere_normal_flow_error(mesh, m_two_spheres, t,
                                                     m_options.sampling);
    return tracker::sphere_error(mesh, m_options.center0,
                                 tracker::sphere_mean_curvature_radius(m_options.radius, t),
                                 m_options.sampling);
}

double ExactSolution::initial_volume() const {
    const double r = m_options.radius, ball = 4.0 / 3.0 * M_PI * r * r * r;
    if (m_options.type != "two_sphere_normal_flow")
        return ball;
    const double d = (m_options.center1 - m_options.center0).norm();
    // Two equal balls overlapping in a lens of volume π(4r + d)(2r − d)²/12.
    const double lens = d < 2.0 * r ? M_PI * (4.0 * r + d) * (2.0 * r - d) * (2.0 * r - d) / 12.0
                                    : 0.0;
    return 2.0 * ball - lens;
}

}  // namespace meniscus::app
