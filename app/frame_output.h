#pragma once
/// \file What `meniscus run` writes into its output folder, and how: the frame files
/// (surface_NNNN.ply/.obj, fields_NNNN.vdb) in the scene's /output/length_unit with every PLY
/// a closed edge-manifold surface, the run's sidecar meniscus.json that importers read instead of
/// guessing (units, frame rate, file patterns, the Blender half-voxel offset), and the removal of
/// an earlier run's frames so a folder never mixes two runs.

#include "app/scene.h"
#include "coupling/vdb_output.h"
#include "tracker/mesh.h"

#include <nlohmann/json.hpp>

#include <string>
#include <vector>

namespace meniscus::app {

/// Frames are numbered with this many digits: surface_0007.ply.
constexpr int FRAME_DIGITS = 4;
/// The sidecar's file name in the output folder.
constexpr const char* SIDECAR_NAME = "meniscus.json";
/// The statistics' file name in the output folder (one JSON line per frame, SI units).
constexpr const char* STATS_NAME = "stats.jsonl";

/// Metres per unit of /output/length_unit ("m", "cm", "mm"); throws std::invalid_argument for
/// any other unit.
double metres_per_unit(const std::string& length_unit);

/// "<dir>/<stem>_NNNN.<ext>".
std::string frame_path(const std::string& dir, const char* stem, int frame, const char* ext);

/// Removes the files a run of ours writes — surface_N.ply, surface_N.obj, fields_N.vdb (N of at
/// least FRAME_DIGITS digits), their `.partial` temporaries, stats.jsonl, meniscus.json and
/// checkpoint.bin — from
/// `dir`, leaving every other file alone; returns the names removed (sorted). A missing folder
/// removes nothing. Throws std::runtime_error naming the file that cannot be removed.
std::vector<std::string> remove_earlier_run(const std::string& dir);

/// Removes the frame files of frames after `frame` and every temporary a run of ours left in
/// `dir` (a resumed run rewrites them); returns the names removed (sorted).
std::vector<std::string> remove_frames_after(const std::string& dir, int frame);

/// The mesh as a frame file holds it: a copy of `mesh` made edge-manifold by
/// tracker::make_edge_manifold() (non-manifold edges, where two sheets meet mid-merge or
/// mid-pinch, split at their midpoints, singular vertices split into one copy per fan, nothing
/// moved), so that each edge has exactly two triangles; positions and velocities multiplied by
/// `length_scale` (output units per metre). The enclosed volume changes by round-off only.
/// A periodic mesh is written unrolled (coupling/periodic_images.h): with `periodic_margin` 0 (the
/// PLY and OBJ) its images in the box, cut exactly at the box's faces along the periodic axes
/// (open there: copies of the box tile into the whole surface); with a margin (m, for the VDB's
/// distances) every image of each triangle reaching into the box grown by it, uncut.
struct OutputSurface {
    tracker::SurfaceMesh mesh;
    std::vector<tracker::Vec3> velocities;  ///< per vertex of `mesh`, output units per second
    int nonmanifold_edges = 0;              ///< in the tracker's mesh
    int vertices_split = 0;                 ///< singular vertices split into one copy per fan
};
OutputSurface output_surface(const tracker::SurfaceMesh& mesh,
                             const std::vector<tracker::Vec3>& velocities, double length_scale,
                             double periodic_margin = 0.0);

/// How a scene's frames are written: the VDB writer's options (lengths still in metres, with
/// length_scale set) and the length unit.
struct FrameFormat {
    OutputOptions output;
    coupling::VdbOutputOptions vdb;
    double metres_per_unit = 1.0;
};
/// The frame format of a scene (voxel size from /output/voxel_size or half the edge length; the
/// region the surface encloses from /surface/inside).
FrameFormat frame_format(const Scene& scene);

/// Writes frame `frame`'s files into `dir` (each atomically): the PLY (and OBJ) of
/// output_surface() and the VDB of the same surface plus, when given, the fluid's fields.
/// Returns their paths. When one fails, those already written are removed and the error
/// (WriteError for a failed write) is rethrown: a frame's files exist all or none.
std::vector<std::string> write_frame_files(const std::string& dir, int frame,
                                           const FrameFormat& format,
                                           const tracker::SurfaceMesh& mesh,
                                           const std::vector<tracker::Vec3>& velocities,
                                           const coupling::FluidFields& fluid = {});

/// The sidecar meniscus.json of a run of `scene` with `frames_written` of `frames_planned`
/// frames after frame 0 written so far (frame 0 counts as written once it exists).
nlohmann::ordered_json run_sidecar(const Scene& scene, const FrameFormat& format,
                                   int frames_written, int frames_planned, bool complete);
/// Writes `sidecar` to dir/meniscus.json atomically.
void write_run_sidecar(const std::string& dir, const nlohmann::ordered_json& sidecar);

}  // namespace meniscus::app
