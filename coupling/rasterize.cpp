#include "coupling/rasterize.h"

#include "tracker/distance.h"

#include <openvdb/openvdb.h>
#include <openvdb/tools/MeshToVolume.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <limits>
#include <mutex>
#include <stdexcept>
#include <utility>
#include <vector>

namespace meniscus::coupling {

namespace {

using tracker::SurfaceMesh;
using tracker::Vec3;

/// The smallest band half width (cells) for which the breadth-first sign fill is exact.
constexpr double MIN_HALF_WIDTH_CELLS = 2.0;
/// The region of space no triangle encloses (tracker convention).
constexpr int AMBIENT_REGION = 0;
/// A barycentric coordinate at or below this counts as zero when finding the closest feature.
constexpr double BARYCENTRIC_FEATURE_TOLERANCE = 1e-9;
/// Bound on the steps of walk_to_closest_triangle().
constexpr int MAX_CLOSEST_TRIANGLE_WALK = 64;

using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point start) {
    return std::chrono::duration<double>(Clock::now() - start).count();
}

void initialize_openvdb_once() {
    static std::once_flag flag;
    std::call_once(flag, [] { openvdb::initialize(); });
}

/// Live triangles packed for OpenVDB, with vertex positions already in VDB index space.
struct PackedMesh {
    std::vector<openvdb::Vec3d> points;     ///< index space: (x − origin)/dx − ½
    std::vector<openvdb::Vec3I> triangles;  ///< into `points`
    std::vector<int> triangle_of_polygon;   ///< packed polygon → mesh triangle index
};

/// openvdb::tools::meshToVolume's MeshDataAdapter over a PackedMesh.
struct PackedMeshAdapter {
    const PackedMesh* mesh = nullptr;
    size_t polygonCount() const { return mesh->triangles.size(); }
    size_t pointCount() const { return mesh->points.size(); }
    size_t vertexCount(size_t) const { return 3; }
    void getIndexSpacePoint(size_t n, size_t v, openvdb::Vec3d& pos) const {
        pos = mesh->points[mesh->triangles[n][static_cast<int>(v)]];
    }
};

PackedMesh pack_mesh(const SurfaceMesh& mesh, const fluid::MacGrid& grid) {
    PackedMesh packed;
    std::vector<unsigned> dense(static_cast<size_t>(mesh.num_vertices()), 0u);
    const Vec3 shift = grid.origin() + Vec3::Constant(0.5 * grid.dx());
    for (int vi = 0; vi < mesh.num_vertices(); ++vi) {
        if (!mesh.vertex_alive(vi))
            continue;
        dense[static_cast<size_t>(vi)] = static_cast<unsigned>(packed.points.size());
        const Vec3 p = (mesh.position(vi) - shift) / grid.dx();
        packed.points.emplace_back(p.x(), p.y(), p.z());
    }
    for (int ti = 0; ti < mesh.num_triangles(); ++ti) {
        if (!mesh.triangle_alive(ti))
            continue;
        const tracker::Triangle& t = mesh.triangle(ti);
        packed.triangles.emplace_back(dense[static_cast<size_t>(t[0])],
                                      dense[static_cast<size_t>(t[1])],
                                      dense[static_cast<size_t>(t[2])]);
        packed.triangle_of_polygon.push_back(ti);
    }
    return packed;
}

/// Angle-weighted pseudo-normals of faces, edges and vertices (unnormalized where a sum).
struct PseudoNormals {
    std::vector<Vec3> face;    ///< unit normal per triangle (zero for dead/degenerate ones)
    std::vector<Vec3> edge;    ///< Σ incident unit face normals, per edge
    std::vector<Vec3> vertex;  ///< Σ incident angle · unit face normal, per vertex
};

PseudoNormals pseudo_normals(const SurfaceMesh& mesh) {
    PseudoNormals normals;
    normals.face.assign(static_cast<size_t>(mesh.num_triangles()), Vec3::Zero());
    normals.edge.assign(static_cast<size_t>(mesh.num_edges()), Vec3::Zero());
    normals.vertex.assign(static_cast<size_t>(mesh.num_vertices()), Vec3::Zero());
    for (int ti = 0; ti < mesh.num_triangles(); ++ti) {
        if (!mesh.triangle_alive(ti))
            continue;
        const tracker::Triangle& t = mesh.triangle(ti);
        const Vec3 n = (mesh.position(t[1]) - mesh.position(t[0]))
                           .cross(mesh.position(t[2]) - mesh.position(t[0]));
        const double length = n.norm();
        if (!(length > 0.0))
            continue;
        const Vec3 unit = n / length;
        normals.face[static_cast<size_t>(ti)] = unit;
        for (int corner = 0; corner < 3; ++corner) {
            const Vec3& p = mesh.position(t[corner]);
            const Vec3 a = mesh.position(t[(corner + 1) % 3]) - p;
            const Vec3 b = mesh.position(t[(corner + 2) % 3]) - p;
            const double angle = std::atan2(a.cross(b).norm(), a.dot(b));
            normals.vertex[static_cast<size_t>(t[corner])] += angle * unit;
            normals.edge[static_cast<size_t>(mesh.triangle_edges(ti)[corner])] += unit;
        }
    }
    return normals;
}

/// Distance from `x` to live triangle `ti` and the region of `x` as seen from it (pseudo-normal
/// test, see the file comment of rasterize.h).
struct SideQuery {
    double distance = 0.0;
    int region = AMBIENT_REGION;
};

SideQuery query_side(const SurfaceMesh& mesh, const PseudoNormals& normals, int ti, const Vec3& x) {
    const tracker::Triangle& t = mesh.triangle(ti);
    const tracker::PointTriangleProximity proximity = tracker::point_triangle_proximity(
        x, mesh.position(t[0]), mesh.position(t[1]), mesh.position(t[2]));
    const std::array<double, 3>& bary = proximity.barycentric;
    Vec3 pseudo = normals.face[static_cast<size_t>(ti)];
    int zero_count = 0;
    int zero_corner = -1;
    int nonzero_corner = -1;
    for (int corner = 0; corner < 3; ++corner) {
        if (bary[static_cast<size_t>(corner)] <= BARYCENTRIC_FEATURE_TOLERANCE) {
            ++zero_count;
            zero_corner = corner;
        } else {
            nonzero_corner = corner;
        }
    }
    if (zero_count == 2) {
        pseudo = normals.vertex[static_cast<size_t>(t[nonzero_corner])];
    } else if (zero_count == 1) {
        // Edge m of the triangle joins corners m and m+1: the edge opposite corner c is c+1.
        pseudo = normals.edge[static_cast<size_t>(mesh.triangle_edges(ti)[(zero_corner + 1) % 3])];
    }
    if (!(pseudo.squaredNorm() > 0.0))
        pseudo = normals.face[static_cast<size_t>(ti)];
    const Vec3 q = proximity.barycentric[0] * mesh.position(t[0]) +
                   proximity.barycentric[1] * mesh.position(t[1]) +
                   proximity.barycentric[2] * mesh.position(t[2]);
    SideQuery result;
    result.distance = proximity.distance;
    result.region = (x - q).dot(pseudo) > 0.0 ? mesh.labels(ti).outside : mesh.labels(ti).inside;
    return result;
}

/// Region of `x` from its closest live triangle over the whole mesh (brute force), or the
/// ambient region for a mesh without live triangles.
int region_by_closest_triangle(const SurfaceMesh& mesh, const PseudoNormals& normals,
                               const Vec3& x) {
    double best = std::numeric_limits<double>::infinity();
    int region = AMBIENT_REGION;
    for (int ti = 0; ti < mesh.num_triangles(); ++ti) {
        if (!mesh.triangle_alive(ti))
            continue;
        const SideQuery side = query_side(mesh, normals, ti, x);
        if (side.distance < best) {
            best = side.distance;
            region = side.region;
        }
    }
    return region;
}

/// Distance from x to live triangle ti.
double triangle_distance(const SurfaceMesh& mesh, int ti, const Vec3& x) {
    const tracker::Triangle& t = mesh.triangle(ti);
    return tracker::point_triangle_proximity(x, mesh.position(t[0]), mesh.position(t[1]),
                                             mesh.position(t[2]))
        .distance;
}

/// The closest triangle to x found from `seeds` (OpenVDB's closest polygons of the cell and its
/// face neighbours, which are approximate: its band dilation hands them from voxel to voxel):
/// the closest seed, then walk_to_closest_triangle().
int closest_triangle_near(const SurfaceMesh& mesh, const std::array<int, 7>& seeds, const Vec3& x) {
    int best = tracker::INVALID_INDEX;
    double best_distance = std::numeric_limits<double>::infinity();
    for (int ti : seeds) {
        if (ti == tracker::INVALID_INDEX || ti == best)
            continue;
        const double d = triangle_distance(mesh, ti, x);
        if (d < best_distance) {
            best_distance = d;
            best = ti;
        }
    }
    return walk_to_closest_triangle(mesh, best, x);
}

/// Gives every cell outside the band (φ not yet set, marked by a zero `sign`) the sign of the
/// band cells its face-connected component touches; breadth first from all band cells.
void fill_signs(std::vector<std::int8_t>& sign, int nx, int ny, int nz) {
    std::vector<size_t> queue;
    queue.reserve(sign.size());
    for (size_t flat = 0; flat < sign.size(); ++flat)
        if (sign[flat] != 0)
            queue.push_back(flat);
    const size_t sx = 1;
    const size_t sy = static_cast<size_t>(nx);
    const size_t sz = static_cast<size_t>(nx) * static_cast<size_t>(ny);
    for (size_t head = 0; head < queue.size(); ++head) {
        const size_t flat = queue[head];
        const int i = static_cast<int>(flat % sy);
        const int j = static_cast<int>((flat / sy) % static_cast<size_t>(ny));
        const int k = static_cast<int>(flat / sz);
        const std::int8_t s = sign[flat];
        const auto visit = [&](size_t neighbour) {
            if (sign[neighbour] == 0) {
                sign[neighbour] = s;
                queue.push_back(neighbour);
            }
        };
        if (i > 0)
            visit(flat - sx);
        if (i + 1 < nx)
            visit(flat + sx);
        if (j > 0)
            visit(flat - sy);
        if (j + 1 < ny)
            visit(flat + sy);
        if (k > 0)
            visit(flat - sz);
        if (k + 1 < nz)
            visit(flat + sz);
    }
}

}  // namespace

int walk_to_closest_triangle(const tracker::SurfaceMesh& mesh, int start_ti,
                             const Eigen::Vector3d& x) {
    if (start_ti == tracker::INVALID_INDEX)
        return tracker::INVALID_INDEX;
    int best = start_ti;
    double best_distance = triangle_distance(mesh, best, x);
    for (int step = 0; step < MAX_CLOSEST_TRIANGLE_WALK; ++step) {
        const int current = best;
        for (int vi : mesh.triangle(current)) {
            for (int ti : mesh.vertex_triangles(vi)) {
                if (ti == current || !mesh.triangle_alive(ti))
                    continue;
                const double d = triangle_distance(mesh, ti, x);
                if (d < best_distance) {
                    best_distance = d;
                    best = ti;
                }
            }
        }
        if (best == current)
            break;
    }
    return best;
}

void RasterizeOptions::validate() const {
    if (!(half_width_cells >= MIN_HALF_WIDTH_CELLS) || !std::isfinite(half_width_cells))
        throw std::invalid_argument("half_width_cells: expected a number >= 2");
}

RasterizeResult rasterize_mesh(const tracker::SurfaceMesh& mesh, const fluid::MacGrid& grid,
                               const RasterizeOptions& options) {
    options.validate();
    const Clock::time_point start = Clock::now();
    const int nx = grid.nx();
    const int ny = grid.ny();
    const int nz = grid.nz();
    const double dx = grid.dx();

    RasterizeResult result;
    result.liquid_region = options.liquid_region;
    result.phi.resize(nx, ny, nz, 0.0);
    result.closest_triangle.resize(nx, ny, nz, tracker::INVALID_INDEX);

    // 1. OpenVDB: unsigned distance and closest polygon in the band.
    initialize_openvdb_once();
    const PackedMesh packed = pack_mesh(mesh, grid);
    std::vector<std::pair<size_t, int>> band;  // (flat cell index, mesh triangle)
    if (!packed.triangles.empty()) {
        openvdb::math::Transform::Ptr transform =
            openvdb::math::Transform::createLinearTransform(dx);
        const Vec3 shift = grid.origin() + Vec3::Constant(0.5 * dx);
        transform->postTranslate(openvdb::Vec3d(shift.x(), shift.y(), shift.z()));
        openvdb::Int32Grid::Ptr index_grid = openvdb::Int32Grid::create();
        const float band_voxels = static_cast<float>(options.half_width_cells);
        PackedMeshAdapter adapter{&packed};
        openvdb::tools::meshToVolume<openvdb::FloatGrid>(
            adapter, *transform, band_voxels, band_voxels, openvdb::tools::UNSIGNED_DISTANCE_FIELD,
            index_grid.get());
        for (auto it = index_grid->cbeginValueOn(); it; ++it) {
            const openvdb::Coord c = it.getCoord();
            if (c.x() < 0 || c.y() < 0 || c.z() < 0 || c.x() >= nx || c.y() >= ny || c.z() >= nz)
                continue;
            const int polygon = *it;
            if (polygon < 0 || static_cast<size_t>(polygon) >= packed.triangle_of_polygon.size())
                continue;
            band.emplace_back(result.phi.index(c.x(), c.y(), c.z()),
                              packed.triangle_of_polygon[static_cast<size_t>(polygon)]);
        }
    }
    result.timings.mesh_to_volume = seconds_since(start);

    // 2. Band cells: exact distance to the closest triangle, sign from its side and labels.
    const Clock::time_point band_start = Clock::now();
    const PseudoNormals normals = pseudo_normals(mesh);
    std::vector<std::int8_t> sign(result.phi.size(), 0);
    const size_t sy = static_cast<size_t>(nx);
    const size_t sz = static_cast<size_t>(nx) * static_cast<size_t>(ny);
    for (const auto& cell : band)
        result.closest_triangle[cell.first] = cell.second;
    const fluid::Array3<int>& vdb_triangle = result.closest_triangle;
    std::vector<int> refined(band.size(), tracker::INVALID_INDEX);
    tbb::parallel_for(
        tbb::blocked_range<size_t>(0, band.size()), [&](const tbb::blocked_range<size_t>& range) {
            for (size_t b = range.begin(); b != range.end(); ++b) {
                const size_t flat = band[b].first;
                const int i = static_cast<int>(flat % sy);
                const int j = static_cast<int>((flat / sy) % static_cast<size_t>(ny));
                const int k = static_cast<int>(flat / sz);
                const Vec3 x = grid.cell_centre(i, j, k);
                std::array<int, 7> seeds{};
                seeds.fill(tracker::INVALID_INDEX);
                seeds[0] = band[b].second;
                const std::array<std::array<int, 3>, 6> offsets{
                    {{-1, 0, 0}, {1, 0, 0}, {0, -1, 0}, {0, 1, 0}, {0, 0, -1}, {0, 0, 1}}};
                for (size_t o = 0; o < offsets.size(); ++o) {
                    const int ni = i + offsets[o][0];
                    const int nj = j + offsets[o][1];
                    const int nk = k + offsets[o][2];
                    if (vdb_triangle.contains(ni, nj, nk))
                        seeds[o + 1] = vdb_triangle(ni, nj, nk);
                }
                refined[b] = closest_triangle_near(mesh, seeds, x);
            }
        });
    tbb::parallel_for(
        tbb::blocked_range<size_t>(0, band.size()), [&](const tbb::blocked_range<size_t>& range) {
            for (size_t b = range.begin(); b != range.end(); ++b) {
                const size_t flat = band[b].first;
                const int ti = refined[b];
                const Vec3 x =
                    grid.cell_centre(static_cast<int>(flat % sy),
                                     static_cast<int>((flat / sy) % static_cast<size_t>(ny)),
                                     static_cast<int>(flat / sz));
                const SideQuery side = query_side(mesh, normals, ti, x);
                const bool liquid = side.region == options.liquid_region;
                result.phi[flat] = liquid ? -side.distance : side.distance;
                result.closest_triangle[flat] = ti;
                sign[flat] = liquid ? -1 : 1;
            }
        });
    result.band_cells = static_cast<long long>(band.size());
    double band_value = options.half_width_cells * dx;
    for (const auto& cell : band)
        band_value = std::max(band_value, std::abs(result.phi[cell.first]));
    result.band_value = band_value;
    result.timings.band = seconds_since(band_start);

    // 3. Cells outside the band: sign of the connected band cells.
    const Clock::time_point fill_start = Clock::now();
    if (band.empty()) {
        const int region = region_by_closest_triangle(mesh, normals, grid.cell_centre(0, 0, 0));
        std::fill(sign.begin(), sign.end(), region == options.liquid_region ? -1 : 1);
    } else {
        fill_signs(sign, nx, ny, nz);
    }
    for (size_t flat = 0; flat < sign.size(); ++flat)
        if (result.closest_triangle[flat] == tracker::INVALID_INDEX)
            result.phi[flat] = sign[flat] < 0 ? -band_value : band_value;
    result.timings.sign_fill = seconds_since(fill_start);
    result.timings.total = seconds_since(start);
    return result;
}

}  // namespace meniscus::coupling
