#include "coupling/vdb_output.h"

#include "common/atomic_file.h"

#include <openvdb/openvdb.h>
#include <openvdb/tools/LevelSetUtil.h>
#include <openvdb/tools/MeshToVolume.h>

#include <cmath>
#include <fstream>
#include <mutex>
#include <stdexcept>
#include <vector>

namespace meniscus::coupling {

namespace {

void initialize_openvdb_once() {
    static std::once_flag flag;
    std::call_once(flag, [] { openvdb::initialize(); });
}

/// Voxel (i, j, k) centred on fluid cell (i, j, k).
openvdb::math::Transform::Ptr cell_centred_transform(const fluid::MacGrid& grid) {
    auto t = openvdb::math::Transform::createLinearTransform(grid.dx());
    const Eigen::Vector3d offset = grid.origin() + Eigen::Vector3d::Constant(0.5 * grid.dx());
    t->postTranslate(openvdb::Vec3d(offset.x(), offset.y(), offset.z()));
    return t;
}

void append_fluid_grids(const fluid::MacGrid& grid, const fluid::Array3<double>* pressure,
                        openvdb::GridPtrVec& grids) {
    const auto transform = cell_centred_transform(grid);
    auto vel = openvdb::Vec3SGrid::create(openvdb::Vec3s(0.0f));
    vel->setName("vel");
    vel->setTransform(transform);
    vel->setVectorType(openvdb::VEC_CONTRAVARIANT_RELATIVE);
    auto acc = vel->getAccessor();
    for (int k = 0; k < grid.nz(); ++k)
        for (int j = 0; j < grid.ny(); ++j)
            for (int i = 0; i < grid.nx(); ++i) {
                const float u =
                    static_cast<float>(0.5 * (grid.u()(i, j, k) + grid.u()(i + 1, j, k)));
                const float v =
                    static_cast<float>(0.5 * (grid.v()(i, j, k) + grid.v()(i, j + 1, k)));
                const float w =
                    static_cast<float>(0.5 * (grid.w()(i, j, k) + grid.w()(i, j, k + 1)));
                acc.setValue(openvdb::Coord(i, j, k), openvdb::Vec3s(u, v, w));
            }
    grids.push_back(vel);
    if (pressure && pressure->ni() == grid.nx() && pressure->nj() == grid.ny() &&
        pressure->nk() == grid.nz()) {
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
    }
}

/// io::File::write() with a stream we own: File::write() opens its own std::ofstream and never
/// checks it, so a full disk left a truncated file; here the caller checks flush, close and
/// size (commit_stream) before the rename. The bytes are those of io::File (a seekable archive
/// with grid offsets, which readers such as Blender need).
class CheckedArchive final : public openvdb::io::Archive {
public:
    void write_seekable(std::ostream& out, const openvdb::GridPtrVec& grids) const {
        openvdb::io::Archive::write(out, grids, /*seekable=*/true);
    }
};

}  // namespace

void VdbOutputOptions::validate() const {
    if (!(voxel_size > 0.0) || !std::isfinite(voxel_size))
        throw std::invalid_argument("voxel_size: expected a number > 0");
    if (!(half_width_voxels >= 1.0) || !std::isfinite(half_width_voxels))
        throw std::invalid_argument("half_width_voxels: expected a number >= 1");
}

VdbOutputInfo write_surface_vdb(const std::string& path, const tracker::SurfaceMesh& mesh,
                                const VdbOutputOptions& options, const FluidFields& fluid) {
    options.validate();
    initialize_openvdb_once();

    std::vector<openvdb::Vec3s> points;
    std::vector<openvdb::Vec3I> triangles;
    std::vector<int> dense(static_cast<size_t>(mesh.num_vertices()), tracker::INVALID_INDEX);
    for (int vi = 0; vi < mesh.num_vertices(); ++vi) {
        if (!mesh.vertex_alive(vi))
            continue;
        dense[static_cast<size_t>(vi)] = static_cast<int>(points.size());
        const tracker::Vec3& p = mesh.position(vi);
        points.emplace_back(static_cast<float>(p.x()), static_cast<float>(p.y()),
                            static_cast<float>(p.z()));
    }
    for (int ti = 0; ti < mesh.num_triangles(); ++ti) {
        if (!mesh.triangle_alive(ti))
            continue;
        const tracker::Triangle& t = mesh.triangle(ti);
        // meshToLevelSet finds the inside by flood fill, so the winding does not set the sign.
        triangles.emplace_back(static_cast<unsigned>(dense[static_cast<size_t>(t[0])]),
                               static_cast<unsigned>(dense[static_cast<size_t>(t[1])]),
                               static_cast<unsigned>(dense[static_cast<size_t>(t[2])]));
    }
    if (triangles.empty())
        throw std::invalid_argument("write_surface_vdb: the mesh has no triangles");

    const auto transform = openvdb::math::Transform::createLinearTransform(options.voxel_size);
    openvdb::FloatGrid::Ptr surface = openvdb::tools::meshToLevelSet<openvdb::FloatGrid>(
        *transform, points, triangles, static_cast<float>(options.half_width_voxels));
    surface->setName("surface");
    surface->setGridClass(openvdb::GRID_LEVEL_SET);

    openvdb::GridPtrVec grids{surface};
    VdbOutputInfo info;
    info.surface_active_voxels = static_cast<long long>(surface->activeVoxelCount());
    if (options.density) {
        openvdb::FloatGrid::Ptr density = surface->deepCopy();
        // Inside the inner half band the fog ramps from 0 at the surface to 1 at the band edge.
        openvdb::tools::sdfToFogVolume(*density);
        density->setName("density");
        info.density_active_voxels = static_cast<long long>(density->activeVoxelCount());
        grids.push_back(density);
    }

    if (fluid.grid)
        append_fluid_grids(*fluid.grid, fluid.pressure, grids);

    std::ofstream out = open_temporary(path, std::ios::binary);
    try {
        CheckedArchive().write_seekable(out, grids);
    } catch (const openvdb::Exception& e) {
        out.close();
        std::remove(temporary_path_for(path).c_str());
        throw WriteError(path + ": cannot write VDB: " + e.what());
    }
    commit_stream(out, path);
    return info;
}

}  // namespace meniscus::coupling
