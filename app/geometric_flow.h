#pragma once
/// \file The geometric flows of a scene (paper §4; /flow other than "fluid"): the stepper a
/// /flow section describes, one step of it with a user's field's failures named as scene errors,
/// and the /flow/exact reference the surface is measured against frame by frame.

#include "app/scene.h"
#include "common/binary_io.h"
#include "common/cancellation.h"
#include "tracker/flows/flow_errors.h"
#include "tracker/flows/flow_runner.h"
#include "tracker/flows/velocity_field.h"
#include "tracker/mesh.h"

#include <nlohmann/json.hpp>

#include <memory>
#include <string>
#include <vector>

namespace meniscus::app {

/// A geometric flow ready to step: the stepper owns its step control; `field` keeps the velocity
/// field a VelocityFieldStepper points to alive. No stepper for "none".
struct GeometricFlow {
    std::unique_ptr<tracker::VelocityField> field;
    std::unique_ptr<tracker::FlowStepper> stepper;
    std::vector<double> breakpoints;  ///< times steps must end on (speed discontinuities)
};

/// The flow of /flow (not "fluid": those scenes run through the coupled simulation).
GeometricFlow make_flow(const FlowOptions& flow, const CancellationToken& cancel);

/// One step of a geometric flow. A user's field that is not finite where the surface is
/// (/flow/expression: ExpressionField throws std::domain_error) is a scene error (InputError).
tracker::FlowStep flow_step(const tracker::FlowStepper& stepper, const tracker::SurfaceMesh& mesh,
                            double t, double dt, const Scene& scene);

/// /flow/exact: the error of the surface against an exact solution, per frame.
class ExactSolution {
public:
    /// `end_time`: the run's last frame time (a never-reversing A1 speed grows until then).
    ExactSolution(const Scene& scene, double end_time);

    bool enabled() const { return m_options.type != "none"; }

    /// Throws InputError if the run ends after the exact surface vanishes (the scene's own end
    /// time is checked when it is read; --frames can extend it).
    void check_end(double end_time) const;

    /// Throws InputError unless the initial surface is the exact solution at t = 0: every vertex
    /// within INITIAL_VERTEX_TOLERANCE · ξ of it and the enclosed volume within
    /// INITIAL_VOLUME_TOLERANCE of the exact one (so that, say, one sphere of the two fails).
    /// rigid_motion: the initial surface is its own exact solution; it is kept for stats().
    void check_initial(const tracker::SurfaceMesh& mesh, double xi);

    /// The stats.jsonl entry at time t.
    nlohmann::json stats(const tracker::SurfaceMesh& mesh, double t) const;

    /// Exact state for checkpoints: the rigid_motion start (nothing for the other exact
    /// solutions, which are closed forms of t).
    void save_state(BinaryWriter& out) const;
    void load_state(BinaryReader& in);

private:
    /// Vertices of the meshed initial shape sit within 1e-3 ξ of it (implicit_mesher).
    static constexpr double INITIAL_VERTEX_TOLERANCE = 1e-2;
    /// Relative volume slack: a polyhedron inscribed in a sphere loses about ℓ²/(4R²).
    static constexpr double INITIAL_VOLUME_TOLERANCE = 0.05;

    /// rigid_motion: the initial mesh carried by the exact rigid map to time t against the
    /// surface, both ways (tracker::hausdorff_distance): `linf`/`l1` are the surface's distances
    /// from the exact one, `hausdorff` the larger of the two one-sided maxima.
    nlohmann::json rigid_motion_stats(const tracker::SurfaceMesh& mesh, double t) const;
    tracker::SurfaceError error(const tracker::SurfaceMesh& mesh, double t) const;
    double initial_volume() const;

    ExactSolutionOptions m_options;
    tracker::TwoSphereNormalFlow m_two_spheres;
    tracker::RigidMotionField m_rigid;
    tracker::SurfaceMesh m_initial;  ///< rigid_motion: the surface at t = 0
    std::string m_source;
};

}  // namespace meniscus::app
