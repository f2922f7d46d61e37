#include "app/frame_writer.h"

#include "app/errors.h"
#include "common/atomic_file.h"

#include <cerrno>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <system_error>

namespace meniscus::app {

namespace {

void remove_files(const std::vector<std::string>& paths) {
    for (const std::string& path : paths)
        std::remove(path.c_str());
}

}  // namespace

FrameWriter::FrameWriter(const Scene& scene, const std::string& out_dir, bool quiet, int frames)
    : m_scene(scene),
      m_dir(out_dir),
      m_stats_path((std::filesystem::path(out_dir) / STATS_NAME).string()),
      m_format(frame_format(scene)),
      m_frames(frames) {
    const std::vector<std::string> removed = remove_earlier_run(m_dir);
    if (!removed.empty() && !quiet)
        std::fprintf(stderr, "%s: removed %zu files of an earlier run (%s ... %s)\n",
                     m_dir.c_str(), removed.size(), removed.front().c_str(),
                     removed.back().c_str());
    std::filesystem::create_directories(m_dir);
    errno = 0;
    m_stats.open(m_stats_path, std::ios::trunc);
    if (!m_stats)
        throw WriteError(m_stats_path + ": cannot open for writing: " +
                         system_reason(errno, "open failed"));
}

FrameWriter::FrameWriter(const Scene& scene, const std::string& out_dir, bool quiet, int frames,
                         const CheckpointHeader& checkpoint, std::uint64_t checkpoint_bytes)
    : m_scene(scene),
      m_dir(out_dir),
      m_stats_path((std::filesystem::path(out_dir) / STATS_NAME).string()),
      m_format(frame_format(scene)),
      m_frames(frames) {
    const std::vector<std::string> removed = remove_frames_after(m_dir, checkpoint.frame);
    if (!removed.empty() && !quiet)
        std::fprintf(stderr, "%s: removed %zu files written after the checkpoint (%s ... %s)\n",
                     m_dir.c_str(), removed.size(), removed.front().c_str(),
                     removed.back().c_str());
    std::string kept;
    {
        std::ifstream in(m_stats_path, std::ios::binary);
        std::string line;
        int lines = 0;
        while (lines <= checkpoint.frame && std::getline(in, line)) {
            if (in.eof())
                break;  // a last line without its newline was cut short
            kept += line + '\n';
            ++lines;
        }
        if (lines == checkpoint.frame) {
            nlohmann::json restored = nlohmann::json::parse(checkpoint.stats_line);
            restored["seconds"] = nullptr;  // the interrupted run's timings are lost
            restored["checkpoint"] = {{"bytes", checkpoint_bytes}, {"seconds", nullptr}};
            kept += restored.dump() + '\n';
        } else if (lines < checkpoint.frame) {
            throw InputError(m_stats_path + ": has " + std::to_string(lines) +
                             " complete lines, but the checkpoint is at frame " +
                             std::to_string(checkpoint.frame) +
                             ": the folder does not belong to the checkpoint");
        }
    }
    errno = 0;
    m_stats.open(m_stats_path, std::ios::binary | std::ios::trunc);
    m_stats << kept;
    m_stats.flush();
    if (!m_stats)
        throw WriteError(m_stats_path + ": cannot write: " +
                         system_reason(errno, "write failed"));
    m_stats_bytes = kept.size();
}

double FrameWriter::write(int frame, const tracker::SurfaceMesh& mesh,
                          const std::vector<tracker::Vec3>& velocities,
                          const coupling::FluidFields& fluid) {
    const auto start = std::chrono::steady_clock::now();
    m_frame_files = write_frame_files(m_dir, frame, m_format, mesh, velocities, fluid);
    m_pending_frame = frame;
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

void FrameWriter::stats(const nlohmann::json& line) {
    const std::string text = line.dump() + '\n';
    errno = 0;
    m_stats << text;
    m_stats.flush();
    if (!m_stats) {
        const std::string reason = system_reason(errno, "the stream reported an error");
        m_stats.close();
        std::error_code ec;
        std::filesystem::resize_file(m_stats_path, m_stats_bytes, ec);
        remove_files(m_frame_files);
        throw WriteError(m_stats_path + ": write failed: " + reason);
    }
    m_stats_bytes += text.size();
    m_frame_files.clear();
    if (m_pending_frame >= 0)
        write_run_sidecar(m_dir, run_sidecar(m_scene, m_format, m_pending_frame + 1,
                                             m_frames + 1, m_pending_frame == m_frames));
    m_pending_frame = -1;
}

void FrameWriter::discard_pending() {
    remove_files(m_frame_files);
    m_frame_files.clear();
    m_pending_frame = -1;
}

}  // namespace meniscus::app
