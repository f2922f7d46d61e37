#include "app/output_dir.h"

#include "app/errors.h"

#include <cerrno>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <system_error>

namespace meniscus::app {

namespace {

namespace fs = std::filesystem;

/// Suffix of files being written (common/atomic_file.h).
const std::string PARTIAL_SUFFIX = ".partial";
/// Probe file that checks the folder is writable.
const char* PROBE_NAME = ".meniscus_write_test";

[[noreturn]] void fail(const std::string& dir, const std::string& what) {
    throw InputError("--out " + dir + ": " + what);
}

}  // namespace

void prepare_output_dir(const std::string& dir) {
    std::error_code ec;
    const fs::file_status status = fs::status(dir, ec);
    if (fs::exists(status) && !fs::is_directory(status))
        fail(dir, "exists and is not a folder");
    fs::create_directories(dir, ec);
    if (ec)
        fail(dir, "cannot create the output folder: " + ec.message());
    const fs::path probe = fs::path(dir) / PROBE_NAME;
    errno = 0;
    std::ofstream out(probe);
    if (!out) {
        const std::string reason = errno != 0 ? std::generic_category().message(errno)
                                              : std::string("cannot create a file there");
        fail(dir, "cannot write into the output folder: " + reason);
    }
    out.close();
    fs::remove(probe, ec);
    for (fs::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec)) {
        const std::string name = it->path().filename().string();
        if (name.size() > PARTIAL_SUFFIX.size() &&
            name.compare(name.size() - PARTIAL_SUFFIX.size(), PARTIAL_SUFFIX.size(),
                         PARTIAL_SUFFIX) == 0)
            fs::remove(it->path(), ec);
    }
}

}  // namespace meniscus::app
