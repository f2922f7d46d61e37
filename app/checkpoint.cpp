#include "app/checkpoint.h"

#include "app/errors.h"
#include "common/atomic_file.h"
#include "common/binary_io.h"

#include <nlohmann/json.hpp>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>

namespace meniscus::app {

namespace {

constexpr char MAGIC[8] = {'M', 'N', 'S', 'C', 'C', 'K', 'P', 'T'};
/// Bytes before the header: the magic and the version.
constexpr std::size_t PREAMBLE_BYTES = sizeof(MAGIC) + sizeof(std::uint32_t);
/// The trailing checksum.
constexpr std::size_t CHECKSUM_BYTES = sizeof(std::uint64_t);

std::string checkpoint_path(const std::string& dir) {
    return (std::filesystem::path(dir) / CHECKPOINT_NAME).string();
}

void diff(const nlohmann::json& a, const nlohmann::json& b, const std::string& path,
          std::vector<std::string>& out, size_t max_paths) {
    if (out.size() >= max_paths || a == b)
        return;
    if (a.is_object() && b.is_object()) {
        for (const auto& [key, value] : a.items()) {
            const std::string child = path + "/" + key;
            if (!b.contains(key))
                out.push_back(child + " (removed)");
            else
                diff(value, b[key], child, out, max_paths);
            if (out.size() >= max_paths)
                return;
        }
        for (const auto& [key, value] : b.items())
            if (!a.contains(key) && out.size() < max_paths)
                out.push_back(path + "/" + key + " (added)");
        return;
    }
    if (a.is_array() && b.is_array() && a.size() == b.size()) {
        for (size_t i = 0; i < a.size() && out.size() < max_paths; ++i)
            diff(a[i], b[i], path + "/" + std::to_string(i), out, max_paths);
        return;
    }
    out.push_back(path.empty() ? "/" : path);
}

}  // namespace

std::uint64_t write_checkpoint(const std::string& dir, const CheckpointHeader& h,
                               const std::string& state) {
    BinaryWriter out;
    for (char c : MAGIC)
        out.put(c);
    out.put(CHECKPOINT_VERSION);
    out.put_string(h.scene_path);
    out.put_string(h.scene_text);
    out.put_string(h.flow_type);
    out.put(h.frame);
    out.put(h.frames);
    out.put(h.time);
    out.put(h.last_dt);
    out.put(h.steps);
    out.put(h.stalled_steps);
    out.put(h.max_intersecting_pairs);
    out.put(h.nominal_xi);
    out.put_string(h.stats_line);
    out.put_string(state);
    const std::string& bytes = out.bytes();
    const std::uint64_t checksum = fnv1a64(bytes.data(), bytes.size());
    const std::string path = checkpoint_path(dir);
    std::ofstream file = open_temporary(path, std::ios::binary);
    file.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
    file.write(reinterpret_cast<const char*>(&checksum), sizeof checksum);
    commit_stream(file, path);
    return bytes.size() + CHECKSUM_BYTES;
}

Checkpoint read_checkpoint(const std::string& dir) {
    const std::string path = checkpoint_path(dir);
    std::error_code ec;
    if (!std::filesystem::is_regular_file(path, ec))
        throw InputError(path + ": no checkpoint here (runs write one with every frame; was " +
                         dir + " written by `meniscus run`?)");
    std::ifstream file(path, std::ios::binary);
    errno = 0;
    std::string bytes((std::istreambuf_iterator<char>(file)), std::istreambuf_iterator<char>());
    if (file.bad())
        throw InputError(path + ": cannot read: " + system_reason(errno, "read failed"));
    const auto corrupt = [&](const std::string& why) {
        return InputError(path + ": not a usable checkpoint: " + why +
                          "; start the run again without --resume");
    };
    if (bytes.size() < PREAMBLE_BYTES + CHECKSUM_BYTES || std::memcmp(bytes.data(), MAGIC, 8) != 0)
        throw corrupt(bytes.size() < PREAMBLE_BYTES + CHECKSUM_BYTES
                          ? "only " + std::to_string(bytes.size()) + " bytes"
                          : std::string("not a Meniscus checkpoint"));
    std::uint64_t stored = 0;
    std::memcpy(&stored, bytes.data() + bytes.size() - CHECKSUM_BYTES, CHECKSUM_BYTES);
    const std::size_t body = bytes.size() - CHECKSUM_BYTES;
    if (fnv1a64(bytes.data(), body) != stored)
        throw corrupt("its checksum does not match (truncated or damaged)");
    Checkpoint c;
    try {
        BinaryReader in(bytes.data() + sizeof(MAGIC), body - sizeof(MAGIC));
        const std::uint32_t version = in.get<std::uint32_t>();
        if (version != CHECKPOINT_VERSION)
            throw corrupt("format version " + std::to_string(version) + ", this meniscus reads " +
                          std::to_string(CHECKPOINT_VERSION));
        CheckpointHeader& h = c.header;
        h.scene_path = in.get_string();
        h.scene_text = in.get_string();
        h.flow_type = in.get_string();
        h.frame = in.get<int>();
        h.frames = in.get<int>();
        h.time = in.get<double>();
        h.last_dt = in.get<double>();
        h.steps = in.get<long long>();
        h.stalled_steps = in.get<int>();
        h.max_intersecting_pairs = in.get<int>();
        h.nominal_xi = in.get<double>();
        h.stats_line = in.get_string();
        c.state = in.get_string();
        if (!in.at_end())
            throw corrupt("bytes after the state");
        if (h.frame < 0 || h.frames < 1 || h.frame > h.frames || !(h.time >= 0.0) || h.steps < 0)
            throw corrupt("its counters are out of range");
    } catch (const FormatError& e) {
        throw corrupt(e.what());
    }
    return c;
}

std::vector<std::string> scene_differences(const std::string& saved, const std::string& current,
                                           size_t max_paths) {
    std::vector<std::string> out;
    if (saved == current)
        return out;
    const nlohmann::json a = nlohmann::json::parse(saved, nullptr, false);
    const nlohmann::json b = nlohmann::json::parse(current, nullptr, false);
    if (a.is_discarded() || b.is_discarded()) {
        out.push_back("/");
        return out;
    }
    diff(a, b, "", out, max_paths);  // empty when only the formatting changed
    return out;
}

}  // namespace meniscus::app
