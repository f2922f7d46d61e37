#include "app/validate_zalesak.h"

#include "app/scene_setup.h"
#include "app/validate_report.h"
#include "tracker/flows/flow_errors.h"
#include "tracker/flows/flow_runner.h"
#include "tracker/flows/velocity_field.h"

#include <cmath>
#include <iterator>
#include <memory>
#include <sstream>

namespace meniscus::app::flow_validation {

namespace {

using Json = nlohmann::json;
using tracker::Vec3;

constexpr const char* LABEL = "notched sphere";

std::string fmt(double v, const char* f = "%.4g") {
    return format_number(v, f);
}

tracker::RigidMotionOptions zalesak_rotation() {
    tracker::RigidMotionOptions o;
    o.angular_velocity = Vec3(0.0, 0.0, 2.0 * M_PI / ZALESAK_PERIOD);
    o.center = Vec3(ZALESAK_AXIS_POINT[0], ZALESAK_AXIS_POINT[1], ZALESAK_AXIS_POINT[2]);
    return o;
}

/// log(e_coarse / e_fine) / log(ξ_coarse / ξ_fine) with the measured ξ.
double observed_order(const Json& coarse, const Json& fine, double e_coarse, double e_fine) {
    return std::log(e_coarse / e_fine) /
           std::log(coarse["xi"].get<double>() / fine["xi"].get<double>());
}

}  // namespace

std::vector<double> zalesak_xis(bool full) {
    return full ? std::vector<double>(std::begin(ZALESAK_FULL_XI), std::end(ZALESAK_FULL_XI))
                : std::vector<double>(std::begin(ZALESAK_QUICK_XI), std::end(ZALESAK_QUICK_XI));
}

tracker::ShapePtr zalesak_shape() {
    const Vec3 c(ZALESAK_CENTER[0], ZALESAK_CENTER[1], ZALESAK_CENTER[2]);
    const double r = ZALESAK_RADIUS, half_width = 0.5 * ZALESAK_SLOT_WIDTH;
    // The slot box reaches a radius past the ball on every side but its top (the slot's floor).
    const Vec3 slot_min(c.x() - half_width, c.y() - 2.0 * r, c.z() - 2.0 * r);
    const Vec3 slot_max(c.x() + half_width, c.y() - r + ZALESAK_SLOT_DEPTH, c.z() + 2.0 * r);
    return tracker::make_difference(tracker::make_sphere(c, r),
                                    tracker::make_box(slot_min, slot_max));
}

void run_zalesak(bool full, bool quiet, const std::function<bool(double)>& runs_xi,
                 const std::function<void(Json, const RunResult&)>& add) {
    // The stepper keeps a pointer to the field: one holder owns both.
    struct Holder {
        tracker::RigidMotionField field;
        tracker::VelocityFieldStepper stepper;
        explicit Holder(const tracker::RigidMotionOptions& o) : field(o), stepper(field) {}
    };
    const tracker::RigidMotionOptions rotation = zalesak_rotation();
    const auto holder = std::make_shared<Holder>(rotation);
    const tracker::ShapePtr shape = zalesak_shape();
    for (double xi : zalesak_xis(full)) {
        if (!runs_xi(xi))
            continue;
        RunSpec s;
        s.case_id = "A6";
        s.label = LABEL;
        s.xi_requested = xi;
        s.shape = shape;
        s.tracker = paper_tracker_options();
        s.stepper = std::shared_ptr<const tracker::FlowStepper>(holder, &holder->stepper);
        s.t_end = ZALESAK_PERIOD;
        s.max_dt = ZALESAK_DT_PER_XI * xi;
        s.crease.snap = ZALESAK_SNAP_CREASES;
        const RunResult r = run_tracked(s, quiet);
        Json j = run_json(r);
        j["period"] = ZALESAK_PERIOD;
        j["dt"] = s.max_dt;
        j["angular_velocity"] = {rotation.angular_velocity.x(), rotation.angular_velocity.y(),
                                 rotation.angular_velocity.z()};
        const tracker::HausdorffDistance h =
            tracker::hausdorff_distance(r.final_mesh, r.initial_mesh);
        j["hausdorff"] = {{"symmetric", h.symmetric},
                          {"symmetric_over_xi", h.symmetric / r.xi},
                          {"final_to_initial", error_json(h.a_to_b)},
                          {"initial_to_final", error_json(h.b_to_a)}};
        add(std::move(j), r);
    }
}

std::string zalesak_report(Json& results) {
    std::vector<Json> rs;
    for (const Json& r : results["runs"])
        if (r["case"] == "A6" && r["label"] == LABEL)
            rs.push_back(r);
    std::ostringstream md;
    md << "## A6 — Zalesak's notched sphere, one rigid turn\n\n";
    if (rs.empty()) {
        md << "Not run (left out by `--case` or `--xi`).\n\n";
        return md.str();
    }
    md << "The 3-D version of Zalesak's slotted disk (Enright, Fedkiw, Ferziger & Mitchell, "
          "J. Comput. Phys. 183, 2002), scaled to the unit cube: a ball of radius "
       << fmt(ZALESAK_RADIUS) << " at (" << fmt(ZALESAK_CENTER[0]) << ", " << fmt(ZALESAK_CENTER[1])
       << ", " << fmt(ZALESAK_CENTER[2]) << ") minus a slot " << fmt(ZALESAK_SLOT_WIDTH)
       << " wide cut " << fmt(ZALESAK_SLOT_DEPTH)
       << " deep from the side facing the axis, through the whole ball along z; turned once "
          "(period "
       << fmt(ZALESAK_PERIOD)
       << " s) about the z-parallel axis through (0.5, 0.5) by the rigid field u = −ω(y − 0.5), "
          "v = ω(x − 0.5), w = 0 (`/flow/type` `rigid`), vertices advected by RK4 with Δt = ξ/2, "
          "α = 1.5ξ, β = 0.5ξ, γ = 0.1ξ³, topology changes and collision safety on. The initial "
          "mesh has its vertices and edges put onto the slot's sharp edges "
          "(`/surface/crease/snap`; "
          "meshed without, its triangles cut across them and leave the surface by up to 0.39ξ). "
          "After one turn the exact surface is the initial one, so every difference is the "
          "tracker's: the RK4 steps alone move vertices by less than 1e-6 of their radius; the "
          "rest is mesh improvement (smoothing and collapses) near the slot's edges and corners. "
          "Hausdorff: the "
          "larger of the two one-sided distances between the final and the initial mesh, each "
          "the largest point-to-triangle distance over vertices and 4² samples per triangle; "
          "mean: the area-weighted mean distance of each mesh from the other.\n\n"
          "| ξ | measured ξ | steps | Δt | triangles | volume change % | remeshing / motion / "
          "collisions % | Hausdorff | Hausdorff / ξ | mean final→initial | mean initial→final | "
          "max intersecting pairs | seconds |\n"
          "|---|---|---|---|---|---|---|---|---|---|---|---|---|\n";
    for (const Json& r : rs) {
        const Json& h = r["hausdorff"];
        const Json& b = r["volume_change_percent_by_phase"];
        md << "| " << fmt(r["xi_requested"]) << " | " << fmt(r["xi"]) << " | "
           << r["steps"].get<long>()
           << (r["completed"].get<bool>()
                   ? std::string()
                   : " (stopped: " + r["stop_reason"].get<std::string>() + ")")
           << " | " << fmt(r["dt"]) << " | " << r["triangles_min"].get<int>() << "–"
           << r["triangles_max"].get<int>() << " | " << fmt(r["volume_change_percent"], "%+.4f")
           << " | " << fmt(b["remeshing"], "%+.4f") << " / " << fmt(b["motion"], "%+.4f") << " / "
           << fmt(b["collisions"], "%+.4f") << " | " << fmt(h["symmetric"], "%.3e") << " | "
           << fmt(h["symmetric_over_xi"], "%.3f") << " | "
           << fmt(h["final_to_initial"]["l1"], "%.2e") << " | "
           << fmt(h["initial_to_final"]["l1"], "%.2e") << " | "
           << r["max_intersecting_pairs"].get<int>() << " | " << fmt(r["wall_seconds"], "%.1f")
           << " |\n";
    }
    md << "\n";
    Json orders = Json::array();
    for (size_t i = 1; i < rs.size(); ++i) {
        const double q_h = observed_order(rs[i - 1], rs[i], rs[i - 1]["hausdorff"]["symmetric"],
                                          rs[i]["hausdorff"]["symmetric"]);
        const double v0 = std::abs(rs[i - 1]["volume_change_percent"].get<double>());
        const double v1 = std::abs(rs[i]["volume_change_percent"].get<double>());
        const double q_v = observed_order(rs[i - 1], rs[i], v0, v1);
        const double q_m =
            observed_order(rs[i - 1], rs[i], rs[i - 1]["hausdorff"]["final_to_initial"]["l1"],
                           rs[i]["hausdorff"]["final_to_initial"]["l1"]);
        md << "observed order (ξ " << fmt(rs[i - 1]["xi_requested"]) << " → "
           << fmt(rs[i]["xi_requested"]) << "): Hausdorff **" << fmt(q_h, "%.2f")
           << "**, mean distance **" << fmt(q_m, "%.2f") << "**, |volume change| **"
           << fmt(q_v, "%.2f") << "**  \n";
        orders.push_back({{"xi_coarse", rs[i - 1]["xi_requested"]},
                          {"xi_fine", rs[i]["xi_requested"]},
                          {"hausdorff", q_h},
                          {"mean_distance", q_m},
                          {"volume_change", q_v}});
    }
    results["orders"]["A6 notched sphere"] = orders;
    md << "\nReference: the exact answer, the initial surface with zero volume change. No "
          "published figure is quoted: Enright et al. (2002) ran this shape with level-set and "
          "particle-level-set methods, but their numbers could not be consulted when this case "
          "was written, and no explicit-mesh result for it was found.\n\n"
          "Plots: `a6_hausdorff.png` (Hausdorff and mean distances against ξ), "
          "`a6_volume.png`, `a6_triangles.png`.\n\n";
    return md.str();
}

}  // namespace meniscus::app::flow_validation
