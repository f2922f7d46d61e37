/// Report of `meniscus validate` part A: the Markdown sections (our numbers beside the paper's,
/// observed orders, per-phase costs) and the matplotlib script for the plots.

#include "app/validate_report.h"

#include "app/plot_script.h"
#include "app/validate_parameters.h"
#include "app/validate_zalesak.h"
#include "tracker/flows/curl_noise.h"
#include "tracker/flows/mean_curvature.h"
#include "tracker/remesh_options.h"

#include <cmath>
#include <cstdio>
#include <sstream>
#include <string>
#include <vector>

namespace meniscus::app {

std::string format_number(double v, const char* f) {
    char buf[64];
    std::snprintf(buf, sizeof buf, f, v);
    return buf;
}

namespace {

using namespace flow_validation;
using Json = nlohmann::json;

std::string fmt(double v, const char* f = "%.6g") {
    return format_number(v, f);
}

/// "remeshing / motion / collisions" volume change in % of the initial volume (see
/// VolumeBudget in validate.cpp).
std::string volume_by_phase(const Json& r) {
    const Json& b = r["volume_change_percent_by_phase"];
    return fmt(b["remeshing"], "%+.4f") + " / " + fmt(b["motion"], "%+.4f") + " / " +
           fmt(b["collisions"], "%+.4f");
}

double observed_order(double e_coarse, double e_fine, double xi_coarse, double xi_fine) {
    return std::log(e_coarse / e_fine) / std::log(xi_coarse / xi_fine);
}

int paper_index(double xi) {
    for (int i = 0; i < 3; ++i)
        if (std::abs(xi - PAPER_XI[i]) < 1e-12)
            return i;
    return -1;
}

std::vector<Json> select(const Json& runs, const std::string& id, const std::string& label) {
    std::vector<Json> out;
    for (const Json& r : runs)
        if (r["case"] == id && r["label"] == label)
            out.push_back(r);
    return out;
}

/// "max, min" of one half of error_by_half (A2 dumbbell).
std::string max_min(const Json& half) {
    return fmt(half["max"]) + ", " + fmt(half["min"]);
}

std::string status(const Json& r) {
    return r["completed"].get<bool>() ? ""
                                      : " (stopped: " + r["stop_reason"].get<std::string>() + ")";
}

void write_orders(std::ostringstream& md, const std::vector<Json>& rs, const char* group,
                  const char* norm, Json& orders) {
    for (size_t i = 1; i < rs.size(); ++i) {
        const double q =
            observed_order(rs[i - 1][group][norm].get<double>(), rs[i][group][norm].get<double>(),
                           rs[i - 1]["xi"].get<double>(), rs[i]["xi"].get<double>());
        md << "observed order (" << norm << ", ξ " << fmt(rs[i - 1]["xi_requested"]) << " → "
           << fmt(rs[i]["xi_requested"]) << "): **" << fmt(q, "%.2f") << "**  \n";
        orders.push_back({{"norm", norm},
                          {"xi_coarse", rs[i - 1]["xi_requested"]},
                          {"xi_fine", rs[i]["xi_requested"]},
                          {"order", q}});
    }
}

void report_a1(std::ostringstream& md, Json& results) {
    md << "## A1 — motion in the normal direction (paper §4.1, Table 4.1)\n\n"
          "Two spheres r = 0.2 at (±0.25, 0, 0), speed +0.2 for t < 1 then −0.2 to t = 2, "
          "Δt = 0.005 shortened by the inversion limit, α = 1.5ξ, β = 0.5ξ, γ = 0.1ξ³, "
          "collapses/flips refused when they turn a normal by more than "
       << fmt(A1_MAX_NORMAL_CHANGE_DEGREES, "%.0f")
       << "°. Error at the final time against the exact entropy solution (two merged balls of "
          "radius 0.4 eroded by 0.2; `two_sphere_normal_flow_error`). L∞ and L1 sample every "
          "triangle (they include the chord error of a flat triangle); vertex L∞ and L1 "
          "measure the vertices' distance only.\n\n";
    for (const char* label : {"face offsetting", "vertex normals"}) {
        const std::vector<Json> rs = select(results["runs"], "A1", label);
        if (rs.empty())
            continue;
        md << "### " << label
           << "\n\n| ξ | measured ξ | t | steps | triangles | L∞ | L∞ paper | L1 | L1 "
              "paper | vertex L∞ | vertex L1 | max intersecting pairs "
              "|\n|---|---|---|---|---|---|---|---|---|---|---|---|\n";
        for (const Json& r : rs) {
            const int pi = paper_index(r["xi_requested"].get<double>());
            const bool paper = pi >= 0 && std::string(label) == "face offsetting";
            md << "| " << fmt(r["xi_requested"]) << " | " << fmt(r["xi"], "%.4f") << " | "
               << fmt(r["t_reached"]) << status(r) << " | " << r["steps"].get<long>() << " | "
               << r["triangles_min"].get<int>() << "–" << r["triangles_max"].get<int>() << " | "
               << fmt(r["error"]["linf"]) << " | " << (paper ? fmt(PAPER_A1_LINF[pi]) : "—")
               << " | " << fmt(r["error"]["l1"]) << " | " << (paper ? fmt(PAPER_A1_L1[pi]) : "—")
               << " | " << fmt(r["error"]["vertex_linf"]) << " | " << fmt(r["error"]["vertex_l1"])
               << " | " << r["max_intersecting_pairs"].get<int>() << " |\n";
        }
        md << "\n";
        Json orders = Json::array();
        write_orders(md, rs, "error", "linf", orders);
        write_orders(md, rs, "error", "l1", orders);
        write_orders(md, rs, "error", "vertex_linf", orders);
        if (std::string(label) == "face offsetting")
            md << "paper's orders: L∞ "
               << fmt(observed_order(PAPER_A1_LINF[0], PAPER_A1_LINF[1], 0.04, 0.02), "%.2f")
               << ", "
               << fmt(observed_order(PAPER_A1_LINF[1], PAPER_A1_LINF[2], 0.02, 0.01), "%.2f")
               << "; L1 " << fmt(observed_order(PAPER_A1_L1[0], PAPER_A1_L1[1], 0.04, 0.02), "%.2f")
               << ", " << fmt(observed_order(PAPER_A1_L1[1], PAPER_A1_L1[2], 0.02, 0.01), "%.2f")
               << "\n";
        if (rs.size() < 2)
            md << "(one resolution only in this mode: no observed order; run `--full`.)\n";
        md << "\n";
        results["orders"]["A1 " + std::string(label)] = orders;
    }
    for (const Json& r : select(results["runs"], "A1", A1_UNSAFE_LABEL)) {
        double first = -1.0;
        const Json& series = r["series"];
        for (size_t i = 0; i < series["t"].size(); ++i)
            if (series["intersecting_pairs"][i].get<int>() > 0) {
                first = series["t"][i].get<double>();
                break;
            }
        md << "### " << A1_UNSAFE_LABEL
           << "\n\nThe same spheres, face offsetting, with both switches off until t = "
           << fmt(A1_UNSAFE_END)
           << " (they touch at t = 0.25 and then grow through each other): the exact test "
              "counts the intersecting triangle pairs after every step.\n\n| ξ | t | steps | "
              "max intersecting pairs | steps with intersections | first intersecting at t |\n"
              "|---|---|---|---|---|---|\n| "
           << fmt(r["xi_requested"]) << " | " << fmt(r["t_reached"]) << status(r) << " | "
           << r["steps"].get<long>() << " | " << r["max_intersecting_pairs"].get<int>() << " | "
           << r["steps_with_intersections"].get<int>() << " | "
           << (first < 0.0 ? std::string("never") : fmt(first)) << " |\n\n";
    }
    md << "Plots: `a1_error.png` (error vs ξ, log axes, with the paper's points), "
          "`a1_volume.png`, `a1_triangles.png`.\n\n";
}

void report_a5(std::ostringstream& md, const Json& results) {
    md << "## A5 — cost per step (paper Table 4.4)\n\n"
          "Seconds per step of the A1 face-offsetting runs, wall time on this machine (the paper: "
          "one 2.4 GHz Core2 core). `collisions` is SurfaceTracker::integrate (broad phase, CCD, "
          "impact zones); the exact per-step intersection check we add is listed apart.\n\n"
          "| ξ | triangles | improvement | topology | set velocity | collisions | our check | "
          "paper triangles | paper improvement | paper topology | paper set velocity | paper "
          "collisions |\n|---|---|---|---|---|---|---|---|---|---|---|---|\n";
    for (const Json& r : select(results["runs"], "A1", "face offsetting")) {
        const Json& s = r["seconds_per_step"];
        const int pi = paper_index(r["xi_requested"].get<double>());
        md << "| " << fmt(r["xi_requested"]) << " | " << r["triangles_min"].get<int>() << "–"
           << r["triangles_max"].get<int>() << " | " << fmt(s["improvement"], "%.4f") << " | "
           << fmt(s["topology"], "%.4f") << " | " << fmt(s["set_velocity"], "%.4f") << " | "
           << fmt(s["collisions"], "%.4f") << " | " << fmt(s["verification"], "%.4f") << " | ";
        if (pi >= 0)
            md << PAPER_A5_TRIANGLES[pi] << " | " << fmt(PAPER_A5_SECONDS[pi][0]) << " | "
               << fmt(PAPER_A5_SECONDS[pi][1]) << " | " << fmt(PAPER_A5_SECONDS[pi][2]) << " | "
               << fmt(PAPER_A5_SECONDS[pi][3]) << " |\n";
        else
            md << "— | — | — | — | — |\n";
    }
    md << "\n";
}

/// How the A2 runs size their edges, as a clause of the report's setup sentences.
/// How A2's remeshing keeps vertices on the smooth surface (app/validate_parameters.h).
std::string mcf_smoothing_text() {
    std::string text;
    if (MCF_COLLAPSE_ON_FITTED_SURFACE && !MCF_COLLAPSE_PRESERVES_VOLUME)
        text += ", collapses onto a surface fitted to the edge's neighbours";
    if (MCF_FITTED_SMOOTHING)
        text += ", smoothing along a " +
                std::string(MCF_SMOOTHING_FIT_DEGREE == 3 ? "cubic" : "quadratic") +
                " height field fitted over each vertex's two-ring where it turns by at most " +
                fmt(MCF_SMOOTHING_FIT_MAX_TURN) +
                " rad (elsewhere in the tangent plane), so the shrinking drops' vertices stay "
                "on the surface while their rings are remeshed";
    return text;
}

std::string mcf_sizing_text() {
    if (MCF_CURVATURE_EDGE_FRACTION <= 0.0)
        return "";
    return ", and curvature-adaptive sizing (not in the paper): edges shorter where the surface "
           "turns, by at most " +
           fmt(MCF_CURVATURE_EDGE_FRACTION) + " rad per edge and down to " +
           fmt(tracker::RemeshOptions{}.min_curvature_size_fraction) +
           " α and β, so the thinning neck keeps its edges around it and pinches on time";
}

/// The A2 dumbbell rows with Meyer's operator (the paper's): table, orders and where the error
/// is, per drop half.
void report_a2_cotangent_dumbbell(std::ostringstream& md, Json& results,
                                  const std::vector<Json>& db) {
    md << "| ξ | measured ξ | t | steps | triangles | pinch-off time | components at end | L∞ | "
          "paper L∞ | L1 | paper L1 | vertex L∞ | vertex L1 | paper's measure: max φ, mean φ | "
          "L∞, L1 vs coarse reference | "
          "reference max, mean \\|φ_c − φ_f\\| | OpenVDB L∞, L1 | OpenVDB max, mean "
          "\\|φ_c − φ_f\\| | max intersecting pairs |\n"
          "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n";
    for (const Json& r : db) {
        const int pi = paper_index(r["xi_requested"].get<double>());
        md << "| " << fmt(r["xi_requested"]) << " | " << fmt(r["xi"], "%.4f") << " | "
           << fmt(r["t_reached"]) << status(r) << " | " << r["steps"].get<long>() << " | "
           << r["triangles_min"].get<int>() << "–" << r["triangles_max"].get<int>() << " | "
           << (r["pinch_off_time"].is_null() ? std::string("none") : fmt(r["pinch_off_time"]))
           << " | " << r["final_components"].get<int>() << " | " << fmt(r["error"]["linf"])
           << (r["error_within_reference_band"].get<bool>() ? "" : " (beyond the band)") << " | "
           << (pi >= 0 ? fmt(PAPER_A2_LINF[pi]) : "—") << " | " << fmt(r["error"]["l1"]) << " | "
           << (pi >= 0 ? fmt(PAPER_A2_L1[pi]) : "—") << " | " << fmt(r["error"]["vertex_linf"])
           << " | " << fmt(r["error"]["vertex_l1"]) << " | " << fmt(r["error"]["vertex_max_signed"])
           << ", " << fmt(r["error"]["vertex_mean_signed"]) << " | "
           << fmt(r["error_coarse_reference"]["linf"]) << ", "
           << fmt(r["error_coarse_reference"]["l1"]) << " | "
           << fmt(r["reference_difference"]["linf"]) << ", " << fmt(r["reference_difference"]["l1"])
           << " | " << fmt(r["openvdb_error"]["linf"])
           << (r["openvdb_error_within_reference_band"].get<bool>() ? "" : " (beyond the band)")
           << ", " << fmt(r["openvdb_error"]["l1"]) << " | "
           << fmt(r["openvdb_reference_difference"]["linf"]) << ", "
           << fmt(r["openvdb_reference_difference"]["l1"]) << " | "
           << r["max_intersecting_pairs"].get<int>() << " |\n";
    }
    md << "\n";
    Json orders = Json::array();
    write_orders(md, db, "error", "linf", orders);
    write_orders(md, db, "error", "l1", orders);
    write_orders(md, db, "error", "vertex_linf", orders);
    write_orders(md, db, "error", "vertex_l1", orders);
    md << "paper's orders (Table 4.3): L∞ "
       << fmt(observed_order(PAPER_A2_LINF[0], PAPER_A2_LINF[1], 0.04, 0.02), "%.2f") << ", "
       << fmt(observed_order(PAPER_A2_LINF[1], PAPER_A2_LINF[2], 0.02, 0.01), "%.2f") << "; L1 "
       << fmt(observed_order(PAPER_A2_L1[0], PAPER_A2_L1[1], 0.04, 0.02), "%.2f") << ", "
       << fmt(observed_order(PAPER_A2_L1[1], PAPER_A2_L1[2], 0.02, 0.01), "%.2f") << "\n";
    if (db.size() < 2)
        md << "(one resolution only in this mode: no observed order; run `--full`.)\n";
    results["orders"]["A2 dumbbell"] = orders;
    md << "\n**Where the error is.** Each drop split at its widest section (|x| = "
       << fmt(db.front()["error_by_half"]["split_x"], "%.3f")
       << " in the reference): the inner half ends in the tip the pinch left, the outer half "
          "in the far pole of the former bulb. Signed φ at the vertices (> 0: outside, late). "
          "The poles lag as the spheroid's do (Meyer's operator where the curvature peaks); "
          "the tips carry the pinch's own error.\n\n"
          "| ξ | inner halves (tips): max φ, min φ | outer halves (poles): max φ, min φ | "
          "paper L∞ |\n|---|---|---|---|\n";
    for (const Json& r : db) {
        const int pi = paper_index(r["xi_requested"].get<double>());
        const Json& h = r["error_by_half"];
        md << "| " << fmt(r["xi_requested"]) << " | " << max_min(h["inner"]) << " | "
           << max_min(h["outer"]) << " | " << (pi >= 0 ? fmt(PAPER_A2_LINF[pi]) : "—") << " |\n";
    }
    md << "\n";
    for (size_t i = 1; i < db.size(); ++i)
        for (const char* half : {"inner", "outer"})
            if (db[i - 1]["error_by_half"][half]["max"].get<double>() > 0.0 &&
                db[i]["error_by_half"][half]["max"].get<double>() > 0.0)
                md << "observed order (max φ, " << half << " halves, ξ "
                   << fmt(db[i - 1]["xi_requested"]) << " → " << fmt(db[i]["xi_requested"])
                   << "): **"
                   << fmt(observed_order(db[i - 1]["error_by_half"][half]["max"].get<double>(),
                                         db[i]["error_by_half"][half]["max"].get<double>(),
                                         db[i - 1]["xi"].get<double>(), db[i]["xi"].get<double>()),
                          "%.2f")
                   << "**  \n";
}

void report_a2(std::ostringstream& md, Json& results) {
    md << "## A2 — motion by mean curvature (paper §4.2, Table 4.3)\n\n"
          "### Sphere against the exact R(t) = sqrt(R₀² − 4t)\n\n"
          "Meyer et al. curvature, "
       << (MCF_HEUN ? "Heun's method" : "forward Euler")
       << " with the CFL step, α = 1.5ξ, β = 0.5ξ, γ = 0.1ξ³"
       << (MCF_COLLAPSE_PRESERVES_VOLUME ? "" : ", collapses on the smooth surface")
       << mcf_smoothing_text() << mcf_sizing_text()
       << ".\n\n| ξ | R₀ | t | steps | exact R(t) | L∞ | L1 | vertex L∞ | vertex L∞ / R | "
          "volume change % | exact volume change % | max intersecting pairs "
          "|\n|---|---|---|---|---|---|---|---|---|---|---|---|\n";
    for (const Json& r : select(results["runs"], "A2", "sphere"))
        md << "| " << fmt(r["xi_requested"]) << " | " << fmt(r["initial_radius"]) << " | "
           << fmt(r["t_reached"]) << status(r) << " | " << r["steps"].get<long>() << " | "
           << fmt(r["exact_radius"]) << " | " << fmt(r["error"]["linf"]) << " | "
           << fmt(r["error"]["l1"]) << " | " << fmt(r["error"]["vertex_linf"]) << " | "
           << fmt(r["error"]["vertex_linf"].get<double>() / r["exact_radius"].get<double>())
           << " | " << fmt(r["volume_change_percent"]) << " | "
           << fmt(100.0 *
                  (std::pow(r["exact_radius"].get<double>() / r["initial_radius"].get<double>(),
                            3) -
                   1.0))
           << " | " << r["max_intersecting_pairs"].get<int>() << " |\n";
    const std::vector<Json> op = select(results["runs"], "A2", "spheroid, no remeshing");
    if (!op.empty()) {
        md << "\n### Meyer's operator alone: a spheroid with no remeshing\n\n"
              "The spheroid x²/"
           << fmt(MCF_SPHEROID_RADII[0]) << "² + (y² + z²)/" << fmt(MCF_SPHEROID_RADII[1])
           << "² = 1 to t = " << fmt(MCF_SPHEROID_END)
           << " with split, flip, collapse and smoothing off, the same stepper, against its own "
              "axisymmetric reference (Δx = "
           << fmt(op.front()["reference_voxel_size"])
           << "): what remains is the error of Meyer et al.'s operator itself, which lags where "
              "the curvature peaks (the poles) and leads where it dips (the equator), an error "
              "of second order in ξ (the orders below). The paper's dumbbell row at the "
              "same ξ is beside it: a mesh run whose drops carry this error meets that row only "
              "where errors of opposite sign cancel.\n\n"
              "The `quartic fit` rows move the vertices by the curvature of a quartic height "
              "field fitted through each vertex over its two-ring and refitted with the "
              "osculating sphere's h² term instead (`quartic_fit`, not in the paper): "
              "pointwise convergent, so its error falls at about fourth order until the time "
              "stepping's shows.\n\n"
              "| operator | ξ | steps | triangles | vertex L∞ | vertex L1 | paper's measure: max "
              "φ, mean φ | L∞, L1 (sampled) | reference max, mean \\|φ_c − φ_f\\| | paper's "
              "dumbbell L∞, L1 |\n|---|---|---|---|---|---|---|---|---|---|\n";
        const std::vector<Json> fitted = select(
            results["runs"], "A2", std::string("spheroid, no remeshing") + A2_QUARTIC_FIT_SUFFIX);
        std::vector<Json> both = op;
        both.insert(both.end(), fitted.begin(), fitted.end());
        for (const Json& r : both) {
            const int pi = paper_index(r["xi_requested"].get<double>());
            const bool quartic = r["label"].get<std::string>() != "spheroid, no remeshing";
            md << "| " << (quartic ? "quartic fit" : "Meyer (cotangent)") << " | "
               << fmt(r["xi_requested"]) << " | " << r["steps"].get<long>() << " | "
               << r["triangles_max"].get<int>() << " | " << fmt(r["error"]["vertex_linf"]) << " | "
               << fmt(r["error"]["vertex_l1"]) << " | " << fmt(r["error"]["vertex_max_signed"])
               << ", " << fmt(r["error"]["vertex_mean_signed"]) << " | " << fmt(r["error"]["linf"])
               << ", " << fmt(r["error"]["l1"]) << " | " << fmt(r["reference_difference"]["linf"])
               << ", " << fmt(r["reference_difference"]["l1"]) << " | "
               << (pi >= 0 ? fmt(PAPER_A2_LINF[pi]) + ", " + fmt(PAPER_A2_L1[pi]) : "—") << " |\n";
        }
        md << "\n";
        Json orders = Json::array();
        write_orders(md, op, "error", "vertex_linf", orders);
        write_orders(md, op, "error", "vertex_l1", orders);
        results["orders"]["A2 spheroid"] = orders;
        if (fitted.size() > 1) {
            md << "quartic fit:  \n";
            Json fitted_orders = Json::array();
            write_orders(md, fitted, "error", "vertex_linf", fitted_orders);
            write_orders(md, fitted, "error", "vertex_l1", fitted_orders);
            results["orders"]["A2 spheroid, quartic fit"] = fitted_orders;
        }
    }
    md << "\n### Dumbbell\n\n";
    const std::vector<Json> db = select(results["runs"], "A2", "dumbbell");
    const std::vector<Json> fitted =
        select(results["runs"], "A2", std::string("dumbbell") + A2_QUARTIC_FIT_SUFFIX);
    if (db.empty() && fitted.empty()) {
        md << "Not run (quick mode runs it only with `--full`, or it was left out by "
              "`--case`).\n\n";
        return;
    }
    const Json& first = db.empty() ? fitted.front() : db.front();
    const Json& axi = first["reference"];
    const Json& vdb = first["openvdb_reference"];
    md << "The paper's dumbbell, from the scripts released with its code (El Topo's "
          "`talpa/sisc-scripts/mc-params-*.txt`): balls r = "
       << fmt(DUMBBELL_BULB_RADIUS) << " at ±" << fmt(DUMBBELL_SEPARATION / 2)
       << " on x and a cylinder r = " << fmt(DUMBBELL_HANDLE_RADIUS)
       << " between their centres, joined without a blend (blend radius "
       << fmt(DUMBBELL_BLEND_RADIUS)
       << "). The handle pinches at t ≈ 0.022 (the paper's Fig. 4.3 shows t = 0.0219); at "
          "t = 0.025 two drops of radius ≈ 0.09 remain, shrinking at 2/R ≈ 22 m/s, so a lag of "
          "5e-5 s in time is 1e-3 m in position. "
       << (MCF_HEUN ? "Heun's method (second order in time) with the CFL step instead of the "
                      "paper's forward Euler, "
                    : "Forward Euler with the CFL step, ")
       << (MCF_COLLAPSE_PRESERVES_VOLUME ? "volume-keeping collapses"
                                         : "collapses that keep the new vertex on the smooth "
                                           "surface (not volume-keeping)")
       << mcf_smoothing_text() << mcf_sizing_text()
       << "; see `app/validate_parameters.h` for what each choice changed. Our pinch-off time "
          "is in the table; the reference's neck closes at t = 0.021925 (Δx = 0.00125: its "
          "neck radius is 6.8e-3 at t = 0.0219 and 3.0e-3 at 0.02192, and r² falls linearly), "
          "after which its tips retract at about 800 m/s (t ≈ 0.02194), 320 m/s (t ≈ 0.022) "
          "and 140 m/s on average from t = 0.022 to 0.0225.\n\n"
       << "**The paper's error measure** (its released `meancurvature.cpp`): the reference's "
          "signed distance φ (cubic interpolation of its grid) at the mesh vertices only; "
          "\"L∞\" = max φ (signed: vertices inside the reference do not count) and \"L1\" = the "
          "vertex-area-weighted mean of φ (signed: inside and outside cancel). Its Table 4.3 has "
          "L∞ < L1 at ξ = 0.01, impossible for norms. The `paper's measure` column gives ours "
          "in that form; `vertex L∞`/`vertex L1` are the same samples as norms, and `L∞`/`L1` "
          "also sample the triangles (which adds the chord sag ℓ²/(8R), 2e-3 for ξ = 0.04 on "
          "the drops).\n\n"
          "**Reference (primary, the `L∞`/`L1` columns)**: `tracker::AxisymmetricMcfReference`, "
          "an independent level-set solution of φ_t = |∇φ|(κ₁ + κ₂) that uses the dumbbell's "
          "axial symmetry: a 2-D meridian grid (axial a, radial r, φ even in r), second-order "
          "central differences, forward Euler with Δt = Δx²/4, Chopp's closest-point "
          "reinitialization on a C¹ bicubic interpolant every 4 steps (it moves the zero set by "
          "O(Δx⁴) only), from the exact signed distance of the same implicit dumbbell. On a "
          "sphere and a long cylinder it converges at second order "
          "(tests/tracker/test_axisymmetric_mcf_reference.cpp). Fine grid Δx = "
       << fmt(axi[1]["voxel_size"]) << " (" << axi[1]["steps"].get<long>() << " steps of "
       << fmt(axi[1]["time_step"]) << " s, " << axi[1]["grid"][0].get<int>() << " × "
       << axi[1]["grid"][1].get<int>() << " grid, " << fmt(axi[1]["seconds"], "%.1f")
       << " s); coarse grid Δx = " << fmt(axi[0]["voxel_size"]) << " ("
       << fmt(axi[0]["seconds"], "%.1f")
       << " s) for its self-convergence. It is the primary reference because it is far more "
          "accurate than a 3-D level set: `|φ_c − φ_f|` below is the difference of its two "
          "grids at the mesh points; at second order the fine grid's own error is about a third "
          "of it, and mesh errors below that are not resolved.\n\n"
          "**Second reference (OpenVDB)**: `coupling::LevelSetReference`, the same equation on a "
          "3-D OpenVDB narrow band (OpenVDB's central-difference curvature stencil, Δt = Δx²/6, "
          "the band renormalized after every step with the interface voxels held fixed), fine "
          "Δx = "
       << fmt(vdb[1]["voxel_size"]) << " (" << vdb[1]["steps"].get<long>() << " steps, "
       << vdb[1]["final_voxels"].get<long long>() << " band voxels at the end, "
       << fmt(vdb[1]["seconds"], "%.1f") << " s), coarse Δx = " << fmt(vdb[0]["voxel_size"]) << " ("
       << fmt(vdb[0]["seconds"], "%.1f")
       << " s). Kept beside the primary one; its own error (its two grids' difference) is "
          "far above the paper's targets near the pinched tips.\n\n"
          "L∞ = max |φ_ref| and L1 = area-weighted mean |φ_ref| over the final mesh's vertices "
          "and 16 sample points per triangle (`tracker::surface_error`).\n\n";
    if (db.empty())
        md << "Meyer's operator (the paper's) was left out by `--curvature-operator`.\n\n";
    else
        report_a2_cotangent_dumbbell(md, results, db);
    if (!fitted.empty()) {
        md << "\n### Dumbbell with the quartic-fit operator\n\n"
              "The same runs with `curvature_operator: quartic_fit` (not in the paper): each "
              "vertex moves by the mean curvature of a quartic height field fitted through it "
              "over its two-ring (Meyer's K where the fit is refused or turns by more than "
           << fmt(tracker::MeanCurvatureFlowOptions{}.fit_max_turn, "%g")
           << " rad). Its curvature converges pointwise where Meyer's does not (the spheroid "
              "above), so the drops' poles no longer lag. A quartic alone errs one way (κ too "
              "small, by a fraction of order (ρκ)⁴ for a two-ring of radius ρ), which on the "
              "coarsest mesh, where a two-ring spans most of a final drop, left every drop "
              "outside (vertex L1 2.8e-4 at ξ = 0.04, above the paper's); refitting it as "
              "h = p + c·h² with c = −κ/4 from the first fit, which a sphere satisfies with a "
              "quadratic p, removes that error on spheres and most of it on drops. These runs "
              "smooth along the fitted cubic wherever it turns by at most "
           << fmt(MCF_QUARTIC_FIT_SMOOTHING_FIT_MAX_TURN, "%g")
           << " rad (Meyer's rows: " << fmt(MCF_SMOOTHING_FIT_MAX_TURN, "%g")
           << "): just after the pinch the tips' two-rings turn by 0.57–0.78 rad, and the "
              "tangent-plane move there sank them ahead of the reference (2.25e-4 at ξ = 0.02 "
              "with the bound at 0.6).";
        const int crease_levels = fitted.front().value("crease_refinement_levels", 0);
        if (crease_levels > 0)
            md << " Their initial mesh is refined around the crease where the handle meets the "
                  "balls (edges within 2ξ of it halved "
               << (crease_levels == 1 ? std::string("once")
                                      : std::to_string(crease_levels) + " times")
               << ", new vertices on the exact dumbbell; ξ stays the unrefined mean edge "
                  "length): unrefined, the crease vertices lag while the layer in which it "
                  "rounds off is narrower than an edge, the deficit spreads along the handle, "
                  "the neck pinches early and the tips end ahead (ξ = 0.01: vertex L∞ 2.59e-5 "
                  "from the plain start, above the paper's row, and 6.17e-6 from the refined "
                  "one in runs of this setup that cut their steps at 50 frame times; 7.21e-6 "
                  "from the refined one with this report's own steps).";
        md << "\n\n"
              "| ξ | steps | triangles | pinch-off time | vertex L∞ | paper L∞ | vertex L1 | "
              "paper L1 | paper's measure: max φ, mean φ | L∞, L1 (sampled) | tips: max φ, "
              "min φ | poles: max φ, min φ | max intersecting pairs |\n"
              "|---|---|---|---|---|---|---|---|---|---|---|---|---|\n";
        for (const Json& r : fitted) {
            const int pi = paper_index(r["xi_requested"].get<double>());
            const Json& h = r["error_by_half"];
            md << "| " << fmt(r["xi_requested"]) << status(r) << " | " << r["steps"].get<long>()
               << " | " << r["triangles_min"].get<int>() << "–" << r["triangles_max"].get<int>()
               << " | "
               << (r["pinch_off_time"].is_null() ? std::string("none")
                                                 : fmt(r["pinch_off_time"]))
               << " | " << fmt(r["error"]["vertex_linf"]) << " | "
               << (pi >= 0 ? fmt(PAPER_A2_LINF[pi]) : "—") << " | "
               << fmt(r["error"]["vertex_l1"]) << " | "
               << (pi >= 0 ? fmt(PAPER_A2_L1[pi]) : "—") << " | "
               << fmt(r["error"]["vertex_max_signed"]) << ", "
               << fmt(r["error"]["vertex_mean_signed"]) << " | " << fmt(r["error"]["linf"])
               << ", " << fmt(r["error"]["l1"]) << " | " << max_min(h["inner"]) << " | "
               << max_min(h["outer"]) << " | " << r["max_intersecting_pairs"].get<int>() << " |\n";
        }
        md << "\n";
        Json fitted_orders = Json::array();
        write_orders(md, fitted, "error", "vertex_linf", fitted_orders);
        write_orders(md, fitted, "error", "vertex_l1", fitted_orders);
        results["orders"]["A2 dumbbell, quartic fit"] = fitted_orders;
    }
    md << "\nPlots: `a2_error.png`, `a2_volume.png`, `a2_triangles.png`.\n\n";
}

void report_a3(std::ostringstream& md, const Json& results) {
    md << "## A3 — Enright deformation test (paper §4.3)\n\n"
          "Sphere r = 0.15 at (0.35, 0.35, 0.35), RK4, Δt = 0.01, α = 1.5ξ, β = 0.5ξ, γ = 0.1ξ³. "
          "The paper runs period 3 at ξ = 0.01 (volume change 0.1764 %). The quick variant runs "
          "the same field with period "
       << fmt(ENRIGHT_QUICK_PERIOD)
       << " (less stretching) for one period; its volume change is not comparable to the "
          "paper's. The volume change splits into what mesh improvement, the flow's motion and "
          "collision handling changed.\n\n| ξ | period | steps | triangles | volume change % | "
          "remeshing / motion / collisions % | paper % | L∞ to initial sphere | L1 to initial "
          "sphere | max intersecting pairs |\n"
          "|---|---|---|---|---|---|---|---|---|---|\n";
    for (const Json& r : select(results["runs"], "A3", "Enright"))
        md << "| " << fmt(r["xi_requested"]) << " | " << fmt(r["period"]) << status(r) << " | "
           << r["steps"].get<long>() << " | " << r["triangles_min"].get<int>() << "–"
           << r["triangles_max"].get<int>() << " | " << fmt(r["volume_change_percent"], "%.4f")
           << " | " << volume_by_phase(r) << " | " << fmt(PAPER_ENRIGHT_VOLUME_PERCENT, "%.4f")
           << " (ξ = 0.01, period 3) | " << fmt(r["error_to_initial_sphere"]["linf"]) << " | "
           << fmt(r["error_to_initial_sphere"]["l1"]) << " | "
           << r["max_intersecting_pairs"].get<int>() << " |\n";
    md << "\nPlots: `a3_volume.png`, `a3_triangles.png`.\n\n";
}

void report_a4(std::ostringstream& md, const Json& results) {
    md << "## A4 — curl noise (paper §4.3)\n\n";
    std::vector<Json> rs;
    for (const char* label : {"curl noise", "curl noise, thin-sheet sizing",
                              "curl noise, three octaves", "curl noise, collision safety off"}) {
        const std::vector<Json> runs = select(results["runs"], "A4", label);
        rs.insert(rs.end(), runs.begin(), runs.end());
    }
    if (rs.empty()) {
        md << "Not run (quick mode runs it only with `--full`, or it was left out by "
              "`--case`).\n\n";
        return;
    }
    md << "Planar curl noise (ψ = (0, 0, φ)): " << CURL_OCTAVES << " octave of random Fourier "
       << "modes, the paper's single-scale \"random spline potential\", at base wavelength "
       << fmt(CURL_WAVELENGTH) << " m, mode frequencies up to " << fmt(CURL_TIME_FREQUENCY)
       << " rad/s and RMS speed " << fmt(CURL_RMS_SPEED) << " m/s (our parameters: the paper "
       << "gives neither its potential nor its speed; at this speed our meshes grow at least as "
       << "much as the paper's, 43× by t = 30: 48× at ξ = 0.04, 70× at ξ = 0.02, 80× at "
       << "ξ = 0.0141). Sphere r = " << fmt(CURL_RADIUS) << ", RK4 Δt = " << fmt(CURL_DT)
       << ", topology changes off, γ = 5e-4 ξ³. The paper's run starts from "
       << PAPER_CURL_INITIAL_TRIANGLES << " triangles (ours 8812 at ξ = 0.0141). The volume "
       << "grows where a sheet becomes thinner than the chord sag of its discretized sides: they "
       << "meet and collision handling holds them apart. The thin-sheet sizing run (ours, not "
       << "the paper's) shrinks edges there, to " << fmt(CURL_THIN_SHEET_MIN_SIZE_FRACTION)
       << " α at most, until the sag is below " << fmt(CURL_THIN_SHEET_SAG_FRACTION)
       << " times the sheet's thickness. The three-octave run is a harder field ("
       << CURL_MULTISCALE_OCTAVES << " octaves down to wavelength "
       << fmt(CURL_WAVELENGTH /
              std::pow(tracker::CurlNoiseOptions{}.lacunarity, CURL_MULTISCALE_OCTAVES - 1))
       << " m, about 3ξ at ξ = 0.04, RMS " << fmt(CURL_MULTISCALE_RMS_SPEED)
       << " m/s) that folds the surface below what the mesh resolves. The volume change splits "
          "into what mesh improvement, the flow's motion and collision handling changed; the "
          "motion part can go negative where the requested motion pushes a sheet's sides through "
          "each other (the signed volume counts the overlap negatively), and collision handling "
          "then gives that back.\n\n"
          "| run | octaves, RMS m/s | ξ | t | steps | triangles | volume change % | remeshing / "
          "motion / collisions % | paper % | max intersecting pairs | steps with intersections "
          "|\n|---|---|---|---|---|---|---|---|---|---|---|\n";
    for (const Json& r : rs)
        md << "| " << r["label"].get<std::string>() << " | " << r["noise"]["octaves"].get<int>()
           << ", " << fmt(r["noise"]["rms_speed"]) << " | " << fmt(r["xi_requested"]) << " | "
           << fmt(r["t_reached"]) << status(r) << " | " << r["steps"].get<long>() << " | "
           << r["triangles_min"].get<int>() << "–" << r["triangles_max"].get<int>() << " | "
           << fmt(r["volume_change_percent"], "%.4f") << " | " << volume_by_phase(r) << " | "
           << (r["collision_safety"].get<bool>()
                   ? fmt(PAPER_CURL_VOLUME_PERCENT, "%.4f") + " (t = 30)"
                   : std::string("—"))
           << " | " << r["max_intersecting_pairs"].get<int>() << " | "
           << r["steps_with_intersections"].get<int>() << " |\n";
    md << "\n";
}

/// Plots from results.json (matplotlib, no display needed). Written beside the results so the
/// plots can be remade.
constexpr const char* PLOT_SCRIPT = R"PY(import json, os, sys
import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt

out = sys.argv[1]
res = json.load(open(os.path.join(out, "results.json")))
runs = res["runs"]
paper = res["paper"]

def sel(case, label=None):
    return [r for r in runs if r["case"] == case and (label is None or r["label"] == label)]

fig, ax = plt.subplots(figsize=(6, 4.5))
for label, marker in (("face offsetting", "o"), ("vertex normals", "s")):
    rs = sel("A1", label)
    if rs:
        xs = [r["xi"] for r in rs]
        ax.loglog(xs, [r["error"]["linf"] for r in rs], marker + "-", label=label + " L-inf")
        ax.loglog(xs, [r["error"]["l1"] for r in rs], marker + "--", label=label + " L1")
ax.loglog(paper["xi"], paper["a1_linf"], "k^:", label="paper L-inf (Table 4.1)")
ax.loglog(paper["xi"], paper["a1_l1"], "kv:", label="paper L1 (Table 4.1)")
ax.set_xlabel("xi (initial mean edge length)")
ax.set_ylabel("error at t = 2")
ax.set_title("A1 normal flow: error vs resolution")
ax.grid(True, which="both", alpha=0.3)
ax.legend(fontsize=7)
fig.tight_layout()
fig.savefig(os.path.join(out, "a1_error.png"), dpi=120)
plt.close(fig)

rs = sel("A2", "dumbbell")
qs = sel("A2", "dumbbell, quartic fit")
if rs or qs:
    fig, ax = plt.subplots(figsize=(6, 4.5))
    if rs:
        xs = [r["xi"] for r in rs]
        ax.loglog(xs, [r["error"]["linf"] for r in rs], "o-",
                  label="L-inf vs axisymmetric reference")
        ax.loglog(xs, [r["error"]["l1"] for r in rs], "o--", label="L1 vs axisymmetric reference")
        ax.loglog(xs, [r["error"]["vertex_linf"] for r in rs], "d-",
                  label="vertex L-inf (the paper's samples)")
        ax.loglog(xs, [r["error"]["vertex_l1"] for r in rs], "d--", label="vertex L1")
        ax.loglog(xs, [r["reference_difference"]["linf"] for r in rs], "x:",
                  label="axisymmetric max |phi_coarse - phi_fine| (reference self-convergence)")
        ax.loglog(xs, [r["openvdb_error"]["linf"] for r in rs], "s-", alpha=0.5,
                  label="L-inf vs OpenVDB 3-D reference")
        ax.loglog(xs, [r["openvdb_reference_difference"]["linf"] for r in rs], "+:", alpha=0.5,
                  label="OpenVDB max |phi_coarse - phi_fine|")
    if qs:
        ax.loglog([r["xi"] for r in qs], [r["error"]["vertex_linf"] for r in qs], "P-",
                  label="vertex L-inf, quartic-fit operator")
        ax.loglog([r["xi"] for r in qs], [r["error"]["vertex_l1"] for r in qs], "P--",
                  label="vertex L1, quartic-fit operator")
    ax.loglog(paper["xi"], paper["a2_linf"], "k^:", label="paper L-inf (Table 4.3)")
    ax.loglog(paper["xi"], paper["a2_l1"], "kv:", label="paper L1 (Table 4.3)")
    ax.set_xlabel("xi (initial mean edge length)")
    ax.set_ylabel("error at t = 0.025")
    ax.set_title("A2 dumbbell, mean curvature: error vs resolution")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(os.path.join(out, "a2_error.png"), dpi=120)
    plt.close(fig)

def series_plot(case, key, name, ylabel, relative=False, extra=None):
    rs = sel(case)
    if not rs:
        return
    fig, ax = plt.subplots(figsize=(6, 4))
    for r in rs:
        s = r["series"]
        y = s[key]
        if relative:
            y = [100.0 * (v - r["initial_volume"]) / r["initial_volume"] for v in y]
        ax.plot(s["t"], y, label="%s xi=%g" % (r["label"], r["xi_requested"]))
        if extra is not None and "initial_radius" in r:
            extra(ax, r)
    ax.set_xlabel("t (s)")
    ax.set_ylabel(ylabel)
    ax.set_title("%s: %s vs time" % (case, ylabel))
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(os.path.join(out, name), dpi=120)
    plt.close(fig)

def exact_sphere(ax, r):
    import math
    ts = r["series"]["t"]
    r0 = r["initial_radius"]
    ax.plot(ts, [4.0 / 3.0 * math.pi * (r0 * r0 - 4.0 * t) ** 1.5 for t in ts], "k:",
            label="exact sphere R(t) = sqrt(R0^2 - 4t), xi=%g" % r["xi_requested"])

rs = sel("A6")
if rs:
    fig, ax = plt.subplots(figsize=(6, 4.5))
    xs = [r["xi"] for r in rs]
    ax.loglog(xs, [r["hausdorff"]["symmetric"] for r in rs], "o-", label="Hausdorff (symmetric)")
    ax.loglog(xs, [r["hausdorff"]["final_to_initial"]["l1"] for r in rs], "s--",
              label="mean distance final -> initial")
    ax.loglog(xs, [r["hausdorff"]["initial_to_final"]["l1"] for r in rs], "d:",
              label="mean distance initial -> final")
    for order, style in ((1, "k-"), (2, "k--")):
        h0 = rs[0]["hausdorff"]["symmetric"]
        ax.loglog(xs, [h0 * (x / xs[0]) ** order for x in xs], style, alpha=0.3,
                  label="order %d" % order)
    ax.set_xlabel("xi (initial mean edge length)")
    ax.set_ylabel("distance to the initial surface after one turn (m)")
    ax.set_title("A6 Zalesak's notched sphere, one rigid turn")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(os.path.join(out, "a6_hausdorff.png"), dpi=120)
    plt.close(fig)

for case in ("A1", "A2", "A3", "A4", "A6"):
    c = case.lower()
    if case in ("A1", "A2"):  # growing and shrinking flows: the volume itself
        series_plot(case, "volume", c + "_volume.png", "volume (m^3)",
                    extra=exact_sphere if case == "A2" else None)
    else:  # volume-preserving fields: the relative change
        series_plot(case, "volume", c + "_volume.png", "volume change (%)", relative=True)
    series_plot(case, "triangles", c + "_triangles.png", "triangles")
)PY";

/// Writes plot_validation.py into the folder and runs it; returns a note for the report.
std::string make_plots(const std::filesystem::path& out) {
    if (!run_plot_script(out, "plot_validation.py", PLOT_SCRIPT, "plot_errors.txt"))
        return "**Plots failed** (`" + std::string(PLOT_PYTHON) +
               "` with matplotlib is needed; see plot_errors.txt): the report has no PNGs.";
    return "Plots (PNG, made by `plot_validation.py` from results.json): a1_error.png, "
           "a6_hausdorff.png, aN_volume.png, aN_triangles.png for each case run.";
}

}  // namespace

std::string geometric_flow_report(Json& results) {
    std::ostringstream md;
    report_a1(md, results);
    report_a5(md, results);
    report_a2(md, results);
    report_a3(md, results);
    report_a4(md, results);
    md << flow_validation::zalesak_report(results);
    return md.str();
}

std::string make_geometric_plots(const std::filesystem::path& out) {
    return make_plots(out);
}

}  // namespace meniscus::app
