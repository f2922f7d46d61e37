#pragma once
/// \file The part A sections of `meniscus validate`'s report.md and its plots
/// (plot_validation.py, run with /usr/bin/python3 and matplotlib).

#include <nlohmann/json.hpp>

#include <filesystem>
#include <string>

namespace meniscus::app {

/// The Markdown sections A1, A5, A2, A3, A4 and A6 from results["runs"] (as validate.cpp writes
/// them), each run beside the paper's numbers; adds the observed orders of convergence to
/// results["orders"].
std::string geometric_flow_report(nlohmann::json& results);

/// Writes plot_validation.py into `out` and runs it on out/results.json; returns a sentence for
/// the report (which plots were written, or why none were).
std::string make_geometric_plots(const std::filesystem::path& out);

/// One number through printf's format `f`.
std::string format_number(double v, const char* f = "%.6g");

}  // namespace meniscus::app
