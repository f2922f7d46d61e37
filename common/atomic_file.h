#pragma once
/// \file Atomic file replacement: write to a temporary file beside the target, then rename over
/// it, so a crash or Ctrl-C never leaves a half-written output file (rename is atomic on POSIX
/// within one file system).

#include <cstdio>
#include <stdexcept>
#include <string>
#include <system_error>

namespace meniscus {

/// The temporary path used while writing `path` (same directory, so the rename is atomic).
inline std::string temporary_path_for(const std::string& path) {
    return path + ".partial";
}

/// Renames the finished temporary file over `path`. Throws std::runtime_error on failure
/// (and removes the temporary).
inline void commit_temporary(const std::string& path) {
    const std::string tmp = temporary_path_for(path);
    if (std::rename(tmp.c_str(), path.c_str()) != 0) {
        const std::string reason = std::generic_category().message(errno);
        std::remove(tmp.c_str());
        throw std::runtime_error("cannot move " + tmp + " to " + path + ": " + reason);
    }
}

}  // namespace meniscus
