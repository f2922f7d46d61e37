#pragma once
/// \file Part B of `meniscus validate` (docs/validation.md: two-phase flow with surface
/// tension): B1 static drop (Laplace jump, spurious currents), B2 oscillating drop (Lamb's
/// frequency and damping), B3 Rayleigh–Plateau (linear growth rate, pinch-off), B4 capillary
/// wave (frequency against ω₀² = σk³/(ρ₁+ρ₂)), B5 merge and pinch scenes (component counts,
/// volume of each phase, intersections). The measurements are in app/fluid_measures.h.

#include <nlohmann/json.hpp>

#include <filesystem>
#include <string>
#include <vector>

namespace meniscus::app {

// ---- The validation cases ------------------------------------------------------------------------

/// True for "B1" … "B5".
bool is_fluid_case(const std::string& id);

/// Options of run_fluid_validation().
struct FluidValidationOptions {
    bool full = false;  ///< false: coarse, short variants (test suite); true: docs/validation.md's
    bool quiet = false;
    std::vector<std::string> cases;  ///< "B1" … "B5"; empty: all
    std::filesystem::path out_dir;   ///< where plot data and plots go
};

/// Part B's results: `results` goes into results.json under "part_b", `report` is the markdown
/// section, `failures` the runs that did not finish, stayed intersecting or lost volume.
struct FluidValidation {
    nlohmann::json results = nlohmann::json::object();
    std::string report;
    bool all_ok = true;
    std::vector<std::string> failures;
};

/// Runs the selected part B cases. Progress lines go to stderr unless quiet.
FluidValidation run_fluid_validation(const FluidValidationOptions& options);

/// Writes plot_fluid.py into `out` and runs it on out/results.json (needs /usr/bin/python3 with
/// matplotlib); returns a sentence for the report.
std::string make_fluid_plots(const std::filesystem::path& out);

}  // namespace meniscus::app
