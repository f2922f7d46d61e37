#include "coupling/vdb_output.h"

#include "common/atomic_file.h"
#include "common/binary_io.h"
#include "coupling/mesh_band.h"

#include <openvdb/openvdb.h>
#include <openvdb/tools/Prune.h>
#include <openvdb/tools/SignedFloodFill.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <limits>
#include <mutex>
#include <stdexcept>
#include <vector>

namespace meniscus::coupling {

namespace {

void initialize_openvdb_once() {
    static std::once_flag flag;
    std::call_once(flag, [] { openvdb::initialize(); });
}

/// Voxel (i, j, k) centred on fluid cell (i, j, k), lengths × length_scale.
openvdb::math::Transform::Ptr cell_centred_transform(const fluid::MacGrid& grid,
                                                     double length_scale) {
    auto t = openvdb::math::Transform::createLinearTransform(grid.dx() * length_scale);
    const Eigen::Vector3d offset =
        length_scale * (grid.origin() + Eigen::Vector3d::Constant(0.5 * grid.dx()));
    t->postTranslate(openvdb::Vec3d(offset.x(), offset.y(), offset.z()));
    return t;
}

void append_fluid_grids(const FluidFields& fluid, const VdbOutputOptions& options,
                        openvdb::GridPtrVec& grids, VdbOutputInfo& info) {
    const fluid::MacGrid& grid = *fluid.grid;
    const auto transform = cell_centred_transform(grid, options.length_scale);
    if (options.velocity) {
        auto vel = openvdb::Vec3SGrid::create(openvdb::Vec3s(0.0f));
        vel->setName("vel");
        vel->setTransform(transform->copy());
        vel->setVectorType(openvdb::VEC_CONTRAVARIANT_RELATIVE);
        auto acc = vel->getAccessor();
        const double s = options.length_scale;
        for (int k = 0; k < grid.nz(); ++k)
            for (int j = 0; j < grid.ny(); ++j)
                for (int i = 0; i < grid.nx(); ++i) {
                    const double u = 0.5 * (grid.u()(i, j, k) + grid.u()(i + 1, j, k));
                    const double v = 0.5 * (grid.v()(i, j, k) + grid.v()(i, j + 1, k));
                    const double w = 0.5 * (grid.w()(i, j, k) + grid.w()(i, j, k + 1));
                    acc.setValue(
                        openvdb::Coord(i, j, k),
                        openvdb::Vec3s(static_cast<float>(s * u), static_cast<float>(s * v),
                                       static_cast<float>(s * w)));
                }
        grids.push_back(vel);
        info.velocity_written = true;
    }
    const fluid::Array3<double>* pressure = fluid.pressure;
    if (options.pressure && pressure && pressure->ni() == grid.nx() &&
        pressure->nj() == grid.ny() && pressure->nk() == grid.nz()) {
        auto p = openvdb::FloatGrid::create(0.0f);
        p->setName("pressure");
        p->setTransform(transform->copy());
        auto pacc = p->getAccessor();
        for (int k = 0; k < grid.nz(); ++k)
            for (int j = 0; j < grid.ny(); ++j)
                for (int i = 0; i < grid.nx(); ++i)
                    pacc.setValue(openvdb::Coord(i, j, k),
                                  static_cast<float>((*pressure)(i, j, k)));
        grids.push_back(p);
        info.pressure_written = true;
    }
}

/// Gives every inactive voxel of every leaf the sign of the active voxels its face-connected
/// inactive region touches inside that leaf (±background). A region cannot touch both signs:
/// active voxels are within the band half width (≥ 1 voxel) of the surface, so any path from
/// inside to outside passes through them. Every leaf holds an active voxel (leaves are created
/// by setting band values), so every inactive region touches one.
void fill_leaf_signs(openvdb::FloatTree& tree, float background) {
    using Leaf = openvdb::FloatTree::LeafNodeType;
    constexpr int DIM = static_cast<int>(Leaf::DIM);
    for (auto leaf = tree.beginLeaf(); leaf; ++leaf) {
        std::array<openvdb::Index, Leaf::SIZE> queue{};
        std::array<bool, Leaf::SIZE> done{};
        size_t tail = 0;
        for (auto it = leaf->cbeginValueOn(); it; ++it) {
            queue[tail++] = it.pos();
            done[it.pos()] = true;
        }
        for (size_t head = 0; head < tail; ++head) {
            const openvdb::Index n = queue[head];
            const openvdb::Coord c = Leaf::offsetToLocalCoord(n);
            const float value = leaf->getValue(n) < 0.0f ? -background : background;
            for (int axis = 0; axis < 3; ++axis)
                for (int step : {-1, 1}) {
                    openvdb::Coord m = c;
                    m[axis] += step;
                    if (m[axis] < 0 || m[axis] >= DIM)
                        continue;
                    const openvdb::Index mn = Leaf::coordToOffset(m);
                    if (done[mn])
                        continue;
                    done[mn] = true;
                    leaf->setValueOnly(mn, value);
                    queue[tail++] = mn;
                }
        }
    }
}

/// Sweeps of vertex pinning: each visits every vertex; they stop early once none changes.
constexpr int MAX_PIN_SWEEPS = 8;
/// Pinning passes per vertex and sweep (the `surface` and the `density` sample in turn).
constexpr int MAX_PIN_PASSES = 4;
/// A sample counts as off target only beyond target × (1 + this): float storage rounds.
constexpr double PIN_SLACK = 1e-4;

/// The eight voxels around a point and their trilinear weights (OpenVDB's convention: voxel
/// (i, j, k) holds the value at (i, j, k) · h), with the values of a grid there.
struct VoxelStencil {
    std::array<openvdb::Coord, 8> coords;
    std::array<double, 8> weights{};
    std::array<double, 8> values{};
};

VoxelStencil stencil_at(const tracker::Vec3& x, double voxel_size) {
    const tracker::Vec3 index = x / voxel_size;
    const std::array<double, 3> floor{std::floor(index.x()), std::floor(index.y()),
                                      std::floor(index.z())};
    VoxelStencil stencil;
    for (int corner = 0; corner < 8; ++corner) {
        double w = 1.0;
        std::array<int, 3> ijk{};
        for (int axis = 0; axis < 3; ++axis) {
            const int bit = (corner >> axis) & 1;
            const double f = index[axis] - floor[static_cast<size_t>(axis)];
            w *= bit ? f : 1.0 - f;
            ijk[static_cast<size_t>(axis)] = static_cast<int>(floor[static_cast<size_t>(axis)]) + bit;
        }
        stencil.coords[static_cast<size_t>(corner)] = openvdb::Coord(ijk[0], ijk[1], ijk[2]);
        stencil.weights[static_cast<size_t>(corner)] = w;
    }
    return stencil;
}

/// The trilinear sample of the stencil's values, each clamped to [−limit, limit].
double clamped_sample(const VoxelStencil& stencil, double limit) {
    double sum = 0.0;
    for (size_t n = 0; n < 8; ++n)
        sum += stencil.weights[n] * std::clamp(stencil.values[n], -limit, limit);
    return sum;
}

/// If the sample of the values clamped at ±limit is farther than `target` from 0, scales down
/// the values of the sample's sign (after clamping them at ±limit, which keeps the sample) by
/// the factor in (0, 1) that brings it to ±target. Signs never change. Returns whether it did.
bool pin_sample(VoxelStencil& stencil, double limit, double target) {
    const double sample = clamped_sample(stencil, limit);
    if (!(std::abs(sample) > target * (1.0 + PIN_SLACK)))
        return false;
    const double sign = sample > 0.0 ? 1.0 : -1.0;
    double same = 0.0;
    for (size_t n = 0; n < 8; ++n) {
        double& v = stencil.values[n];
        if (sign * v > 0.0) {
            v = sign * std::min(std::abs(v), limit);
            same += stencil.weights[n] * v;
        }
    }
    // sample = same + other with sign·other ≤ 0 < target < sign·sample, so 0 < factor < 1.
    const double factor = (sign * target - (sample - same)) / same;
    for (double& v : stencil.values)
        if (sign * v > 0.0)
            v *= factor;
    return true;
}

/// The larger offset from 0 of the stencil's `surface` sample and its `density` ramp sample.
double sample_offset(const VoxelStencil& stencil, double ramp_limit) {
    return std::max(std::abs(clamped_sample(stencil, std::numeric_limits<double>::infinity())),
                    std::abs(clamped_sample(stencil, ramp_limit)));
}

/// Vertex pinning of `surface` (band values set, before the signs are filled; see the file
/// comment of vdb_output.h). Every stencil voxel is in the band: a vertex is within √3/2 voxel
/// of its eight voxel centres and the band half width is ≥ 1 voxel. Values near folds sharper
/// than a voxel are no longer exact distances afterwards (only their magnitudes shrink).
void pin_vertices(openvdb::FloatGrid& surface, const tracker::SurfaceMesh& mesh,
                  const VdbOutputOptions& options, VdbOutputInfo& info) {
    const double h = options.voxel_size;
    const double unit = h * options.length_scale;  // one voxel in output units
    const double target = options.vertex_pin_voxels * unit;
    const double ramp_limit = options.density ? 0.5 * options.density_ramp_voxels * unit
                                              : std::numeric_limits<double>::infinity();
    auto acc = surface.getAccessor();
    auto load = [&](int vi) {
        VoxelStencil stencil = stencil_at(mesh.position(vi), h);
        for (size_t n = 0; n < 8; ++n)
            stencil.values[n] = acc.getValue(stencil.coords[n]);
        return stencil;
    };
    std::vector<int> vertices;
    for (int vi = 0; vi < mesh.num_vertices(); ++vi)
        if (mesh.vertex_alive(vi))
            vertices.push_back(vi);
    for (int vi : vertices)
        info.vertex_offset_before_voxels =
            std::max(info.vertex_offset_before_voxels, sample_offset(load(vi), ramp_limit) / unit);
    if (options.pin_vertices) {
        std::vector<char> pinned(static_cast<size_t>(mesh.num_vertices()), 0);
        std::vector<openvdb::Coord> changed_voxels;
        for (int sweep = 0; sweep < MAX_PIN_SWEEPS; ++sweep) {
            bool changed = false;
            for (int vi : vertices) {
                VoxelStencil stencil = load(vi);
                bool vertex_changed = false;
                for (int pass = 0; pass < MAX_PIN_PASSES; ++pass) {
                    const bool a = pin_sample(stencil, std::numeric_limits<double>::infinity(),
                                              target);
                    const bool b = pin_sample(stencil, ramp_limit, target);
                    if (!a && !b)
                        break;
                    vertex_changed = true;
                }
                if (!vertex_changed)
                    continue;
                changed = true;
                pinned[static_cast<size_t>(vi)] = 1;
                for (size_t n = 0; n < 8; ++n) {
                    const float old_value = acc.getValue(stencil.coords[n]);
                    float value = static_cast<float>(stencil.values[n]);
                    if (value == 0.0f && old_value != 0.0f)  // keep the sign through rounding
                        value = std::copysign(std::numeric_limits<float>::min(), old_value);
                    if (value != old_value) {
                        acc.setValueOnly(stencil.coords[n], value);
                        changed_voxels.push_back(stencil.coords[n]);
                    }
                }
            }
            if (!changed)
                break;
        }
        std::sort(changed_voxels.begin(), changed_voxels.end());
        info.voxels_pinned = static_cast<long long>(
            std::unique(changed_voxels.begin(), changed_voxels.end()) - changed_voxels.begin());
        info.vertices_pinned = std::count(pinned.begin(), pinned.end(), 1);
    }
    for (int vi : vertices)
        info.vertex_offset_after_voxels =
            std::max(info.vertex_offset_after_voxels, sample_offset(load(vi), ramp_limit) / unit);
}

/// The `surface` level set: signed band values, vertex pinning, then signs outside the band.
openvdb::FloatGrid::Ptr surface_grid(const tracker::SurfaceMesh& mesh,
                                     const VdbOutputOptions& options, VdbOutputInfo& info) {
    const double h = options.voxel_size;
    const double s = options.length_scale;
    const float background = static_cast<float>(options.half_width_voxels * h * s);
    VoxelLattice lattice;
    lattice.voxel_size = h;
    SignedBandOptions band_options;
    band_options.half_width_voxels = options.half_width_voxels;
    band_options.inside_region = options.inside_region;
    const SignedBand band = signed_band(mesh, lattice, band_options);

    auto surface = openvdb::FloatGrid::create(background);
    surface->setName("surface");
    surface->setGridClass(openvdb::GRID_LEVEL_SET);
    surface->setTransform(openvdb::math::Transform::createLinearTransform(h * s));
    auto acc = surface->getAccessor();
    for (const BandVoxel& v : band.voxels) {
        const float phi = static_cast<float>(v.phi * s);
        if (std::abs(phi) < background)
            acc.setValue(openvdb::Coord(v.ijk[0], v.ijk[1], v.ijk[2]), phi);
    }
    pin_vertices(*surface, mesh, options, info);
    fill_leaf_signs(surface->tree(), background);
    // Tiles between leaves: OpenVDB's sign propagation from the (now filled) leaves.
    constexpr openvdb::Index TILE_LEVELS_ONLY = 1;
    openvdb::tools::signedFloodFill(surface->tree(), true, 1, TILE_LEVELS_ONLY);
    return surface;
}

/// The `density` fog: clamp(½ − φ / (ramp · h), 0, 1) of every value of `surface`, active where
/// positive (whole tiles inside the surface become active tiles of 1).
openvdb::FloatGrid::Ptr density_grid(const openvdb::FloatGrid& surface,
                                     const VdbOutputOptions& options) {
    auto density = openvdb::FloatGrid::create(0.0f);
    density->setName("density");
    density->setGridClass(openvdb::GRID_FOG_VOLUME);
    density->setTransform(surface.transform().copy());
    const double ramp = options.density_ramp_voxels * options.voxel_size * options.length_scale;
    // The voxels kept along each axis (VdbOutputOptions::density_cut): voxel i is centred at
    // i · voxel_size.
    openvdb::CoordBBox kept(openvdb::Coord::min(), openvdb::Coord::max());
    for (int a = 0; a < 3; ++a)
        if (options.density_cut.wraps(a)) {
            const double lo = options.density_cut.origin[a] / options.voxel_size;
            const double hi = lo + options.density_cut.length[a] / options.voxel_size;
            kept.min()[a] = static_cast<openvdb::Int32>(std::ceil(lo));
            kept.max()[a] = static_cast<openvdb::Int32>(std::ceil(hi)) - 1;
        }
    auto acc = density->getAccessor();
    for (auto it = surface.cbeginValueAll(); it; ++it) {
        const double phi = *it;
        if (it.isVoxelValue()) {
            const double fog = std::clamp(0.5 - phi / ramp, 0.0, 1.0);
            if (fog > 0.0 && kept.isInside(it.getCoord()))
                acc.setValue(it.getCoord(), static_cast<float>(fog));
        } else if (phi < 0.0) {
            openvdb::CoordBBox box;
            it.getBoundingBox(box);
            box.intersect(kept);
            if (!box.empty())
                density->fill(box, 1.0f, true);
        }
    }
    openvdb::tools::prune(density->tree());
    return density;
}

/// io::File::write() with a stream we own: File::write() opens its own std::ofstream and never
/// checks it, so a full disk left a truncated file; here the caller checks flush, close and
/// size (commit_stream) before the rename. The bytes are those of io::File (a seekable archive
/// with grid offsets, which readers such as Blender need).
class CheckedArchive final : public openvdb::io::Archive {
public:
    /// The file's bytes, with the UUID made from its content (content_uuid).
    std::string write_seekable(const openvdb::GridPtrVec& grids) const {
        std::ostringstream out(std::ios::binary);
        openvdb::io::Archive::write(out, grids, /*seekable=*/true);
        std::string bytes = std::move(out).str();
        content_uuid(bytes, getUniqueTag());
        return bytes;
    }

private:
    /// OpenVDB stamps every file with a random UUID (Archive::writeHeader), so two runs of one
    /// scene, or a run and its resumed copy, wrote different bytes. Readers use the UUID only to
    /// tell files apart (caches); here it is a hash of the file's other bytes, as an RFC 9562
    /// version-8 ("custom") UUID: the same content gets the same UUID, different content a
    /// different one (up to 64-bit hash collisions).
    static void content_uuid(std::string& bytes, const std::string& written) {
        constexpr std::size_t HEADER_BYTES = 64;  // magic, versions, offsets flag, then the UUID
        const std::size_t at = bytes.find(written);
        if (written.size() != 36 || at == std::string::npos || at > HEADER_BYTES)
            throw std::logic_error("write_surface_vdb: the archive's UUID is not in its header");
        std::fill_n(bytes.begin() + static_cast<std::ptrdiff_t>(at), written.size(), '0');
        const std::uint64_t hi = fnv1a64(bytes.data(), bytes.size());
        std::uint64_t lo = hi ^ (0x9e3779b97f4a7c15ull + bytes.size());  // splitmix64 finaliser
        lo = (lo ^ (lo >> 30)) * 0xbf58476d1ce4e5b9ull;
        lo = (lo ^ (lo >> 27)) * 0x94d049bb133111ebull;
        lo ^= lo >> 31;
        char hex[33];
        std::snprintf(hex, sizeof hex, "%016llx%016llx", static_cast<unsigned long long>(hi),
                      static_cast<unsigned long long>(lo));
        hex[12] = '8';                                         // version 8
        hex[16] = "89ab"[(hex[16] <= '9' ? hex[16] - '0' : hex[16] - 'a' + 10) & 3];  // variant
        const std::string uuid = std::string(hex, 8) + '-' + std::string(hex + 8, 4) + '-' +
                                 std::string(hex + 12, 4) + '-' + std::string(hex + 16, 4) + '-' +
                                 std::string(hex + 20, 12);
        bytes.replace(at, uuid.size(), uuid);
    }
};

}  // namespace

void VdbOutputOptions::validate() const {
    if (!(voxel_size > 0.0) || !std::isfinite(voxel_size))
        throw std::invalid_argument("voxel_size: expected a number > 0");
    if (!(half_width_voxels >= 1.0) || !std::isfinite(half_width_voxels))
        throw std::invalid_argument("half_width_voxels: expected a number >= 1");
    if (!(density_ramp_voxels > 0.0) || !(density_ramp_voxels <= 2.0 * half_width_voxels))
        throw std::invalid_argument(
            "density_ramp_voxels: expected a number > 0 and <= 2 * half_width_voxels");
    if (!(vertex_pin_voxels > 0.0) || !(vertex_pin_voxels <= 0.5))
        throw std::invalid_argument("vertex_pin_voxels: expected a number > 0 and <= 0.5");
    if (!(length_scale > 0.0) || !std::isfinite(length_scale))
        throw std::invalid_argument("length_scale: expected a number > 0");
}

VdbOutputInfo write_surface_vdb(const std::string& path, const tracker::SurfaceMesh& mesh,
                                const VdbOutputOptions& options, const FluidFields& fluid) {
    options.validate();
    if (mesh.count_live_triangles() == 0)
        throw std::invalid_argument("write_surface_vdb: the mesh has no triangles");
    initialize_openvdb_once();

    VdbOutputInfo info;
    openvdb::FloatGrid::Ptr surface = surface_grid(mesh, options, info);
    info.surface_active_voxels = static_cast<long long>(surface->activeVoxelCount());
    openvdb::GridPtrVec grids{surface};
    if (options.density) {
        openvdb::FloatGrid::Ptr density = density_grid(*surface, options);
        info.density_active_voxels = static_cast<long long>(density->activeVoxelCount());
        grids.push_back(density);
    }
    if (fluid.grid)
        append_fluid_grids(fluid, options, grids, info);

    std::string bytes;
    try {
        bytes = CheckedArchive().write_seekable(grids);
    } catch (const openvdb::Exception& e) {
        throw WriteError(path + ": cannot write VDB: " + e.what());
    }
    std::ofstream out = open_temporary(path, std::ios::binary);
    out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
    commit_stream(out, path);
    return info;
}

}  // namespace meniscus::coupling
