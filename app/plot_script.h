#pragma once
/// \file The validation report's plots: a Python script (matplotlib) written beside
/// results.json and run on it.

#include <filesystem>

namespace meniscus::app {

/// Python with matplotlib (Debian's python3-matplotlib).
inline constexpr const char* PLOT_PYTHON = "/usr/bin/python3";

/// Writes `script` to out/`script_name` and runs it as `PLOT_PYTHON script out`, its stderr going
/// to out/`errors_name`, which is removed when the script succeeds. Returns whether it did.
bool run_plot_script(const std::filesystem::path& out, const char* script_name, const char* script,
                     const char* errors_name);

}  // namespace meniscus::app
