#pragma once
/// \file The output folder of one run, frame by frame. A frame is complete as a set: its files
/// are written first (each atomically), its line of stats.jsonl next, then the sidecar
/// meniscus.json that counts it, so a frame whose line is missing was cut short. When one file of
/// a frame fails, the frame's files already written are removed again; an earlier run's files
/// are removed first (frame_output.h).

#include "app/checkpoint.h"
#include "app/frame_output.h"
#include "app/scene.h"
#include "coupling/vdb_output.h"
#include "tracker/mesh.h"

#include <nlohmann/json.hpp>

#include <cstdint>
#include <fstream>
#include <string>
#include <vector>

namespace meniscus::app {

class FrameWriter {
public:
    /// A new run in `out_dir`, which will write `frames` frames after frame 0. `quiet`: say
    /// nothing on stderr about the earlier run's files removed.
    FrameWriter(const Scene& scene, const std::string& out_dir, bool quiet, int frames);

    /// A resumed run continues the folder of the run that wrote `checkpoint`: frames after the
    /// checkpoint's frame (and temporaries) are removed, stats.jsonl is cut back to the lines
    /// of frames 0 to that frame (the frame's own line restored from the checkpoint when the
    /// kill came before it was written), and new lines are appended. `checkpoint_bytes`: the
    /// checkpoint file's size (for a restored line). Throws InputError when stats.jsonl has
    /// fewer lines than the checkpoint's frame (the folder is not the checkpoint's).
    FrameWriter(const Scene& scene, const std::string& out_dir, bool quiet, int frames,
                const CheckpointHeader& checkpoint, std::uint64_t checkpoint_bytes);

    /// Writes the frame's files; returns seconds spent.
    double write(int frame, const tracker::SurfaceMesh& mesh,
                 const std::vector<tracker::Vec3>& velocities,
                 const coupling::FluidFields& fluid = {});

    /// Appends the frame's line to stats.jsonl (what marks the frame complete), then rewrites
    /// the sidecar to count the frame. When the line cannot be written whole, stats.jsonl is cut
    /// back to its complete lines and the frame's files are removed, so no frame is left
    /// half-recorded (WriteError).
    void stats(const nlohmann::json& line);

    /// Removes the files of the frame whose line is not written yet (its checkpoint failed).
    void discard_pending();

private:
    const Scene& m_scene;
    std::string m_dir;
    std::string m_stats_path;
    FrameFormat m_format;
    int m_frames = 0;
    std::ofstream m_stats;
    std::uintmax_t m_stats_bytes = 0;       ///< bytes of complete lines in stats.jsonl
    std::vector<std::string> m_frame_files;  ///< files of the frame whose line is not written yet
    int m_pending_frame = -1;                ///< the frame those files belong to
};

}  // namespace meniscus::app
