/// `meniscus validate --quick` in the test suite: runs the coarse validation cases into a
/// temporary folder and checks the quick targets of docs/validation.md part A against results.json
/// and report.md.

#include "app/validate.h"
#include "app/validate_parameters.h"
#include "tests/one_worker_thread.h"
#include "tracker/implicit_mesher.h"
#include "tracker/implicit_shape.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

namespace {

using meniscus::app::check_validate_options;
using meniscus::app::run_validation;
using meniscus::app::ValidateOptions;
using Json = nlohmann::json;
namespace fs = std::filesystem;

/// Paper Table 4.1, face offsetting at ξ = 0.04.
constexpr double PAPER_A1_LINF_COARSE = 0.00811073;
constexpr double PAPER_A1_L1_COARSE = 0.00114493;
/// Our coarse errors are below the paper's since split points and smoothing moves land on a
/// fitted surface (tracker/remesh/surface_fit.h): L∞ 4.97e-3, L1 1.00e-3 sampling whole
/// triangles (which includes the chord error of flat triangles, ≈ ℓ²/(12R) on the spheres).
/// Before, L1 was 1.71e-3 (1.5 × the paper's).
constexpr double A1_L1_COARSE_BOUND = PAPER_A1_L1_COARSE;
/// Sphere under mean-curvature flow: vertex distance to the exact R(t), relative to R.
constexpr double MCF_RELATIVE_VERTEX_ERROR = 5e-3;
/// Paper Table 4.3, dumbbell at ξ = 0.04.
constexpr double PAPER_A2_LINF_COARSE = 6.18499e-4;
constexpr double PAPER_A2_L1_COARSE = 2.62302e-4;
/// A2 dumbbell (the paper's: balls 0.3 at ±0.5, handle 0.2) at ξ = 0.04 against the primary,
/// axisymmetric reference (quick: Δx = 0.0025), with curvature-adaptive sizing. At the mesh
/// vertices, the paper's samples, as norms (stricter than the paper's signed max and mean):
/// L∞ measured 4.84e-4 (paper 6.18e-4; 1.39e-3 without the sizing, whose neck pinched late),
/// L1 1.79e-4 (paper 2.62e-4). Sampling the triangles too adds the chord sag of the small drops
/// left at t = 0.025 (ℓ²/(8R) ≈ 2e-3 at ℓ = ξ, R = 0.09): L1 measured 7.35e-4.
constexpr double A2_QUICK_VERTEX_LINF_BOUND = PAPER_A2_LINF_COARSE;
constexpr double A2_QUICK_VERTEX_L1_BOUND = PAPER_A2_L1_COARSE;
constexpr double A2_QUICK_L1_BOUND = 1.2e-3;
/// The drops must not sink while their rings are remeshed: mean signed vertex φ measured −7.7e-5
/// with fitted smoothing and collapses, −1.8e-4 with tangent-plane smoothing and butterfly
/// collapses (every drop vertex inside; −2.3e-5 at ξ = 0.01, above the paper's L1 there).
constexpr double A2_QUICK_MEAN_SIGNED_BOUND = 1.2e-4;
/// Where the reference's right-hand drop meets the axis at t = 0.025 (Δx = 0.0025).
constexpr double A2_DROP_INNER_TIP_X = 0.2525;
constexpr double A2_DROP_OUTER_TIP_X = 0.4945;
/// The reference's neck closes at t = 0.021925 (Δx = 0.0025 and 0.00125; 0.02192 at Δx = 0.005).
/// Measured 0.021948; without curvature-adaptive sizing 0.022006, and with sizing at c = 0.3
/// 0.021892 (too early): the window holds the pinch within 1.3e-4 s of the reference's.
constexpr double A2_PINCH_AFTER = 0.0218;
constexpr double A2_PINCH_BEFORE = 0.0220;
/// The axisymmetric reference's two quick grids (Δx = 0.005, 0.0025) differ by 5.7e-5 on average
/// and 2.0e-4 at most at the mesh points: the reference resolves the mesh's error, whose
/// average must be at least this many times the reference's self-difference (measured 13).
constexpr double A2_REFERENCE_RESOLUTION_FACTOR = 4.0;
constexpr double A2_QUICK_REFERENCE_MAX_DIFFERENCE_BOUND = 5e-4;
/// Against the second, OpenVDB reference (Δx = 0.02, so the final drops are 9 voxels across):
/// L1 measured 4.5e-3; its two grids (Δx = 0.04, 0.02) differ by 6.0e-3 on average at the mesh
/// points, so neither bound is tight.
constexpr double A2_QUICK_OPENVDB_L1_BOUND = 8e-3;
constexpr double A2_QUICK_OPENVDB_REFERENCE_DIFFERENCE_BOUND = 1.2e-2;
/// A2 operator floor: the spheroid (0.3, 0.2, 0.2) with no remeshing at ξ = 0.04 to t = 0.006.
/// Meyer's operator lags at the poles (x = ±0.3 at the start): vertex L∞ measured 3.02e-4,
/// positive, at |x| = 0.2; the reference grids differ by 7e-6 there, so the error is the
/// mesh's.
constexpr double A2_SPHEROID_VERTEX_LINF_BOUND = 5e-4;
constexpr double A2_SPHEROID_POLE_X = 0.15;
/// The quartic-fit operator's vertex L∞ on that spheroid must be below this fraction of
/// Meyer's.
constexpr double A2_SPHEROID_QUARTIC_FIT_FRACTION = 0.5;
/// Enright quick variant (period 1, ξ = 0.02): relative volume change bound, percent.
constexpr double ENRIGHT_QUICK_VOLUME_PERCENT = 0.5;
/// Enright quick: the surface returns near the initial sphere (L∞ distance, m; ξ = 0.02).
constexpr double ENRIGHT_QUICK_RETURN_LINF = 0.01;

/// Part B quick variants (coarse: docs/validation.md targets the --full resolutions).
/// Measured with the one-sided vertex velocities (coupling/interpolate.h): Δp −0.003 % at 10
/// and 16 cells per diameter; Lamb frequency −0.3 % at 12 cells per diameter (trilinear:
/// −4.9 %); Rayleigh–Plateau growth rate −0.6 % at R = 3 cells (trilinear: −5.5 %);
/// capillary-wave frequency −3.7 % at 16 cells per wavelength (trilinear: −5.0 %; since then
/// −2.1 %, below).
constexpr double B1_JUMP_RELATIVE = 0.02;              ///< docs/validation.md B1 (≥ 16 cells per D)
constexpr double B1_SPURIOUS_CAPILLARY_NUMBER = 0.05;  ///< max|u| sqrt(ρD/σ); measured 6e-3
constexpr double B2_QUICK_FREQUENCY_RELATIVE = 0.02;
constexpr double B3_QUICK_RATE_RELATIVE = 0.03;
/// B4 at 16 cells per wavelength with the mirrored outside velocities (/coupling/outside_velocity
/// mirror): measured ω −2.1 %, fitted |decay rate| 0.047 1/s; with the clamped ones −2.7 % and
/// 0.48 1/s (the inviscid wave's amplitude drifted: the slab beyond the side walls kinked).
constexpr double B4_QUICK_FREQUENCY_RELATIVE = 0.03;
constexpr double B4_QUICK_DECAY_RATE = 0.2;  ///< 1/s; inviscid: no decay
/// An oscillation fit must describe the run: rms residual below this fraction of the amplitude.
constexpr double FIT_RMS_FRACTION = 0.05;
/// B6 viscous drop (ω₀R²/ν = 20) at 12 cells per diameter against the exact free-drop mode:
/// measured ω −1.7 %, γ −3.8 % at the solver's own Δt, −1.9 % / −3.7 % at Δt/2.
constexpr double B6_QUICK_FREQUENCY_RELATIVE = 0.04;
constexpr double B6_QUICK_DAMPING_RELATIVE = 0.08;
/// The coupled step's answer does not move with Δt (the split step's would, by the viscous
/// diffusion number): own Δt against Δt/2.
constexpr double B6_DT_CHANGE_RELATIVE = 0.01;
/// B7 creeping bubble at 8 cells per diameter in a 6-radius free-slip box against the
/// wall-corrected Hadamard–Rybczynski speed, /fluid/viscosity_weights pointwise (the default):
/// measured +1.3 % (the split step gave +480 % at the same Δt, diffusion number 11).
constexpr double B7_QUICK_SPEED_RELATIVE = 0.04;
/// The same with the sharp weights (harmonic mean on edges): +17.4 %; with volume_fraction:
/// −8.5 %. Both are biased by about half a cell, to either side.
constexpr double B7_QUICK_SHARP_RELATIVE = 0.25;
constexpr double B7_QUICK_BLENDED_RELATIVE = 0.12;
constexpr double B7_DT_CHANGE_RELATIVE = 0.02;
/// Steady by the end: the last quarter's mean speed against the quarter before.
constexpr double B7_STEADY_RELATIVE = 0.01;

// The validation runs on one worker thread (validate --quick alone: 201 s wall and 336 s of CPU
// on 2 threads, 257 s and 291 s on 1; results.json the same but for its timings).
::testing::Environment* const ONE_WORKER_THREAD =
    ::testing::AddGlobalTestEnvironment(new meniscus::testing::OneWorkerThread);

class QuickValidation : public ::testing::Test {
protected:
    static void SetUpTestSuite() {
        // One folder per process: other build folders may run this test at the same time.
        s_out = fs::temp_directory_path() /
                ("meniscus_test_validate_" + std::to_string(static_cast<long>(::getpid())));
        fs::remove_all(s_out);
        ValidateOptions options;
        options.out_dir = s_out.string();
        options.quiet = true;
        s_exit_code = run_validation(options);
        std::ifstream f(s_out / "results.json");
        s_results = Json::parse(f);
        std::ifstream r(s_out / "report.md");
        std::stringstream text;
        text << r.rdbuf();
        s_report = text.str();
    }

    static void TearDownTestSuite() { fs::remove_all(s_out); }

    static std::vector<Json> runs(const std::string& case_id, const std::string& label) {
        std::vector<Json> out;
        for (const Json& r : s_results["runs"])
            if (r["case"] == case_id && r["label"] == label)
                out.push_back(r);
        return out;
    }

    static fs::path s_out;
    static int s_exit_code;
    static Json s_results;
    static std::string s_report;
};

fs::path QuickValidation::s_out;
int QuickValidation::s_exit_code = -1;
Json QuickValidation::s_results;
std::string QuickValidation::s_report;

TEST_F(QuickValidation, EveryRunFinishesWithoutIntersections) {
    EXPECT_EQ(s_exit_code, 0);
    EXPECT_TRUE(s_results["all_ok"].get<bool>()) << s_results["failures"].dump();
    ASSERT_FALSE(s_results["runs"].empty());
    int unsafe_runs = 0;
    for (const Json& r : s_results["runs"]) {
        SCOPED_TRACE(r["case"].get<std::string>() + " " + r["label"].get<std::string>());
        EXPECT_TRUE(r["completed"].get<bool>());
        EXPECT_EQ(r["initial_intersecting_pairs"].get<int>(), 0);
        if (!r["collision_safety"].get<bool>()) {
            // A1: the spheres grow through each other; A4: curl noise folds the surface onto
            // itself. The count is reported and not zero.
            EXPECT_GT(r["max_intersecting_pairs"].get<int>(), 0);
            ++unsafe_runs;
            continue;
        }
        EXPECT_EQ(r["max_intersecting_pairs"].get<int>(), 0);
        for (const Json& pairs : r["series"]["intersecting_pairs"])
            EXPECT_EQ(pairs.get<int>(), 0);
        EXPECT_EQ(r["series"]["t"].size(), static_cast<size_t>(r["steps"].get<long>()) + 1);
    }
    EXPECT_EQ(unsafe_runs, 2);
}

TEST_F(QuickValidation, NormalFlowCoarseErrorsAgainstThePaper) {
    const std::vector<Json> fo = runs("A1", "face offsetting");
    const std::vector<Json> vn = runs("A1", "vertex normals");
    ASSERT_EQ(fo.size(), 1u);
    ASSERT_EQ(vn.size(), 1u);
    EXPECT_DOUBLE_EQ(fo[0]["t_reached"].get<double>(), 2.0);
    const Json& e = fo[0]["error"];
    std::cout << "[ measured ] A1 ξ=0.04 face offsetting L∞ " << e["linf"] << " (paper "
              << PAPER_A1_LINF_COARSE << "), L1 " << e["l1"] << " (paper " << PAPER_A1_L1_COARSE
              << "); vertex normals L∞ " << vn[0]["error"]["linf"] << "\n";
    EXPECT_LE(e["linf"].get<double>(), PAPER_A1_LINF_COARSE);
    EXPECT_LE(e["l1"].get<double>(), A1_L1_COARSE_BOUND);
    // Vertex normals miss the entropy solution at the merged neck.
    EXPECT_GT(vn[0]["error"]["linf"].get<double>(), 2.0 * e["linf"].get<double>());
}

TEST_F(QuickValidation, SphereMeanCurvatureFollowsExactRadius) {
    const std::vector<Json> s = runs("A2", "sphere");
    ASSERT_EQ(s.size(), 1u);
    const double r = s[0]["exact_radius"].get<double>();
    EXPECT_LT(s[0]["error"]["vertex_linf"].get<double>(), MCF_RELATIVE_VERTEX_ERROR * r);
}

TEST_F(QuickValidation, MeyerOperatorAloneLagsAtTheSpheroidPoles) {
    const std::vector<Json> s = runs("A2", "spheroid, no remeshing");
    ASSERT_EQ(s.size(), 1u);
    const Json& e = s[0]["error"];
    std::cout << "[ measured ] A2 spheroid ξ=0.04, no remeshing: vertex L∞ " << e["vertex_linf"]
              << " at x = " << e["vertex_linf_position"][0] << ", signed max "
              << e["vertex_max_signed"] << "; reference grids differ by "
              << s[0]["reference_difference"]["vertex_linf"] << "\n";
    EXPECT_LT(e["vertex_linf"].get<double>(), A2_SPHEROID_VERTEX_LINF_BOUND);
    EXPECT_EQ(e["vertex_max_signed"].get<double>(), e["vertex_linf"].get<double>());  // a lag
    EXPECT_GT(std::abs(e["vertex_linf_position"][0].get<double>()), A2_SPHEROID_POLE_X);
    EXPECT_GT(e["vertex_linf"].get<double>(),
              10.0 * s[0]["reference_difference"]["vertex_linf"].get<double>());
}

/// The quartic-fit operator on the same spheroid: its curvature converges pointwise, so the
/// poles do not lag: measured vertex L∞ 1.19e-4 against Meyer's 3.02e-4 (its L1, 9.0e-5
/// against 8.4e-5, is not better: at this ξ its one-signed error keeps the whole surface out).
TEST_F(QuickValidation, QuarticFitOperatorBeatsMeyerOnTheSpheroid) {
    const std::vector<Json> meyer = runs("A2", "spheroid, no remeshing");
    const std::vector<Json> fitted = runs("A2", "spheroid, no remeshing, quartic fit");
    ASSERT_EQ(meyer.size(), 1u);
    ASSERT_EQ(fitted.size(), 1u);
    const double e = fitted[0]["error"]["vertex_linf"].get<double>();
    std::cout << "[ measured ] A2 spheroid ξ=0.04, no remeshing, quartic fit: vertex L∞ " << e
              << " (Meyer " << meyer[0]["error"]["vertex_linf"] << ")\n";
    EXPECT_LT(e, A2_SPHEROID_QUARTIC_FIT_FRACTION * meyer[0]["error"]["vertex_linf"].get<double>());
    EXPECT_GT(e, fitted[0]["reference_difference"]["vertex_linf"].get<double>());
}

TEST_F(QuickValidation, DumbbellPinchesOffNearTheLevelSetReference) {
    const std::vector<Json> d = runs("A2", "dumbbell");
    ASSERT_EQ(d.size(), 1u);
    EXPECT_TRUE(d[0]["completed"].get<bool>());
    EXPECT_EQ(d[0]["final_components"].get<int>(), 2);
    ASSERT_FALSE(d[0]["pinch_off_time"].is_null());
    EXPECT_GT(d[0]["pinch_off_time"].get<double>(), A2_PINCH_AFTER);
    EXPECT_LT(d[0]["pinch_off_time"].get<double>(), A2_PINCH_BEFORE);
    const Json& e = d[0]["error"];
    const Json& self = d[0]["reference_difference"];
    std::cout << "[ measured ] A2 dumbbell ξ=0.04 vs axisymmetric reference: L∞ " << e["linf"]
              << ", L1 " << e["l1"] << ", vertex L∞ " << e["vertex_linf"] << ", vertex L1 "
              << e["vertex_l1"] << " (paper " << PAPER_A2_LINF_COARSE << ", " << PAPER_A2_L1_COARSE
              << "); reference self-difference max " << self["linf"] << ", mean " << self["l1"]
              << "; vs OpenVDB reference: L∞ " << d[0]["openvdb_error"]["linf"] << ", L1 "
              << d[0]["openvdb_error"]["l1"] << "\n";
    EXPECT_TRUE(d[0]["error_within_reference_band"].get<bool>());
    EXPECT_LT(e["vertex_linf"].get<double>(), A2_QUICK_VERTEX_LINF_BOUND);
    EXPECT_LT(e["vertex_l1"].get<double>(), A2_QUICK_VERTEX_L1_BOUND);
    EXPECT_LT(e["l1"].get<double>(), A2_QUICK_L1_BOUND);
    EXPECT_LT(std::abs(e["vertex_mean_signed"].get<double>()), A2_QUICK_MEAN_SIGNED_BOUND);
    // The halves split each drop at its widest section (|x| = 0.389 in the reference at
    // t = 0.025, between the tips at 0.2525 and 0.4945) and together hold every vertex.
    const Json& halves = d[0]["error_by_half"];
    EXPECT_GT(halves["split_x"].get<double>(), A2_DROP_INNER_TIP_X);
    EXPECT_LT(halves["split_x"].get<double>(), A2_DROP_OUTER_TIP_X);
    EXPECT_EQ(std::max(halves["inner"]["max"].get<double>(), halves["outer"]["max"].get<double>()),
              e["vertex_max_signed"].get<double>());
    EXPECT_EQ(std::min(halves["inner"]["min"].get<double>(), halves["outer"]["min"].get<double>()),
              e["vertex_min_signed"].get<double>());
    EXPECT_LT(self["linf"].get<double>(), A2_QUICK_REFERENCE_MAX_DIFFERENCE_BOUND);
    EXPECT_GT(e["l1"].get<double>(), A2_REFERENCE_RESOLUTION_FACTOR * self["l1"].get<double>());
    EXPECT_TRUE(d[0]["openvdb_error_within_reference_band"].get<bool>());
    EXPECT_LT(d[0]["openvdb_error"]["l1"].get<double>(), A2_QUICK_OPENVDB_L1_BOUND);
    EXPECT_LT(d[0]["openvdb_reference_difference"]["l1"].get<double>(),
              A2_QUICK_OPENVDB_REFERENCE_DIFFERENCE_BOUND);
}

TEST_F(QuickValidation, EnrightQuickConservesVolumeAndReturns) {
    const std::vector<Json> s = runs("A3", "Enright");
    ASSERT_EQ(s.size(), 1u);
    EXPECT_LT(std::abs(s[0]["volume_change_percent"].get<double>()), ENRIGHT_QUICK_VOLUME_PERCENT);
    EXPECT_LT(s[0]["error_to_initial_sphere"]["linf"].get<double>(), ENRIGHT_QUICK_RETURN_LINF);
}

/// A6 quick (ξ = 0.04, 0.02, snapped onto the slot's edges), measured: volume change
/// +0.0133 %, +0.0011 %; Hausdorff distance to the start after one turn 0.051 ξ, 0.026 ξ; mean
/// distance 1.3e-4, 2.6e-5. At ξ = 0.04 the slot is 1.25 edges wide.
constexpr double ZALESAK_QUICK_VOLUME_PERCENT = 0.03;
constexpr double ZALESAK_QUICK_HAUSDORFF_XI = 0.1;

TEST_F(QuickValidation, ZalesakNotchedSphereComesBackAfterOneTurn) {
    const std::vector<Json> s = runs("A6", "notched sphere");
    ASSERT_EQ(s.size(), 2u);
    for (const Json& r : s) {
        SCOPED_TRACE("ξ = " + r["xi_requested"].dump());
        EXPECT_TRUE(r["completed"].get<bool>());
        EXPECT_EQ(r["max_intersecting_pairs"].get<int>(), 0);
        EXPECT_DOUBLE_EQ(r["t_reached"].get<double>(), 1.0);  // one whole turn
        EXPECT_LT(std::abs(r["volume_change_percent"].get<double>()), ZALESAK_QUICK_VOLUME_PERCENT);
        EXPECT_LT(r["hausdorff"]["symmetric_over_xi"].get<double>(), ZALESAK_QUICK_HAUSDORFF_XI);
        EXPECT_EQ(r["hausdorff"]["symmetric"].get<double>(),
                  std::max(r["hausdorff"]["final_to_initial"]["linf"].get<double>(),
                           r["hausdorff"]["initial_to_final"]["linf"].get<double>()));
    }
    // Finer is closer: the mean distance and the volume change shrink with ξ.
    EXPECT_LT(s[1]["hausdorff"]["final_to_initial"]["l1"].get<double>(),
              0.5 * s[0]["hausdorff"]["final_to_initial"]["l1"].get<double>());
    EXPECT_LT(std::abs(s[1]["volume_change_percent"].get<double>()),
              0.5 * std::abs(s[0]["volume_change_percent"].get<double>()));
    ASSERT_EQ(s_results["orders"]["A6 notched sphere"].size(), 1u);
    EXPECT_NE(s_report.find("## A6 — Zalesak's notched sphere"), std::string::npos);
    EXPECT_NE(s_report.find("| ξ | measured ξ | steps | Δt | triangles | volume change %"),
              std::string::npos);
}

TEST_F(QuickValidation, VolumeChangeByPhaseSumsToTheVolumeChange) {
    for (const Json& r : s_results["runs"]) {
        SCOPED_TRACE(r["case"].get<std::string>() + " " + r["label"].get<std::string>());
        const Json& b = r["volume_change_percent_by_phase"];
        const double sum = b["remeshing"].get<double>() + b["motion"].get<double>() +
                           b["collisions"].get<double>();
        EXPECT_NEAR(sum, r["volume_change_percent"].get<double>(), 1e-9);
        if (!r["collision_safety"].get<bool>()) {  // nothing changed but v · Δt's rounding
            EXPECT_NEAR(b["collisions"].get<double>(), 0.0, 1e-9);
        }
    }
}

TEST_F(QuickValidation, ReportHasEveryCaseTable) {
    ASSERT_TRUE(fs::exists(s_out / "report.md"));
    for (const char* heading : {"## A1", "## A2", "## A3", "## A4", "## A5", "## A6"})
        EXPECT_NE(s_report.find(heading), std::string::npos) << heading;
    for (const char* table :
         {"| ξ | measured ξ | t | steps | triangles | L∞ | L∞ paper",
          "| ξ | triangles | improvement", "| ξ | R₀ | t | steps | exact R(t)",
          "| ξ | period | steps | triangles | volume change %",
          "| ξ | t | steps | max intersecting pairs | steps with intersections",
          "| run | octaves, RMS m/s | ξ | t | steps | triangles | volume change %"})
        EXPECT_NE(s_report.find(table), std::string::npos) << table;
    EXPECT_NE(s_report.find("0.00811073"), std::string::npos);  // the paper's numbers beside ours
}

TEST_F(QuickValidation, PartBStaticDropHasTheLaplaceJump) {
    const Json& runs = s_results["part_b"]["B1"]["runs"];
    ASSERT_GE(runs.size(), 2u);
    for (const Json& r : runs) {
        SCOPED_TRACE(r["cells_per_diameter"].dump() + " cells per diameter");
        EXPECT_TRUE(r["completed"].get<bool>());
        EXPECT_EQ(r["max_intersecting_pairs"].get<int>(), 0);
        EXPECT_LT(std::abs(r["jump_relative_error"].get<double>()), B1_JUMP_RELATIVE);
        EXPECT_LT(r["capillary_number_peak"].get<double>(), B1_SPURIOUS_CAPILLARY_NUMBER);
    }
}

TEST_F(QuickValidation, PartBCasesCarryConvergenceStudies) {
    // B1 is cheap enough to run its coarsest resolution at Δt, Δt/2, Δt/4 in quick mode too:
    // the study gives the observed orders (the full variant: every case at three resolutions).
    const Json& study = s_results["part_b"]["B1"]["jump"];
    ASSERT_GE(study["rows"].size(), 2u);
    const Json& coarsest = study["rows"][0];
    ASSERT_EQ(coarsest["runs"].size(), 3u);
    EXPECT_EQ(coarsest["runs"][0]["dt_factor"].get<double>(), 1.0);
    EXPECT_EQ(coarsest["runs"][2]["dt_factor"].get<double>(), 0.25);
    EXPECT_LT(coarsest["runs"][2]["dt"].get<double>(), 0.3 * coarsest["runs"][0]["dt"].get<double>());
    EXPECT_FALSE(study["rows"][1]["space_order"].is_null());
    for (const char* id : {"B2", "B3", "B4"}) {
        SCOPED_TRACE(id);
        const Json& b = s_results["part_b"][id];
        const char* key = std::string(id) == "B3" ? "growth" : "frequency";
        ASSERT_TRUE(b.contains(key));
        EXPECT_EQ(b[key]["rows"].size(), 1u);
    }
    EXPECT_NE(s_report.find("| cells per D | Δx (m) | Δt (s) | steps | pressure jump Δp (Pa)"),
              std::string::npos);
    // B5: the merge time of drop_merge at Δt and Δt/2 (imposed steps), resolved to a step.
    const Json& merge = s_results["part_b"]["B5"]["runs"][0];
    ASSERT_TRUE(merge.contains("convergence"));
    const Json& runs = merge["convergence"]["runs"];
    ASSERT_EQ(runs.size(), 2u);
    EXPECT_NEAR(runs[1]["dt"].get<double>(), 0.5 * runs[0]["dt"].get<double>(), 1e-15);
    EXPECT_GT(runs[1]["steps"].get<long long>(), runs[0]["steps"].get<long long>());
    for (const Json& r : runs) {
        EXPECT_EQ(r["max_intersecting_pairs"].get<int>(), 0);
        // the drops touch at about 6 ms (tests/coupling/test_scenes_physics.cpp)
        EXPECT_GT(r["event_time"].get<double>(), 0.004);
        EXPECT_LT(r["event_time"].get<double>(), 0.008);
    }
}

/// Semi-implicit surface tension at 3× the capillary limit against the explicit run, both with
/// trilinear vertex velocities (issue 36 item 3; the normal form, the mesh moved with the term's
/// weights): measured B4 ω −0.58 % (and its extra damping about ω²Δt/2: γ 0.78 against 0.05
/// 1/s), B2 ω −1.50 % (−0.10 % with the mesh moved by the plain trilinear velocities), B1 Δp
/// −0.003 % with the peak spurious currents 0.52× the explicit run's (4.9e-3 against 9.3e-3 in
/// max|u|·sqrt(ρD/σ); 2.3× before the term's sampling was weighted by face density).
TEST_F(QuickValidation, PartBImplicitTensionKeepsTheFrequencyAtThreeTimesTheCapillaryStep) {
    const Json& b = s_results["part_b"];
    for (const char* id : {"B1", "B2", "B4"}) {
        SCOPED_TRACE(id);
        const Json& pair = b[id]["implicit_runs"];
        ASSERT_EQ(pair.size(), 2u);
        EXPECT_FALSE(pair[0]["implicit_tension"].get<bool>());
        EXPECT_TRUE(pair[1]["implicit_tension"].get<bool>());
        EXPECT_NEAR(pair[1]["dt"].get<double>(), 3.0 * pair[0]["dt"].get<double>(),
                    0.05 * pair[1]["dt"].get<double>());
        EXPECT_LT(pair[1]["steps"].get<long long>(), pair[0]["steps"].get<long long>() / 2);
        for (const Json& r : pair) {
            EXPECT_TRUE(r["completed"].get<bool>());
            EXPECT_EQ(r["max_intersecting_pairs"].get<int>(), 0);
        }
    }
    const Json& wave = b["B4"]["implicit_runs"];
    EXPECT_LT(std::abs(wave[1]["omega"].get<double>() / wave[0]["omega"].get<double>() - 1.0),
              0.02);
    const Json& drop = b["B1"]["implicit_runs"];
    EXPECT_LT(std::abs(drop[1]["jump"].get<double>() / drop[0]["jump"].get<double>() - 1.0), 1e-3);
    EXPECT_LT(drop[1]["capillary_number_peak"].get<double>(),
              drop[0]["capillary_number_peak"].get<double>());
    const Json& lamb = b["B2"]["implicit_runs"];
    EXPECT_LT(std::abs(lamb[1]["omega"].get<double>() / lamb[0]["omega"].get<double>() - 1.0),
              0.02);
    EXPECT_NE(s_report.find("Semi-implicit surface tension"), std::string::npos);
}

TEST_F(QuickValidation, PartBOscillationsAndGrowthAgainstTheory) {
    const Json& b = s_results["part_b"];
    ASSERT_EQ(b["B2"]["runs"].size(), 1u);
    const Json& drop = b["B2"]["runs"][0];
    EXPECT_LT(std::abs(drop["frequency_relative_error"].get<double>()),
              B2_QUICK_FREQUENCY_RELATIVE);
    EXPECT_LT(drop["rms_residual"].get<double>(),
              FIT_RMS_FRACTION * drop["amplitude"].get<double>());
    ASSERT_EQ(b["B3"]["runs"].size(), 1u);
    const Json& jet = b["B3"]["runs"][0];
    EXPECT_GE(jet["fit_samples"].get<int>(), 10);
    EXPECT_LT(std::abs(jet["rate_relative_error"].get<double>()), B3_QUICK_RATE_RELATIVE);
    ASSERT_EQ(b["B4"]["runs"].size(), 1u);
    const Json& wave = b["B4"]["runs"][0];
    EXPECT_LT(std::abs(wave["frequency_relative_error"].get<double>()),
              B4_QUICK_FREQUENCY_RELATIVE);
    EXPECT_LT(std::abs(wave["decay_rate"].get<double>()), B4_QUICK_DECAY_RATE);
    EXPECT_LT(wave["rms_residual"].get<double>(),
              FIT_RMS_FRACTION * wave["amplitude"].get<double>());
    for (const char* id : {"B2", "B3", "B4"})
        for (const Json& r : b[id]["runs"]) {
            SCOPED_TRACE(id);
            EXPECT_TRUE(r["completed"].get<bool>());
            EXPECT_EQ(r["max_intersecting_pairs"].get<int>(), 0);
            EXPECT_LT(r["volume_drift"].get<double>(), 0.005);
        }
}

TEST_F(QuickValidation, PartBMergeSceneKeepsPhaseVolumes) {
    const Json& runs = s_results["part_b"]["B5"]["runs"];
    ASSERT_FALSE(runs.empty());
    for (const Json& r : runs) {
        SCOPED_TRACE(r["scene"].get<std::string>());
        EXPECT_TRUE(r["topology_ok"].get<bool>());
        EXPECT_EQ(r["max_intersecting_pairs"].get<int>(), 0);
        EXPECT_LT(r["volume_drift_inside"].get<double>(), 0.005);
        EXPECT_LT(r["volume_drift_other"].get<double>(), 0.005);
    }
    for (const char* heading : {"## B1", "## B2", "## B3", "## B4", "## B5"})
        EXPECT_NE(s_report.find(heading), std::string::npos) << heading;
    EXPECT_NE(s_report.find("| cells per D | Δt | steps | fitted period (ms) | Lamb (ms)"),
              std::string::npos);
}

TEST_F(QuickValidation, PartBViscousDropHasTheExactModeAtEveryTimeStep) {
    const Json& b6 = s_results["part_b"]["B6"];
    const Json& runs = b6["runs"];
    ASSERT_EQ(runs.size(), 2u);  // own Δt and Δt/2
    const double omega = b6["omega_exact"].get<double>(), gamma = b6["decay_rate_exact"].get<double>();
    for (const Json& r : runs) {
        SCOPED_TRACE("dt factor " + r["dt_factor"].dump());
        EXPECT_TRUE(r["completed"].get<bool>());
        EXPECT_EQ(r["max_intersecting_pairs"].get<int>(), 0);
        EXPECT_LT(std::abs(r["omega"].get<double>() / omega - 1.0), B6_QUICK_FREQUENCY_RELATIVE);
        EXPECT_LT(std::abs(r["decay_rate"].get<double>() / gamma - 1.0), B6_QUICK_DAMPING_RELATIVE);
        EXPECT_LT(r["rms_residual"].get<double>(), FIT_RMS_FRACTION * r["amplitude"].get<double>());
        EXPECT_LT(r["volume_drift"].get<double>(), 0.005);
    }
    EXPECT_LT(std::abs(runs[1]["omega"].get<double>() / runs[0]["omega"].get<double>() - 1.0),
              B6_DT_CHANGE_RELATIVE);
    EXPECT_LT(std::abs(runs[1]["decay_rate"].get<double>() / runs[0]["decay_rate"].get<double>() -
                       1.0),
              2.0 * B6_DT_CHANGE_RELATIVE);
    EXPECT_NE(s_report.find("## B6"), std::string::npos);
    EXPECT_TRUE(fs::exists(s_out / "b6_viscous_drop.png"));
}

TEST_F(QuickValidation, PartBCreepingBubbleRisesAtTheReferenceSpeedAtItsOwnTimeStep) {
    const Json& b7 = s_results["part_b"]["B7"];
    std::map<std::string, Json> by_weights;
    for (const Json& r : b7["runs"]) {
        Json& list = by_weights[r["weights"].get<std::string>()];
        if (list.is_null())
            list = Json::array();
        list.push_back(r);
    }
    ASSERT_EQ(by_weights["pointwise"].size(), 2u);  // own Δt and Δt/2
    ASSERT_EQ(by_weights["sharp"].size(), 1u);      // own Δt
    ASSERT_EQ(by_weights["volume_fraction"].size(), 1u);
    const auto error = [](const Json& r) {
        return r["rise_speed"].get<double>() / r["reference_speed"].get<double>() - 1.0;
    };
    for (const Json& r : b7["runs"]) {
        SCOPED_TRACE(r["weights"].get<std::string>() + ", dt factor " + r["dt_factor"].dump());
        EXPECT_TRUE(r["completed"].get<bool>());
        EXPECT_EQ(r["max_intersecting_pairs"].get<int>(), 0);
        EXPECT_LT(std::abs(error(r)), B7_QUICK_SHARP_RELATIVE);
        EXPECT_LT(std::abs(r["rise_speed_previous_quarter"].get<double>() /
                               r["rise_speed"].get<double>() -
                           1.0),
                  B7_STEADY_RELATIVE);
    }
    const Json& runs = by_weights["pointwise"];
    for (const Json& r : runs)
        EXPECT_LT(std::abs(error(r)), B7_QUICK_SPEED_RELATIVE);
    // The solver's own Δt is at viscous diffusion number ≈ 11 in the liquid.
    EXPECT_GT(runs[0]["diffusion_number"].get<double>(), 5.0);
    EXPECT_LT(std::abs(runs[1]["rise_speed"].get<double>() / runs[0]["rise_speed"].get<double>() -
                       1.0),
              B7_DT_CHANGE_RELATIVE);
    // The harmonic edge mean makes the bubble too fast, the blended weights too slow.
    EXPECT_GT(error(by_weights["sharp"][0]), 0.1);
    EXPECT_LT(error(by_weights["volume_fraction"][0]), -0.04);
    EXPECT_LT(std::abs(error(by_weights["volume_fraction"][0])), B7_QUICK_BLENDED_RELATIVE);
    EXPECT_NE(s_report.find("## B7"), std::string::npos);
    EXPECT_NE(s_report.find("With `volume_fraction`"), std::string::npos);
    EXPECT_TRUE(fs::exists(s_out / "b7_creeping_bubble.png"));
}

TEST(ValidateOptionsCheck, NamesTheXiNoSelectedCaseRunsAndTheOnesTheyDo) {
    ValidateOptions options;
    options.cases = {"A2"};
    options.xis = {0.01};
    try {
        check_validate_options(options);  // quick A2: sphere and dumbbell at 0.04 only
        FAIL() << "expected std::invalid_argument";
    } catch (const std::invalid_argument& e) {
        const std::string what = e.what();
        EXPECT_NE(what.find("--xi 0.01"), std::string::npos) << what;
        EXPECT_NE(what.find("quick mode (they run 0.04)"), std::string::npos) << what;
    }
    options.full = true;  // full A2's dumbbell runs 0.04, 0.02 and 0.01
    EXPECT_NO_THROW(check_validate_options(options));
    options.cases = {"A3"};
    options.xis = {0.02, 0.0141};  // A3 runs 0.02 and 0.01; 0.0141 is A4's
    EXPECT_THROW(check_validate_options(options), std::invalid_argument);
    options.cases = {"A3", "A4"};
    EXPECT_NO_THROW(check_validate_options(options));
    options.cases = {"A7"};
    options.xis.clear();
    EXPECT_THROW(check_validate_options(options), std::invalid_argument);
    // A6 runs ξ = 0.04 and 0.02 in quick mode, 0.02, 0.01 and 0.005 in full mode.
    options.cases = {"A6"};
    options.full = false;
    options.xis = {0.005};
    EXPECT_THROW(check_validate_options(options), std::invalid_argument);
    options.full = true;
    EXPECT_NO_THROW(check_validate_options(options));
}

TEST(ValidateOptionsCheck, NamesAnUnknownCurvatureOperator) {
    ValidateOptions options;
    options.curvature_operators = {"cotangent", "quartic_fit"};
    EXPECT_NO_THROW(check_validate_options(options));
    options.curvature_operators = {"quartic"};
    try {
        check_validate_options(options);
        FAIL() << "expected std::invalid_argument";
    } catch (const std::invalid_argument& e) {
        const std::string what = e.what();
        EXPECT_NE(what.find("curvature operator 'quartic'"), std::string::npos) << what;
    }
}

/// What a selective run_validation() wrote: results.json and report.md.
struct ValidationOutput {
    int exit_code = 0;
    Json results;
    std::string report;
};

/// Runs `options` (quietly) into a fresh temporary folder named after `tag`, reads back what it
/// wrote and removes the folder.
ValidationOutput run_into_temporary_folder(ValidateOptions options, const std::string& tag) {
    const fs::path out = fs::temp_directory_path() /
                         ("meniscus_test_validate_" + tag + "_" +
                          std::to_string(static_cast<long>(::getpid())));
    fs::remove_all(out);
    options.out_dir = out.string();
    options.quiet = true;
    ValidationOutput o;
    o.exit_code = run_validation(options);
    std::ifstream f(out / "results.json");
    o.results = Json::parse(f);
    std::ifstream md(out / "report.md");
    std::stringstream report;
    report << md.rdbuf();
    o.report = report.str();
    fs::remove_all(out);
    return o;
}

TEST(ValidateCurvatureOperatorSelection, QuarticFitAloneRunsOnlyItsRowsAndItsDumbbellInQuickMode) {
    // Quick A2 with the quartic-fit operator only: its spheroid and (named, so also in quick
    // mode) its dumbbell at ξ = 0.04; no sphere, no Meyer rows. Its dumbbell, started from the
    // crease-refined mesh, meets the paper's row there: vertex L∞, L1 3.51e-4, 1.43e-4 against
    // the quick reference (Δx = 0.0025), 1305 steps, pinch at t = 0.02192 (paper 6.18e-4,
    // 2.62e-4; from the plain mesh 1.39e-4, 3.4e-5). Without the sphere refit the quartic's
    // one-signed error left every drop outside: 4.98e-4, 2.81e-4, L1 above the paper's.
    ValidateOptions options;
    options.cases = {"A2"};
    options.curvature_operators = {"quartic_fit"};
    const ValidationOutput o = run_into_temporary_folder(options, "operator");
    EXPECT_EQ(o.exit_code, 0);
    const Json& results = o.results;
    std::vector<std::string> labels;
    for (const Json& r : results["runs"])
        labels.push_back(r["label"].get<std::string>());
    ASSERT_EQ(labels.size(), 2u);
    EXPECT_EQ(labels[0], "spheroid, no remeshing, quartic fit");
    EXPECT_EQ(labels[1], "dumbbell, quartic fit");
    const Json& dumbbell = results["runs"][1];
    EXPECT_LT(dumbbell["error"]["vertex_linf"].get<double>(), PAPER_A2_LINF_COARSE);
    EXPECT_LT(dumbbell["error"]["vertex_l1"].get<double>(), PAPER_A2_L1_COARSE);
    EXPECT_GT(dumbbell["pinch_off_time"].get<double>(), A2_PINCH_AFTER);
    EXPECT_LT(dumbbell["pinch_off_time"].get<double>(), A2_PINCH_BEFORE);
    EXPECT_EQ(dumbbell["max_intersecting_pairs"].get<int>(), 0);
    // The crease-refined start keeps the unrefined mesh's mean edge length as ξ, so every
    // length fraction of the remeshing is that of the plain ξ = 0.04 run.
    namespace fv = meniscus::app::flow_validation;
    ASSERT_GT(fv::A2_QUARTIC_FIT_DUMBBELL_CREASE_LEVELS, 0);
    EXPECT_EQ(dumbbell["crease_refinement_levels"].get<int>(),
              fv::A2_QUARTIC_FIT_DUMBBELL_CREASE_LEVELS);
    meniscus::tracker::ImplicitMeshOptions mesh_options;
    mesh_options.edge_length = dumbbell["xi_requested"].get<double>();
    mesh_options.crease.levels = fv::A2_QUARTIC_FIT_DUMBBELL_CREASE_LEVELS;
    meniscus::tracker::ImplicitMeshReport mesh_report;
    meniscus::tracker::mesh_implicit_shape(
        *meniscus::tracker::make_dumbbell(Eigen::Vector3d::Zero(), fv::DUMBBELL_BULB_RADIUS,
                                          fv::DUMBBELL_SEPARATION, fv::DUMBBELL_HANDLE_RADIUS,
                                          fv::DUMBBELL_BLEND_RADIUS),
        mesh_options, &mesh_report);
    EXPECT_GT(mesh_report.crease_splits, 0);
    EXPECT_GT(mesh_report.unrefined_mean_edge_length, mesh_report.mean_edge_length);
    EXPECT_DOUBLE_EQ(dumbbell["xi"].get<double>(), mesh_report.unrefined_mean_edge_length);
    EXPECT_NE(o.report.find("### Dumbbell with the quartic-fit operator"), std::string::npos);
    EXPECT_NE(o.report.find("Their initial mesh is refined around the crease"), std::string::npos);
    EXPECT_NE(o.report.find("left out by `--curvature-operator`"), std::string::npos);
}

TEST(ValidateXiSelection, RunsOnlyTheRequestedResolution) {
    // Full A1 at ξ = 0.04 only: the two methods and the run without collision safety, none of
    // the 0.02 and 0.01 runs (those take minutes).
    ValidateOptions options;
    options.full = true;
    options.cases = {"A1"};
    options.xis = {0.04};
    const ValidationOutput o = run_into_temporary_folder(options, "xi");
    EXPECT_EQ(o.exit_code, 0);
    const Json& results = o.results;
    ASSERT_EQ(results["runs"].size(), 3u);
    for (const Json& r : results["runs"]) {
        EXPECT_EQ(r["case"], "A1");
        EXPECT_DOUBLE_EQ(r["xi_requested"].get<double>(), 0.04);
    }
}

}  // namespace
