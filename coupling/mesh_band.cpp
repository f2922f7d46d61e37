#include "coupling/mesh_band.h"

#include "tracker/distance.h"

#include <openvdb/openvdb.h>
#include <openvdb/tools/MeshToVolume.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <chrono>
#include <cmath>
#include <limits>
#include <mutex>
#include <stdexcept>
#include <utility>

namespace meniscus::coupling {

namespace {

using tracker::SurfaceMesh;
using tracker::Vec3;

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

/// Live triangles packed for OpenVDB, with vertex positions already in lattice index space.
struct PackedMesh {
    std::vector<openvdb::Vec3d> points;     ///< index space: (x − origin)/voxel_size
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

PackedMesh pack_mesh(const SurfaceMesh& mesh, const VoxelLattice& lattice) {
    PackedMesh packed;
    std::vector<unsigned> dense(static_cast<size_t>(mesh.num_vertices()), 0u);
    for (int vi = 0; vi < mesh.num_vertices(); ++vi) {
        if (!mesh.vertex_alive(vi))
            continue;
        dense[static_cast<size_t>(vi)] = static_cast<unsigned>(packed.points.size());
        const Vec3 p = (mesh.position(vi) - lattice.origin) / lattice.voxel_size;
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
/// test, see the file comment of mesh_band.h).
struct SideQuery {
    double distance = 0.0;
    int region = 0;
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

/// Distance from x to live triangle ti.
double triangle_distance(const SurfaceMesh& mesh, int ti, const Vec3& x) {
    const tracker::Triangle& t = mesh.triangle(ti);
    return tracker::point_triangle_proximity(x, mesh.position(t[0]), mesh.position(t[1]),
                                             mesh.position(t[2]))
        .distance;
}

/// The seeds of a band voxel: OpenVDB's closest polygon of itself and of its six face neighbours.
constexpr int SEED_COUNT = 7;
constexpr std::array<std::array<int, 3>, SEED_COUNT> SEED_OFFSETS{
    {{0, 0, 0}, {-1, 0, 0}, {1, 0, 0}, {0, -1, 0}, {0, 1, 0}, {0, 0, -1}, {0, 0, 1}}};

/// The closest triangle to x found from `seeds` (mesh triangle indices or INVALID_INDEX): the
/// closest seed, then walk_to_closest_triangle().
int closest_triangle_near(const SurfaceMesh& mesh, const std::array<int, SEED_COUNT>& seeds,
                          const Vec3& x) {
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

}  // namespace

void SignedBandOptions::validate() const {
    if (!(half_width_voxels > 0.0) || !std::isfinite(half_width_voxels))
        throw std::invalid_argument("half_width_voxels: expected a number > 0");
}

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

int region_at(const tracker::SurfaceMesh& mesh, const Eigen::Vector3d& x, int ambient_region) {
    const PseudoNormals normals = pseudo_normals(mesh);
    double best = std::numeric_limits<double>::infinity();
    int region = ambient_region;
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

SignedBand signed_band(const tracker::SurfaceMesh& mesh, const VoxelLattice& lattice,
                       const SignedBandOptions& options, const VoxelBounds* bounds) {
    options.validate();
    if (!(lattice.voxel_size > 0.0) || !std::isfinite(lattice.voxel_size))
        throw std::invalid_argument("signed_band: voxel_size: expected a number > 0");
    SignedBand band;
    const Clock::time_point start = Clock::now();

    // 1. OpenVDB: the band voxels and an approximate closest polygon of each.
    initialize_openvdb_once();
    const PackedMesh packed = pack_mesh(mesh, lattice);
    if (packed.triangles.empty())
        return band;
    // The packed points are in index space already: an identity transform.
    const openvdb::math::Transform::Ptr index_space =
        openvdb::math::Transform::createLinearTransform(1.0);
    openvdb::Int32Grid::Ptr polygon_grid = openvdb::Int32Grid::create(tracker::INVALID_INDEX);
    const float band_voxels = static_cast<float>(options.half_width_voxels);
    PackedMeshAdapter adapter{&packed};
    openvdb::tools::meshToVolume<openvdb::FloatGrid>(
        adapter, *index_space, band_voxels, band_voxels, openvdb::tools::UNSIGNED_DISTANCE_FIELD,
        polygon_grid.get());
    // Polygon indices → mesh triangle indices, in place, so neighbours can seed each other.
    for (auto it = polygon_grid->beginValueOn(); it; ++it) {
        const int polygon = *it;
        const bool valid =
            polygon >= 0 && static_cast<size_t>(polygon) < packed.triangle_of_polygon.size();
        it.setValue(valid ? packed.triangle_of_polygon[static_cast<size_t>(polygon)]
                          : tracker::INVALID_INDEX);
        const openvdb::Coord c = it.getCoord();
        if (valid && (!bounds || bounds->contains(c.x(), c.y(), c.z()))) {
            BandVoxel v;
            v.ijk = {c.x(), c.y(), c.z()};
            band.voxels.push_back(v);
        }
    }
    band.seconds_mesh_to_volume = seconds_since(start);

    // 2. Exact closest triangle, distance and side of every band voxel.
    const Clock::time_point exact_start = Clock::now();
    const PseudoNormals normals = pseudo_normals(mesh);
    const openvdb::Int32Grid& seeds_grid = *polygon_grid;
    tbb::parallel_for(
        tbb::blocked_range<size_t>(0, band.voxels.size()),
        [&](const tbb::blocked_range<size_t>& range) {
            auto seeds_of = seeds_grid.getConstAccessor();
            for (size_t b = range.begin(); b != range.end(); ++b) {
                BandVoxel& v = band.voxels[b];
                std::array<int, SEED_COUNT> seeds{};
                for (size_t s = 0; s < SEED_OFFSETS.size(); ++s) {
                    const openvdb::Coord c(v.ijk[0] + SEED_OFFSETS[s][0],
                                           v.ijk[1] + SEED_OFFSETS[s][1],
                                           v.ijk[2] + SEED_OFFSETS[s][2]);
                    int ti = tracker::INVALID_INDEX;
                    seeds[s] = seeds_of.probeValue(c, ti) ? ti : tracker::INVALID_INDEX;
                }
                const Vec3 x = lattice.centre(v.ijk[0], v.ijk[1], v.ijk[2]);
                v.closest_triangle = closest_triangle_near(mesh, seeds, x);
                const SideQuery side = query_side(mesh, normals, v.closest_triangle, x);
                v.phi = side.region == options.inside_region ? -side.distance : side.distance;
            }
        });
    band.seconds_exact = seconds_since(exact_start);
    return band;
}

}  // namespace meniscus::coupling
