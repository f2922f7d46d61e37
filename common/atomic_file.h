#pragma once
/// \file Atomic file replacement: write to a temporary file beside the target, then rename over
/// it, so a crash or Ctrl-C never leaves a half-written output file (rename is atomic on POSIX
/// within one file system). Every write is checked before the rename — stream state after the
/// flush, the close, and the size on disk against the bytes written — so a full disk or an I/O
/// error leaves no file under the target's name.

#include <cerrno>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <string>
#include <system_error>

namespace meniscus {

/// A file could not be written (full disk, I/O error, permissions): the message names the path
/// and the system's reason. No file is left under the target's name.
class WriteError : public std::runtime_error {
public:
    using std::runtime_error::runtime_error;
};

/// The temporary path used while writing `path` (same directory, so the rename is atomic).
inline std::string temporary_path_for(const std::string& path) {
    return path + ".partial";
}

/// The system's text for errno `error`, or `fallback` when errno says nothing.
inline std::string system_reason(int error, const char* fallback) {
    return error != 0 ? std::generic_category().message(error) : std::string(fallback);
}

/// Renames the finished temporary file over `path`. Throws WriteError on failure (and removes
/// the temporary).
inline void commit_temporary(const std::string& path) {
    const std::string tmp = temporary_path_for(path);
    if (std::rename(tmp.c_str(), path.c_str()) != 0) {
        const std::string reason = system_reason(errno, "rename failed");
        std::remove(tmp.c_str());
        throw WriteError("cannot move " + tmp + " to " + path + ": " + reason);
    }
}

/// Opens the temporary file for `path` (truncating it). Throws WriteError naming `path`.
inline std::ofstream open_temporary(const std::string& path, std::ios::openmode mode) {
    errno = 0;
    std::ofstream out(temporary_path_for(path), mode | std::ios::out | std::ios::trunc);
    if (!out)
        throw WriteError(path + ": cannot open for writing: " +
                         system_reason(errno, "open failed"));
    return out;
}

/// Flushes and closes `out` (opened by open_temporary(path)), checks that every byte reached
/// the file, and renames it to `path`. On any failure removes the temporary and throws
/// WriteError with the path and the system's reason (e.g. "No space left on device").
inline void commit_stream(std::ofstream& out, const std::string& path) {
    const std::string tmp = temporary_path_for(path);
    const auto fail = [&](int error, const char* fallback) {
        const std::string reason = system_reason(error, fallback);
        out.close();
        std::remove(tmp.c_str());
        throw WriteError(path + ": write failed: " + reason);
    };
    // errno is not cleared here: a failed write set it inside an earlier out.write() (the
    // stream has done nothing since, being bad); open_temporary() cleared it before.
    out.flush();
    if (!out)
        fail(errno, "the stream reported an error");
    const std::streamoff written = out.tellp();
    errno = 0;
    out.close();
    if (out.fail())
        fail(errno, "close failed");
    std::error_code ec;
    const auto size = std::filesystem::file_size(tmp, ec);
    if (ec)
        fail(ec.value(), "cannot read the written size");
    if (written < 0 || size != static_cast<std::uintmax_t>(written))
        fail(0, ("the file holds " + std::to_string(size) + " of " + std::to_string(written) +
                 " bytes written")
                    .c_str());
    commit_temporary(path);
}

}  // namespace meniscus
