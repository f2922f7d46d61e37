#pragma once
/// \file Checkpoints of `meniscus run`: DIR/checkpoint.bin holds everything the next step reads
/// (the solver state of coupling::Simulation or of the tracker of a geometric flow, at full
/// precision) with the run's counters, the scene's own text and the frame's stats.jsonl line,
/// so that `meniscus run --resume DIR` continues exactly: the frames written after a resume are
/// byte-identical to those of the run done without interruption.
///
/// File layout (native byte order; common/binary_io.h): the 8-byte magic "MNSCCKPT", a u32
/// format version, the header fields (CheckpointHeader, in declaration order), the solver state
/// as one length-prefixed block, then a u64 FNV-1a checksum of every byte before it. The file
/// is replaced atomically (write a temporary, check it, rename), so a kill at any moment leaves
/// either the previous complete checkpoint or the new one.

#include <cstdint>
#include <string>
#include <vector>

namespace meniscus::app {

/// The checkpoint's file name in the output folder.
constexpr const char* CHECKPOINT_NAME = "checkpoint.bin";
/// Bumped whenever the layout or the meaning of a saved field changes.
constexpr std::uint32_t CHECKPOINT_VERSION = 2;  ///< 2: volumes through the open faces

/// What the run records beside the solver state.
struct CheckpointHeader {
    std::string scene_path;  ///< the scene file as given to `meniscus run`, made absolute
    std::string scene_text;  ///< its text when the run started
    std::string flow_type;   ///< /flow/type ("fluid" or a geometric flow)
    int frame = 0;           ///< the frame this checkpoint was written with
    int frames = 0;          ///< frames the run writes after frame 0 (--frames or the scene)
    double time = 0.0;       ///< simulated time at `frame` (s)
    double last_dt = 0.0;    ///< geometric flows: the last step's dt (for stats)
    long long steps = 0;     ///< steps taken so far
    int stalled_steps = 0;   ///< geometric flows: consecutive steps that advanced no time
    int max_intersecting_pairs = -1;
    double nominal_xi = 0.0;  ///< the tracker's nominal ξ (crease-refined meshes), 0 if none
    std::string stats_line;   ///< the frame's stats.jsonl line, without "checkpoint"
};

/// A checkpoint read back: its header and the solver state block.
struct Checkpoint {
    CheckpointHeader header;
    std::string state;
};

/// Writes DIR/checkpoint.bin atomically; returns its size in bytes. Throws WriteError (with the
/// path and the system's reason) when it cannot be written; the previous checkpoint stays.
std::uint64_t write_checkpoint(const std::string& dir, const CheckpointHeader& header,
                               const std::string& state);

/// Reads DIR/checkpoint.bin. Throws InputError naming the file when it is missing, truncated,
/// corrupt (checksum), of another format version, or inconsistent.
Checkpoint read_checkpoint(const std::string& dir);

/// The JSON paths (RFC 6901 pointers, at most `max_paths`) at which two scene texts differ:
/// keys added, removed or changed; none when they differ only in formatting. A text that is
/// not JSON differs as a whole ("/").
std::vector<std::string> scene_differences(const std::string& saved, const std::string& current,
                                           size_t max_paths = 8);

}  // namespace meniscus::app
