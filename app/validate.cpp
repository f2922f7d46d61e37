/// `meniscus validate`: geometric-flow validation cases of docs/validation.md part A, each a set
/// of tracked runs (app/validate_run.h) measured against its exact or reference solution, and
/// the driver that runs the selected cases of parts A and B and writes the report.

#include "app/scene_setup.h"
#include "app/validate.h"

#include "app/validate_fluid.h"
#include "app/validate_parameters.h"
#include "app/validate_report.h"
#include "app/validate_run.h"
#include "app/validate_zalesak.h"
#include "coupling/levelset_reference.h"
#include "tracker/flows/axisymmetric_mcf_reference.h"
#include "tracker/flows/curl_noise.h"
#include "tracker/flows/flow_errors.h"
#include "tracker/flows/flow_runner.h"
#include "tracker/flows/velocity_field.h"
#include "tracker/implicit_shape.h"
#include "tracker/mesh_measures.h"

#include <nlohmann/json.hpp>
#include <tbb/global_control.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <future>
#include <limits>
#include <memory>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

namespace meniscus::app {
namespace {

using tracker::SurfaceMesh;
using tracker::Vec3;
using Json = nlohmann::json;
using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point start) {
    return std::chrono::duration<double>(Clock::now() - start).count();
}

using namespace flow_validation;

// ---- Cases ------------------------------------------------------------------------------------

/// The resolutions ξ (m) each part-A case runs, in order; A1's and A4's include their
/// collision-safety-off runs.
std::vector<double> a1_xis(bool full) {
    return full ? std::vector<double>{0.04, 0.02, 0.01} : std::vector<double>{0.04};
}
std::vector<double> a2_sphere_xis(bool full) {
    return full ? std::vector<double>{0.04, 0.02} : std::vector<double>{0.04};
}
std::vector<double> a2_dumbbell_xis(bool full) {
    return full ? std::vector<double>(std::begin(A2_FULL_XI), std::end(A2_FULL_XI))
                : std::vector<double>(std::begin(A2_QUICK_XI), std::end(A2_QUICK_XI));
}
std::vector<double> a2_spheroid_xis(bool full) {
    return full
               ? std::vector<double>(std::begin(A2_SPHEROID_FULL_XI), std::end(A2_SPHEROID_FULL_XI))
               : std::vector<double>(std::begin(A2_SPHEROID_QUICK_XI),
                                     std::end(A2_SPHEROID_QUICK_XI));
}
std::vector<double> a3_xis(bool full) {
    return full ? std::vector<double>{0.02, 0.01} : std::vector<double>{0.02};
}
std::vector<double> case_xis(const std::string& id, bool full) {
    std::vector<double> xis;
    if (id == "A1") {
        xis = a1_xis(full);
        xis.push_back(A1_UNSAFE_XI);
    } else if (id == "A2") {
        xis = a2_sphere_xis(full);
        for (double xi : a2_spheroid_xis(full))
            xis.push_back(xi);
        for (double xi : a2_dumbbell_xis(full))
            xis.push_back(xi);
    } else if (id == "A3") {
        xis = a3_xis(full);
    } else if (id == "A4") {
        xis = {CURL_XI};
        if (full)
            xis.insert(xis.end(), std::begin(CURL_XI_FULL), std::end(CURL_XI_FULL));
    } else if (id == "A6") {
        xis = zalesak_xis(full);
    }
    return xis;
}

bool same_xi(double a, double b) {
    return std::abs(a - b) <= 1e-6 * std::max(a, b);
}

struct Context {
    bool full = false;
    bool quiet = false;
    std::vector<double> xis;  ///< ValidateOptions::xis: empty runs every resolution
    /// ValidateOptions::curvature_operators: empty runs both.
    std::vector<std::string> curvature_operators;

    /// Whether a run at resolution `xi` is selected.
    bool runs_xi(double xi) const {
        return xis.empty() ||
               std::any_of(xis.begin(), xis.end(), [xi](double x) { return same_xi(x, xi); });
    }
    /// Whether A2 runs with the cotangent (false) or the quartic-fit (true) operator.
    bool runs_operator(bool quartic_fit) const {
        const std::string name = quartic_fit ? "quartic_fit" : "cotangent";
        return curvature_operators.empty() ||
               std::find(curvature_operators.begin(), curvature_operators.end(), name) !=
                   curvature_operators.end();
    }
    /// Whether the quartic-fit dumbbell rows run: in full mode, or when named.
    bool runs_quartic_dumbbell() const {
        return runs_operator(true) &&
               (full || A2_QUARTIC_FIT_DUMBBELL_IN_QUICK || !curvature_operators.empty());
    }
    Json runs = Json::array();
    bool all_ok = true;
    std::vector<std::string> failures;

    void add(Json run, const RunResult& r) {
        if (!r.completed) {
            all_ok = false;
            failures.push_back(r.spec.case_id + " " + r.spec.label +
                               " ξ=" + std::to_string(r.spec.xi_requested) + ": " + r.stop_reason);
        }
        if (r.spec.tracker.collision_safety &&
            (r.max_intersecting_pairs > 0 || r.initial_intersecting_pairs > 0)) {
            all_ok = false;
            failures.push_back(r.spec.case_id + " " + r.spec.label +
                               " ξ=" + std::to_string(r.spec.xi_requested) +
                               ": intersecting pairs with collision safety on");
        }
        if (!quiet) {  // every number but the time series, as soon as the run ends
            Json summary = run;
            summary.erase("series");
            std::fprintf(stderr, "    %s\n", summary.dump().c_str());
        }
        runs.push_back(std::move(run));
    }
};

void case_a1(Context& c) {
    tracker::TwoSphereNormalFlow flow;
    flow.reversal_time = A1_REVERSAL;
    const tracker::NormalSpeed speed = [flow](double t) { return flow.normal_speed(t); };
    const auto shape =
        tracker::make_union({tracker::make_sphere(flow.center0, flow.initial_radius),
                             tracker::make_sphere(flow.center1, flow.initial_radius)});
    const std::vector<double> xis = a1_xis(c.full);
    struct Method {
        const char* label;
        std::shared_ptr<const tracker::FlowStepper> stepper;
    };
    const std::vector<Method> methods = {
        {"face offsetting", std::make_shared<tracker::FaceOffsettingStepper>(speed)},
        {"vertex normals", std::make_shared<tracker::VertexNormalStepper>(speed)}};
    for (const Method& m : methods)
        for (double xi : xis) {
            if (!c.runs_xi(xi))
                continue;
            RunSpec s;
            s.case_id = "A1";
            s.label = m.label;
            s.xi_requested = xi;
            s.shape = shape;
            s.tracker = paper_tracker_options();
            s.tracker.remesh.max_normal_change_degrees = A1_MAX_NORMAL_CHANGE_DEGREES;
            // Shape accuracy over volume: split points and smoothing on the fitted surface.
            s.tracker.remesh.split_on_fitted_surface = true;
            s.tracker.remesh.smoothing_onto_fitted_surface = true;
            s.stepper = m.stepper;
            s.t_end = A1_END;
            s.max_dt = A1_DT;
            s.breakpoints = {A1_REVERSAL};
            const RunResult r = run_tracked(s, c.quiet);
            Json j = run_json(r);
            j["error"] = error_json(tracker::two_sphere_normal_flow_error(r.final_mesh, flow, r.t));
            c.add(std::move(j), r);
        }
    if (!c.runs_xi(A1_UNSAFE_XI))
        return;
    RunSpec s;
    s.case_id = "A1";
    s.label = A1_UNSAFE_LABEL;
    s.xi_requested = A1_UNSAFE_XI;
    s.shape = shape;
    s.tracker = paper_tracker_options();
    s.tracker.remesh.max_normal_change_degrees = A1_MAX_NORMAL_CHANGE_DEGREES;
    s.tracker.remesh.split_on_fitted_surface = true;
    s.tracker.remesh.smoothing_onto_fitted_surface = true;
    s.tracker.collision_safety = false;
    s.tracker.allow_topology_changes = false;
    s.stepper = methods.front().stepper;
    s.t_end = A1_UNSAFE_END;
    s.max_dt = A1_DT;
    const RunResult r = run_tracked(s, c.quiet);
    c.add(run_json(r), r);
}

/// φ(x) of a reference solution (anything with distance(x)), and the difference of two.
template <typename Reference>
auto distance_of(const Reference& ref) {
    return [&ref](const Vec3& x) { return ref.distance(x); };
}
template <typename Reference>
auto difference_of(const Reference& coarse, const Reference& fine) {
    return [&coarse, &fine](const Vec3& x) { return coarse.distance(x) - fine.distance(x); };
}

/// Axial coordinate a ≥ 0 (m) at which the reference's surface is farthest from the axis, over
/// a ∈ [0, extent] in steps of `step`: the widest section of the right-hand drop.
double widest_section(const tracker::AxisymmetricMcfReference& ref, double extent, double step) {
    constexpr int BISECTIONS = 50;
    double widest_a = 0.0, widest_r = 0.0;
    for (double a = 0.0; a <= extent; a += step) {
        if (ref.meridian_distance(a, 0.0) >= 0.0)
            continue;  // the axis is outside here
        double inside = 0.0, outside = ref.band_half_width() + extent;
        for (int k = 0; k < BISECTIONS; ++k) {
            const double r = 0.5 * (inside + outside);
            (ref.meridian_distance(a, r) < 0.0 ? inside : outside) = r;
        }
        if (inside > widest_r) {
            widest_r = inside;
            widest_a = a;
        }
    }
    return widest_a;
}

/// Largest and smallest signed φ of the reference at the live vertices of `mesh` with
/// |x| < split (the drops' inner halves, the pinched tips) and |x| ≥ split (the outer halves,
/// the bulbs' far poles).
Json error_by_half(const SurfaceMesh& mesh, const tracker::AxisymmetricMcfReference& ref,
                   double split) {
    constexpr double INF = std::numeric_limits<double>::infinity();
    double max_phi[2] = {-INF, -INF}, min_phi[2] = {INF, INF};
    for (int vi = 0; vi < mesh.num_vertices(); ++vi) {
        if (!mesh.vertex_alive(vi))
            continue;
        const Vec3& x = mesh.position(vi);
        const double phi = ref.distance(x);
        const int half = std::abs(x.x()) < split ? 0 : 1;
        max_phi[half] = std::max(max_phi[half], phi);
        min_phi[half] = std::min(min_phi[half], phi);
    }
    return {{"split_x", split},
            {"inner", {{"max", max_phi[0]}, {"min", min_phi[0]}}},
            {"outer", {{"max", max_phi[1]}, {"min", min_phi[1]}}}};
}

void case_a2(Context& c) {
    tracker::MeanCurvatureFlowOptions mcf;
    if (MCF_HEUN)
        mcf.integrator = tracker::MeanCurvatureIntegrator::heun;
    const auto stepper = std::make_shared<tracker::MeanCurvatureStepper>(mcf);
    tracker::MeanCurvatureFlowOptions fitted_mcf = mcf;
    fitted_mcf.curvature_operator = tracker::CurvatureOperator::quartic_fit;
    const auto fitted_stepper = std::make_shared<tracker::MeanCurvatureStepper>(fitted_mcf);
    tracker::TrackerOptions mcf_tracker = paper_tracker_options();
    mcf_tracker.remesh.collapse_preserves_volume = MCF_COLLAPSE_PRESERVES_VOLUME;
    mcf_tracker.remesh.curvature_edge_fraction = MCF_CURVATURE_EDGE_FRACTION;
    mcf_tracker.remesh.split_on_fitted_surface = MCF_CURVATURE_EDGE_FRACTION > 0.0;
    mcf_tracker.remesh.smoothing_onto_fitted_surface = MCF_FITTED_SMOOTHING;
    mcf_tracker.remesh.smoothing_fit_degree = MCF_SMOOTHING_FIT_DEGREE;
    mcf_tracker.remesh.smoothing_fit_max_turn = MCF_SMOOTHING_FIT_MAX_TURN;
    mcf_tracker.remesh.collapse_on_fitted_surface = MCF_COLLAPSE_ON_FITTED_SURFACE;
    tracker::TrackerOptions quartic_fit_tracker = mcf_tracker;
    quartic_fit_tracker.remesh.smoothing_fit_max_turn = MCF_QUARTIC_FIT_SMOOTHING_FIT_MAX_TURN;
    const auto mcf_run = [&](const std::string& label, double xi, tracker::ShapePtr shape,
                             const tracker::TrackerOptions& tracker, double t_end,
                             bool quartic_fit = false, int crease_levels = 0) {
        RunSpec s;
        s.case_id = "A2";
        s.label = quartic_fit ? label + A2_QUARTIC_FIT_SUFFIX : label;
        s.xi_requested = xi;
        s.shape = std::move(shape);
        s.tracker = tracker;
        s.stepper = quartic_fit ? fitted_stepper : stepper;
        s.t_end = t_end;
        s.max_dt = MCF_MAX_DT;
        s.crease.levels = crease_levels;
        return run_tracked(s, c.quiet);
    };
    {
        const Vec3 center = Vec3::Zero();
        const double t_end = MCF_SPHERE_TIME_FRACTION * MCF_SPHERE_RADIUS * MCF_SPHERE_RADIUS / 4.0;
        for (double xi : a2_sphere_xis(c.full)) {
            if (!c.runs_xi(xi) || !c.runs_operator(false))
                continue;
            const RunResult r = mcf_run(
                "sphere", xi, tracker::make_sphere(center, MCF_SPHERE_RADIUS), mcf_tracker, t_end);
            Json j = run_json(r);
            const double exact = tracker::sphere_mean_curvature_radius(MCF_SPHERE_RADIUS, r.t);
            j["initial_radius"] = MCF_SPHERE_RADIUS;
            j["exact_radius"] = exact;
            j["error"] = error_json(tracker::sphere_error(r.final_mesh, center, exact));
            c.add(std::move(j), r);
        }
    }
    // Meyer's operator alone: the spheroid with every remeshing operation off, against its own
    // axisymmetric reference (coarse and fine grid).
    {
        const tracker::ShapePtr spheroid = tracker::make_ellipsoid(
            Vec3::Zero(),
            Vec3(MCF_SPHEROID_RADII[0], MCF_SPHEROID_RADII[1], MCF_SPHEROID_RADII[2]));
        std::vector<double> xis;
        for (double xi : a2_spheroid_xis(c.full))
            if (c.runs_xi(xi))
                xis.push_back(xi);
        const double* dx = c.full ? A2_SPHEROID_DX_FULL : A2_SPHEROID_DX_QUICK;
        std::vector<tracker::AxisymmetricMcfReference> refs;
        for (int i = 0; i < 2 && !xis.empty(); ++i) {
            tracker::AxisymmetricMcfOptions o;
            o.voxel_size = dx[i];
            o.end_time = MCF_SPHEROID_END;
            refs.emplace_back(*spheroid, Vec3::Zero(), Vec3::UnitX(), o);
        }
        tracker::TrackerOptions fixed = mcf_tracker;
        fixed.remesh.split = fixed.remesh.flip = fixed.remesh.collapse = fixed.remesh.smooth =
            false;
        for (const bool quartic_fit : {false, true})
            for (double xi : xis) {
                if (!c.runs_operator(quartic_fit))
                    continue;
                const RunResult r = mcf_run("spheroid, no remeshing", xi, spheroid, fixed,
                                            MCF_SPHEROID_END, quartic_fit);
                Json j = run_json(r);
                j["error"] =
                    error_json(tracker::surface_error(r.final_mesh, distance_of(refs[1])));
                j["reference_difference"] = error_json(
                    tracker::surface_error(r.final_mesh, difference_of(refs[0], refs[1])));
                j["reference_voxel_size"] = dx[1];
                c.add(std::move(j), r);
            }
    }
    // Dumbbell: the references (axisymmetric and OpenVDB, coarse and fine grid each) are
    // computed on a second thread while the meshes run; then each mesh is measured against them.
    std::vector<double> dumbbell_xis;
    for (double xi : a2_dumbbell_xis(c.full))
        if (c.runs_xi(xi))
            dumbbell_xis.push_back(xi);
    if (dumbbell_xis.empty() || (!c.runs_operator(false) && !c.runs_quartic_dumbbell()))
        return;
    const tracker::ShapePtr dumbbell =
        tracker::make_dumbbell(Vec3::Zero(), DUMBBELL_BULB_RADIUS, DUMBBELL_SEPARATION,
                               DUMBBELL_HANDLE_RADIUS, DUMBBELL_BLEND_RADIUS);
    const double* axi_dx = c.full ? A2_AXISYMMETRIC_DX_FULL : A2_AXISYMMETRIC_DX_QUICK;
    const double* ref_dx = c.full ? A2_REFERENCE_DX_FULL : A2_REFERENCE_DX_QUICK;
    struct References {
        std::vector<tracker::AxisymmetricMcfReference> axis;
        Json axis_json = Json::array();
        std::vector<coupling::LevelSetReference> vdb;
        Json vdb_json = Json::array();
    };
    const bool quiet = c.quiet;
    std::future<References> pending = std::async(std::launch::async, [=] {
        References refs;
        for (int i = 0; i < 2; ++i) {
            tracker::AxisymmetricMcfOptions o;
            o.voxel_size = axi_dx[i];
            o.end_time = DUMBBELL_END;
            refs.axis.emplace_back(*dumbbell, Vec3::Zero(), Vec3::UnitX(), o);
            const tracker::AxisymmetricMcfStats& st = refs.axis.back().stats();
            refs.axis_json.push_back({{"voxel_size", o.voxel_size},
                                      {"time_step", st.time_step},
                                      {"steps", st.steps},
                                      {"reinit_interval", o.reinit_interval},
                                      {"band_half_width", refs.axis.back().band_half_width()},
                                      {"grid", {st.axial_cells, st.radial_cells}},
                                      {"final_band_cells", st.final_band_cells},
                                      {"seconds", st.seconds}});
            if (!quiet)
                std::fprintf(stderr,
                             "  A2 dumbbell axisymmetric reference Δx=%g: %ld steps of %g s, "
                             "%d×%d grid, %lld band cells, %.1f s\n",
                             o.voxel_size, st.steps, st.time_step, st.axial_cells, st.radial_cells,
                             st.final_band_cells, st.seconds);
        }
        for (int i = 0; i < 2; ++i) {
            coupling::LevelSetReferenceOptions o;
            o.voxel_size = ref_dx[i];
            o.end_time = DUMBBELL_END;
            refs.vdb.emplace_back(*dumbbell, o);
            const coupling::LevelSetReferenceStats& st = refs.vdb.back().stats();
            refs.vdb_json.push_back({{"voxel_size", o.voxel_size},
                                     {"time_step", st.time_step},
                                     {"steps", st.steps},
                                     {"renormalization_iterations", o.renormalization_iterations},
                                     {"band_half_width", refs.vdb.back().band_half_width()},
                                     {"initial_voxels", st.initial_voxels},
                                     {"final_voxels", st.final_voxels},
                                     {"seconds", st.seconds}});
            if (!quiet)
                std::fprintf(stderr,
                             "  A2 dumbbell OpenVDB level-set reference Δx=%g: %ld steps of %g "
                             "s, %lld → %lld band voxels, %.1f s\n",
                             o.voxel_size, st.steps, st.time_step, st.initial_voxels,
                             st.final_voxels, st.seconds);
        }
        return refs;
    });
    std::vector<RunResult> runs;
    if (c.runs_operator(false))
        for (double xi : dumbbell_xis)
            runs.push_back(mcf_run("dumbbell", xi, dumbbell, mcf_tracker, DUMBBELL_END));
    if (c.runs_quartic_dumbbell())
        for (double xi : dumbbell_xis)
            runs.push_back(mcf_run("dumbbell", xi, dumbbell, quartic_fit_tracker, DUMBBELL_END,
                                   true, A2_QUARTIC_FIT_DUMBBELL_CREASE_LEVELS));
    const References refs = pending.get();
    const double widest = widest_section(refs.axis.back(), DUMBBELL_SEPARATION, 0.5 * axi_dx[1]);
    const double axi_trusted =
        refs.axis.back().band_half_width() - A2_AXISYMMETRIC_TRUSTED_MARGIN_VOXELS * axi_dx[1];
    const double trusted =
        refs.vdb.back().band_half_width() - A2_REFERENCE_TRUSTED_MARGIN_VOXELS * ref_dx[1];
    for (const RunResult& r : runs) {
        Json j = run_json(r);
        double pinch = -1.0;
        for (size_t i = 0; i < r.series_components.size(); ++i)
            if (r.series_components[i] > r.series_components.front()) {
                pinch = r.series_t[i];
                break;
            }
        j["pinch_off_time"] = pinch < 0.0 ? Json(nullptr) : Json(pinch);
        j["euler_characteristic"] = tracker::euler_characteristic(r.final_mesh);
        // L∞, L1 as for the analytic flows (flow_errors.h), with each reference's φ. The
        // axisymmetric reference is the primary one ("error").
        const tracker::SurfaceError error =
            tracker::surface_error(r.final_mesh, distance_of(refs.axis.back()));
        j["error"] = error_json(error);
        j["error_within_reference_band"] = error.linf < axi_trusted;
        j["error_by_half"] = error_by_half(r.final_mesh, refs.axis.back(), widest);
        j["error_coarse_reference"] =
            error_json(tracker::surface_error(r.final_mesh, distance_of(refs.axis.front())));
        j["reference_difference"] = error_json(tracker::surface_error(
            r.final_mesh, difference_of(refs.axis.front(), refs.axis.back())));
        j["reference"] = refs.axis_json;
        const tracker::SurfaceError vdb_error =
            tracker::surface_error(r.final_mesh, distance_of(refs.vdb.back()));
        j["openvdb_error"] = error_json(vdb_error);
        j["openvdb_error_within_reference_band"] = vdb_error.linf < trusted;
        j["openvdb_error_coarse_reference"] =
            error_json(tracker::surface_error(r.final_mesh, distance_of(refs.vdb.front())));
        j["openvdb_reference_difference"] = error_json(
            tracker::surface_error(r.final_mesh, difference_of(refs.vdb.front(), refs.vdb.back())));
        j["openvdb_reference"] = refs.vdb_json;
        c.add(std::move(j), r);
    }
}

void case_a3(Context& c) {
    const Vec3 center = Vec3::Constant(ENRIGHT_CENTER);
    const double period = c.full ? ENRIGHT_PERIOD : ENRIGHT_QUICK_PERIOD;
    const auto field = std::make_shared<tracker::EnrightField>(period);
    // The stepper keeps a pointer to the field: hold both in one aliasing shared_ptr.
    struct Holder {
        std::shared_ptr<tracker::EnrightField> field;
        tracker::VelocityFieldStepper stepper;
    };
    const auto holder =
        std::make_shared<Holder>(Holder{field, tracker::VelocityFieldStepper(*field)});
    for (double xi : a3_xis(c.full)) {
        if (!c.runs_xi(xi))
            continue;
        RunSpec s;
        s.case_id = "A3";
        s.label = "Enright";
        s.xi_requested = xi;
        s.shape = tracker::make_sphere(center, ENRIGHT_RADIUS);
        s.tracker = paper_tracker_options();
        s.stepper = std::shared_ptr<const tracker::FlowStepper>(holder, &holder->stepper);
        s.t_end = period;
        s.max_dt = ENRIGHT_DT;
        const RunResult r = run_tracked(s, c.quiet);
        Json j = run_json(r);
        j["period"] = period;
        j["error_to_initial_sphere"] =
            error_json(tracker::sphere_error(r.final_mesh, center, ENRIGHT_RADIUS));
        c.add(std::move(j), r);
    }
}

void case_a4(Context& c) {
    struct Holder {
        tracker::CurlNoiseField field;
        tracker::VelocityFieldStepper stepper;
        explicit Holder(const tracker::CurlNoiseOptions& o) : field(o), stepper(field) {}
    };
    const auto field = [](int octaves, double rms_speed) {
        tracker::CurlNoiseOptions noise;
        noise.planar = true;
        noise.octaves = octaves;
        noise.rms_speed = rms_speed;
        noise.base_wavelength = CURL_WAVELENGTH;
        noise.time_frequency = CURL_TIME_FREQUENCY;
        return std::make_shared<Holder>(noise);
    };
    const auto paper_like = field(CURL_OCTAVES, CURL_RMS_SPEED);
    struct Curl {
        bool safety;
        double xi;
        bool thin_sheet_sizing;
        bool three_octaves;
    };
    // Quick: only the (cheap) run without collision safety, which must show intersections.
    std::vector<Curl> runs{{false, CURL_XI, false, false}};
    std::shared_ptr<Holder> multiscale;
    if (c.full) {
        for (double xi : CURL_XI_FULL)
            runs.push_back({true, xi, false, false});
        runs.push_back({true, CURL_XI, true, false});
        runs.push_back({true, CURL_XI, false, true});
        multiscale = field(CURL_MULTISCALE_OCTAVES, CURL_MULTISCALE_RMS_SPEED);
    }
    for (const auto& [safety, xi, thin_sheet_sizing, three_octaves] : runs) {
        if (!c.runs_xi(xi))
            continue;
        RunSpec s;
        s.case_id = "A4";
        s.label = !safety             ? "curl noise, collision safety off"
                  : thin_sheet_sizing ? "curl noise, thin-sheet sizing"
                  : three_octaves     ? "curl noise, three octaves"
                                      : "curl noise";
        s.xi_requested = xi;
        s.shape = tracker::make_sphere(Vec3::Zero(), CURL_RADIUS);
        s.tracker = paper_tracker_options();
        s.tracker.allow_topology_changes = false;
        s.tracker.remesh.max_volume_change_fraction = CURL_VOLUME_FRACTION;
        s.tracker.collision_safety = safety;
        if (thin_sheet_sizing) {
            s.tracker.remesh.split_on_fitted_surface = true;
            s.tracker.remesh.thin_sheet_sag_fraction = CURL_THIN_SHEET_SAG_FRACTION;
            s.tracker.remesh.min_curvature_size_fraction = CURL_THIN_SHEET_MIN_SIZE_FRACTION;
        }
        const std::shared_ptr<Holder>& holder = three_octaves ? multiscale : paper_like;
        s.stepper = std::shared_ptr<const tracker::FlowStepper>(holder, &holder->stepper);
        s.t_end = safety ? CURL_END : CURL_UNSAFE_END;
        s.max_dt = CURL_DT;
        const RunResult r = run_tracked(s, c.quiet);
        Json j = run_json(r);
        const tracker::CurlNoiseOptions& noise = holder->field.options();
        j["noise"] = {{"planar", noise.planar},
                      {"rms_speed", noise.rms_speed},
                      {"base_wavelength", noise.base_wavelength},
                      {"octaves", noise.octaves},
                      {"time_frequency", noise.time_frequency},
                      {"seed", noise.seed}};
        c.add(std::move(j), r);
    }
}

void case_a6(Context& c) {
    run_zalesak(
        c.full, c.quiet, [&c](double xi) { return c.runs_xi(xi); },
        [&c](Json run, const RunResult& r) { c.add(std::move(run), r); });
}

/// Whether `options` selects case `id` (no --case selects every case).
bool case_selected(const ValidateOptions& options, const char* id) {
    return options.cases.empty() ||
           std::find(options.cases.begin(), options.cases.end(), id) != options.cases.end();
}

}  // namespace

void check_validate_options(const ValidateOptions& options) {
    for (const std::string& id : options.cases)
        if (!is_fluid_case(id) && id != "A1" && id != "A2" && id != "A3" && id != "A4" &&
            id != "A6")
            throw std::invalid_argument("validate: unknown case '" + id +
                                        "' (expected A1, A2, A3, A4, A6 or B1 … B7)");
    for (const std::string& name : options.curvature_operators)
        if (name != "cotangent" && name != "quartic_fit")
            throw std::invalid_argument("validate: unknown curvature operator '" + name +
                                        "' (expected cotangent or quartic_fit)");
    for (double xi : options.xis) {  // each requested ξ must be one a selected case runs
        std::vector<double> offered;
        for (const char* id : {"A1", "A2", "A3", "A4", "A6"})
            if (case_selected(options, id))
                for (double x : case_xis(id, options.full))
                    if (std::find(offered.begin(), offered.end(), x) == offered.end())
                        offered.push_back(x);
        if (std::none_of(offered.begin(), offered.end(),
                         [xi](double x) { return same_xi(x, xi); })) {
            std::string list;
            for (double x : offered)
                list += (list.empty() ? "" : ", ") + format_number(x, "%g");
            throw std::invalid_argument(
                "validate: --xi " + format_number(xi, "%g") + " is not a resolution of the " +
                "selected part-A cases in " + (options.full ? "full" : "quick") + " mode (" +
                (list.empty() ? std::string("none selected") : "they run " + list) + ")");
        }
    }
}

int run_validation(const ValidateOptions& options) {
    namespace fs = std::filesystem;
    const auto wall_start = Clock::now();
    const fs::path out(options.out_dir);
    fs::create_directories(out);
    Context c;
    c.full = options.full;
    c.quiet = options.quiet;
    if (!options.quiet)
        std::fprintf(stderr, "meniscus validate (%s) → %s\n", options.full ? "full" : "quick",
                     out.string().c_str());
    check_validate_options(options);
    std::vector<std::string> fluid_cases;  // part B (app/validate_fluid.h)
    for (const std::string& id : options.cases)
        if (is_fluid_case(id))
            fluid_cases.push_back(id);
    const bool any_fluid_case = options.cases.empty() || !fluid_cases.empty();
    c.xis = options.xis;
    c.curvature_operators = options.curvature_operators;
    if (case_selected(options, "A1"))
        case_a1(c);
    if (case_selected(options, "A2"))
        case_a2(c);
    if (case_selected(options, "A3"))
        case_a3(c);
    if (case_selected(options, "A4"))
        case_a4(c);
    if (case_selected(options, "A6"))
        case_a6(c);
    FluidValidation part_b;
    if (any_fluid_case) {
        part_b = run_fluid_validation({options.full, options.quiet, fluid_cases, out});
        c.all_ok = c.all_ok && part_b.all_ok;
        c.failures.insert(c.failures.end(), part_b.failures.begin(), part_b.failures.end());
    }

    Json results;
    results["mode"] = options.full ? "full" : "quick";
    results["runs"] = c.runs;
    results["paper"] = {{"xi", PAPER_XI},
                        {"a1_linf", PAPER_A1_LINF},
                        {"a1_l1", PAPER_A1_L1},
                        {"a2_linf", PAPER_A2_LINF},
                        {"a2_l1", PAPER_A2_L1},
                        {"enright_volume_percent", PAPER_ENRIGHT_VOLUME_PERCENT},
                        {"curl_volume_percent", PAPER_CURL_VOLUME_PERCENT}};
    results["orders"] = Json::object();

    std::ostringstream md;
    md << "# Meniscus validation report (" << (options.full ? "full" : "quick") << ")\n\n"
       << "Cases of docs/validation.md part A (the paper's §4), run by `meniscus validate"
       << (options.full ? " --full" : " --quick")
       << "`. Every run uses the collision-safe SurfaceTracker unless marked otherwise, and "
          "the exact static self-intersection test runs after every step (`max intersecting "
          "pairs`).\n\n";
    std::ostringstream body;
    body << geometric_flow_report(results);
    if (any_fluid_case) {
        results["part_b"] = part_b.results;
        body << part_b.report;
    }
    results["all_ok"] = c.all_ok;
    results["failures"] = c.failures;
    results["wall_seconds"] = seconds_since(wall_start);
    // The worker threads the runs could use (--threads, MENISCUS_THREADS or every core), which
    // the timings above depend on.
    const auto threads =
        tbb::global_control::active_value(tbb::global_control::max_allowed_parallelism);
    results["threads"] = threads;
    {
        std::ofstream f(out / "results.json");
        if (!f)
            throw std::runtime_error("cannot write " + (out / "results.json").string());
        f << results.dump(1) << "\n";
    }
    const std::string plot_note =
        make_geometric_plots(out) + (any_fluid_case ? " " + make_fluid_plots(out) : std::string());
    md << "**Status: "
       << (c.all_ok ? "all runs finished, no intersections with safety on" : "FAILURES") << "**";
    for (const std::string& f : c.failures)
        md << "\n- " << f;
    md << "\n\nWall time: " << format_number(seconds_since(wall_start), "%.0f") << " s on "
       << threads << (threads == 1 ? " thread. " : " threads. ") << plot_note << "\n\n"
       << body.str();
    std::ofstream f(out / "report.md");
    if (!f)
        throw std::runtime_error("cannot write " + (out / "report.md").string());
    f << md.str();
    if (!options.quiet)
        std::fprintf(stderr, "meniscus validate: wrote %s (%.0f s)%s\n",
                     (out / "report.md").string().c_str(), seconds_since(wall_start),
                     c.all_ok ? "" : " — with failures");
    return c.all_ok ? 0 : 1;
}

}  // namespace meniscus::app
