#include "coupling/vdb_output.h"

#include "common/atomic_file.h"
#include "coupling/mesh_band.h"

#include <openvdb/openvdb.h>
#include <openvdb/tools/Prune.h>
#include <openvdb/tools/SignedFloodFill.h>

#include <algorithm>
#include <array>
#include <cmath>
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

/// The `surface` level set: signed band values, then signs outside the band.
openvdb::FloatGrid::Ptr surface_grid(const tracker::SurfaceMesh& mesh,
                                     const VdbOutputOptions& options) {
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
    auto acc = density->getAccessor();
    for (auto it = surface.cbeginValueAll(); it; ++it) {
        const double phi = *it;
        if (it.isVoxelValue()) {
            const double fog = std::clamp(0.5 - phi / ramp, 0.0, 1.0);
            if (fog > 0.0)
                acc.setValue(it.getCoord(), static_cast<float>(fog));
        } else if (phi < 0.0) {
            openvdb::CoordBBox box;
            it.getBoundingBox(box);
            density->fill(box, 1.0f, true);
        }
    }
    openvdb::tools::prune(density->tree());
    return density;
}

}  // namespace

void VdbOutputOptions::validate() const {
    if (!(voxel_size > 0.0) || !std::isfinite(voxel_size))
        throw std::invalid_argument("voxel_size: expected a number > 0");
    if (!(half_width_voxels >= 1.0) || !std::isfinite(half_width_voxels))
        throw std::invalid_argument("half_width_voxels: expected a number >= 1");
    if (!(density_ramp_voxels > 0.0) || !(density_ramp_voxels <= 2.0 * half_width_voxels))
        throw std::invalid_argument(
            "density_ramp_voxels: expected a number > 0 and <= 2 * half_width_voxels");
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
    openvdb::FloatGrid::Ptr surface = surface_grid(mesh, options);
    info.surface_active_voxels = static_cast<long long>(surface->activeVoxelCount());
    openvdb::GridPtrVec grids{surface};
    if (options.density) {
        openvdb::FloatGrid::Ptr density = density_grid(*surface, options);
        info.density_active_voxels = static_cast<long long>(density->activeVoxelCount());
        grids.push_back(density);
    }
    if (fluid.grid)
        append_fluid_grids(fluid, options, grids, info);

    const std::string tmp = temporary_path_for(path);
    try {
        openvdb::io::File file(tmp);
        file.write(grids);
        file.close();
    } catch (const openvdb::Exception& e) {
        std::remove(tmp.c_str());
        throw std::runtime_error(path + ": cannot write VDB: " + e.what());
    }
    commit_temporary(path);
    return info;
}

}  // namespace meniscus::coupling
