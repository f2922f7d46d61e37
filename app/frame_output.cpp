#include "app/frame_output.h"

#include "app/checkpoint.h"
#include "app/scene_setup.h"

#include "common/atomic_file.h"
#include "coupling/periodic_images.h"
#include "tracker/mesh_io.h"
#include "tracker/topology/separate.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <system_error>

namespace meniscus::app {

namespace {

namespace fs = std::filesystem;

/// The VDB voxel size when /output/voxel_size is 0: this fraction of the surface edge length.
constexpr double DEFAULT_VOXEL_FRACTION = 0.5;

/// printf pattern of a frame file, e.g. "surface_%04d.ply".
std::string frame_pattern(const char* stem, const char* ext) {
    return std::string(stem) + "_%0" + std::to_string(FRAME_DIGITS) + "d." + ext;
}

/// True for "<stem>_<digits>.<ext>" with at least FRAME_DIGITS digits.
bool is_frame_name(const std::string& name, const std::string& stem, const std::string& ext) {
    const std::string prefix = stem + "_", suffix = "." + ext;
    if (name.size() < prefix.size() + FRAME_DIGITS + suffix.size() ||
        name.compare(0, prefix.size(), prefix) != 0 ||
        name.compare(name.size() - suffix.size(), suffix.size(), suffix) != 0)
        return false;
    const std::string digits =
        name.substr(prefix.size(), name.size() - prefix.size() - suffix.size());
    return std::all_of(digits.begin(), digits.end(),
                       [](unsigned char c) { return std::isdigit(c) != 0; });
}

/// True for a file name that a run of ours writes (or its temporary while writing).
bool is_run_file(std::string name) {
    const std::string partial = temporary_path_for("");
    if (name.size() > partial.size() &&
        name.compare(name.size() - partial.size(), partial.size(), partial) == 0)
        name.resize(name.size() - partial.size());
    return name == STATS_NAME || name == SIDECAR_NAME || name == CHECKPOINT_NAME ||
           is_frame_name(name, "surface", "ply") ||
           is_frame_name(name, "surface", "obj") || is_frame_name(name, "fields", "vdb");
}

}  // namespace

double metres_per_unit(const std::string& length_unit) {
    if (length_unit == "m")
        return 1.0;
    if (length_unit == "cm")
        return 0.01;
    if (length_unit == "mm")
        return 0.001;
    throw std::invalid_argument("length_unit: expected m, cm or mm, got '" + length_unit + "'");
}

std::string frame_path(const std::string& dir, const char* stem, int frame, const char* ext) {
    char name[64];
    std::snprintf(name, sizeof name, "%s_%0*d.%s", stem, FRAME_DIGITS, frame, ext);
    return (fs::path(dir) / name).string();
}

std::vector<std::string> remove_earlier_run(const std::string& dir) {
    std::vector<std::string> removed;
    std::error_code ec;
    if (!fs::is_directory(dir, ec))
        return removed;
    for (const fs::directory_entry& entry : fs::directory_iterator(dir)) {
        const std::string name = entry.path().filename().string();
        if (!entry.is_regular_file(ec) || !is_run_file(name))
            continue;
        if (!fs::remove(entry.path(), ec) && ec)
            throw std::runtime_error(entry.path().string() +
                                     ": cannot remove the earlier run's file: " + ec.message());
        removed.push_back(name);
    }
    std::sort(removed.begin(), removed.end());
    return removed;
}

std::vector<std::string> remove_frames_after(const std::string& dir, int frame) {
    std::vector<std::string> removed;
    std::error_code ec;
    if (!fs::is_directory(dir, ec))
        return removed;
    for (const fs::directory_entry& entry : fs::directory_iterator(dir)) {
        const std::string name = entry.path().filename().string();
        if (!entry.is_regular_file(ec) || !is_run_file(name))
            continue;
        const bool partial = name.size() > temporary_path_for("").size() &&
                             name.compare(name.size() - temporary_path_for("").size(),
                                          std::string::npos, temporary_path_for("")) == 0;
        const size_t underscore = name.find('_');
        const bool later_frame = underscore != std::string::npos &&
                                 std::isdigit(static_cast<unsigned char>(name[underscore + 1])) &&
                                 std::stoll(name.substr(underscore + 1, 18)) > frame;
        if (!partial && !later_frame)
            continue;
        if (!fs::remove(entry.path(), ec) && ec)
            throw std::runtime_error(entry.path().string() +
                                     ": cannot remove a file written after the checkpoint: " +
                                     ec.message());
        removed.push_back(name);
    }
    std::sort(removed.begin(), removed.end());
    return removed;
}

OutputSurface output_surface(const tracker::SurfaceMesh& mesh,
                             const std::vector<tracker::Vec3>& velocities, double length_scale,
                             double periodic_margin) {
    OutputSurface out;
    out.velocities = velocities;
    out.velocities.resize(static_cast<size_t>(mesh.num_vertices()), tracker::Vec3::Zero());
    if (mesh.periodic()) {
        coupling::UnrolledMesh unrolled = coupling::unroll_periodic_mesh(mesh, periodic_margin);
        out.velocities = coupling::unrolled_values(unrolled, out.velocities);
        out.mesh = periodic_margin > 0.0
                       ? std::move(unrolled.mesh)
                       : coupling::cut_at_box(unrolled.mesh, mesh.periods(), &out.velocities);
    } else {
        out.mesh = mesh;
    }
    const tracker::EdgeManifoldReport split = tracker::make_edge_manifold(out.mesh);
    out.nonmanifold_edges = split.nonmanifold_edges;
    out.vertices_split = split.vertices_split;
    for (const tracker::AddedVertex& a : split.added) {
        out.velocities.resize(static_cast<size_t>(a.vi) + 1, tracker::Vec3::Zero());
        out.velocities[static_cast<size_t>(a.vi)] =
            (1.0 - a.s) * out.velocities[static_cast<size_t>(a.from0)] +
            a.s * out.velocities[static_cast<size_t>(a.from1)];
    }
    for (int vi = 0; vi < out.mesh.num_vertices(); ++vi)
        out.mesh.set_position(vi, length_scale * out.mesh.position(vi));
    for (tracker::Vec3& v : out.velocities)
        v *= length_scale;
    return out;
}

FrameFormat frame_format(const Scene& scene) {
    FrameFormat format;
    format.output = scene.output;
    format.metres_per_unit = metres_per_unit(scene.output.length_unit);
    coupling::VdbOutputOptions& vdb = format.vdb;
    vdb.voxel_size = scene.output.voxel_size > 0.0
                         ? scene.output.voxel_size
                         : DEFAULT_VOXEL_FRACTION * scene.surface.edge_length;
    vdb.half_width_voxels = scene.output.half_width_voxels;
    vdb.density_ramp_voxels = scene.output.density_ramp_voxels;
    vdb.velocity = scene.output.vdb_velocity;
    vdb.pressure = scene.output.vdb_pressure;
    vdb.length_scale = 1.0 / format.metres_per_unit;
    // /surface/inside names the phase the surface encloses (build_initial_surface's labels).
    vdb.inside_region = scene.surface.inside == "gas" ? 0 : 1;
    vdb.density_cut = scene_periods(scene);
    return format;
}

std::vector<std::string> write_frame_files(const std::string& dir, int frame,
                                           const FrameFormat& format,
                                           const tracker::SurfaceMesh& mesh,
                                           const std::vector<tracker::Vec3>& velocities,
                                           const coupling::FluidFields& fluid) {
    const OutputOptions& o = format.output;
    std::vector<std::string> written;
    try {
        if (o.ply || o.obj) {
            const OutputSurface surface = output_surface(mesh, velocities, format.vdb.length_scale);
            if (o.ply) {
                written.push_back(frame_path(dir, "surface", frame, "ply"));
                tracker::write_ply(written.back(), surface.mesh,
                                   o.ply_velocity ? &surface.velocities : nullptr);
            }
            if (o.obj) {
                written.push_back(frame_path(dir, "surface", frame, "obj"));
                tracker::write_obj(written.back(), surface.mesh);
            }
        }
        if (o.vdb) {
            // The VDB's signs come from the same fans the PLY is split into (lengths in metres;
            // the writer scales them).
            // A periodic mesh's images reach past the box by the band, so the distances near
            // its faces see the surface beyond them.
            const double margin = (format.vdb.half_width_voxels + 2.0) * format.vdb.voxel_size;
            const OutputSurface surface = output_surface(mesh, {}, 1.0, margin);
            written.push_back(frame_path(dir, "fields", frame, "vdb"));
            coupling::write_surface_vdb(written.back(), surface.mesh, format.vdb, fluid);
        }
    } catch (...) {
        for (const std::string& path : written)
            std::remove(path.c_str());
        throw;
    }
    return written;
}

nlohmann::ordered_json run_sidecar(const Scene& scene, const FrameFormat& format,
                                   int frames_written, int frames_planned, bool complete) {
    const OutputOptions& o = format.output;
    const std::string unit = o.length_unit;
    const double scale = format.vdb.length_scale;
    const double frame_duration = scene.time.end / scene.time.frames;
    nlohmann::ordered_json files = {{"stats", STATS_NAME}};
    files["surface_ply"] =
        o.ply ? nlohmann::ordered_json(frame_pattern("surface", "ply")) : nullptr;
    files["surface_obj"] =
        o.obj ? nlohmann::ordered_json(frame_pattern("surface", "obj")) : nullptr;
    files["fields_vdb"] = o.vdb ? nlohmann::ordered_json(frame_pattern("fields", "vdb")) : nullptr;
    nlohmann::ordered_json sidecar = {
        {"format", "meniscus run"},
        {"format_version", 1},
        {"meniscus_version", MENISCUS_VERSION},
        {"scene", scene.name},
        {"scene_file", scene.source_path},
        {"description", scene.description},
        {"flow", scene.flow.type},
        {"inside", scene.surface.inside},
        {"closed", !scene.surface.open},
        {"length_unit", unit},
        {"metres_per_unit", format.metres_per_unit},
        {"velocity_unit", unit + "/s"},
        {"pressure_unit", "Pa"},
        {"stats_units", "SI (m, s, m³)"},
        {"frame_rate", 1.0 / frame_duration},
        {"frame_duration", frame_duration},
        {"first_frame", 0},
        {"frame_count", frames_written},
        {"frames_planned", frames_planned},
        {"complete", complete},
        {"files", files},
        {"ply_vertex_velocity", o.ply && o.ply_velocity},
    };
    if (o.vdb) {
        const double h = format.vdb.voxel_size * scale;
        nlohmann::ordered_json grids = {"surface"};
        if (format.vdb.density)
            grids.push_back("density");
        const bool fluid = scene.flow.type == "fluid";
        if (fluid && format.vdb.velocity)
            grids.push_back("vel");
        if (fluid && format.vdb.pressure)
            grids.push_back("pressure");
        sidecar["vdb"] = {
            {"grids", grids},
            {"voxel_size", h},
            {"half_width_voxels", format.vdb.half_width_voxels},
            {"density_ramp_voxels", format.vdb.density_ramp_voxels},
            {"surface_sign", "negative inside the surface (the `inside` phase)"},
            {"voxel_convention",
             "OpenVDB: voxel (i, j, k) holds the value at (i, j, k) · voxel_size"},
            // Blender draws voxel (i, j, k) as the cube [i, i + 1] · h: move the volume by −h/2.
            {"blender_offset", {-0.5 * h, -0.5 * h, -0.5 * h}},
        };
        if (fluid) {
            const double dx = scene.domain.size.x() / scene.domain.cells;
            sidecar["vdb"]["fluid_cell_size"] = dx * scale;
            sidecar["vdb"]["fluid_blender_offset"] = {-0.5 * dx * scale, -0.5 * dx * scale,
                                                      -0.5 * dx * scale};
        }
    }
    if (scene.flow.type == "fluid") {
        // The fluid box as make_fluid_simulation() builds it: whole cubic cells.
        const double dx = scene.domain.size.x() / scene.domain.cells;
        Eigen::Vector3d size = scene.domain.size;
        for (int axis = 1; axis < 3; ++axis)
            size[axis] = dx * std::max(1.0, std::round(size[axis] / dx));
        const Eigen::Vector3d lo = scene.domain.min * scale;
        const Eigen::Vector3d hi = (scene.domain.min + size) * scale;
        sidecar["domain"] = {{"min", {lo.x(), lo.y(), lo.z()}}, {"max", {hi.x(), hi.y(), hi.z()}}};
    }
    return sidecar;
}

void write_run_sidecar(const std::string& dir, const nlohmann::ordered_json& sidecar) {
    const std::string path = (fs::path(dir) / SIDECAR_NAME).string();
    const std::string tmp = temporary_path_for(path);
    {
        std::ofstream out(tmp, std::ios::trunc);
        out << sidecar.dump(2) << '\n';
        out.close();
        if (!out) {
            std::remove(tmp.c_str());
            throw std::runtime_error(path + ": cannot write");
        }
    }
    commit_temporary(path);
}

}  // namespace meniscus::app
