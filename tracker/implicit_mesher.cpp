#include "tracker/implicit_mesher.h"

#include "tracker/broadphase.h"
#include "tracker/crease_snap.h"
#include "tracker/isotropic_remesh.h"
#include "tracker/mesh_measures.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <iomanip>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <unordered_map>
#include <vector>

namespace meniscus::tracker {

namespace {

/// Grid spacing of marching tetrahedra relative to the requested edge length: the raw
/// surface is then a bit finer than the target and remeshing mostly collapses and smooths.
constexpr double GRID_SPACING_FRACTION = 0.7;
/// Bisection/regula-falsi steps for each edge crossing.
constexpr int ROOT_ITERATIONS = 30;
/// Grid cells of padding around the shape's bounds.
constexpr int PADDING_CELLS = 2;
/// Keep crossings this fraction of a grid edge away from grid nodes (no zero-length edges).
constexpr double MIN_CROSSING_PARAMETER = 1e-3;

/// Crease band relative to edge_length when CreaseRefinementOptions::band is 0.
constexpr double DEFAULT_CREASE_BAND_EDGES = 2.0;

/// Cube corner offsets indexed by bits (x = bit 0, y = bit 1, z = bit 2).
constexpr std::array<std::array<int, 3>, 8> CORNER = {
    {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, 0}, {0, 0, 1}, {1, 0, 1}, {0, 1, 1}, {1, 1, 1}}};
/// Kuhn subdivision: six tetrahedra from corner 0 to corner 7 along each axis permutation.
constexpr std::array<std::array<int, 4>, 6> KUHN_TETS = {
    {{0, 1, 3, 7}, {0, 1, 5, 7}, {0, 2, 3, 7}, {0, 2, 6, 7}, {0, 4, 5, 7}, {0, 4, 6, 7}}};

class MarchingTetrahedra {
public:
    /// Along an axis the periods wrap, the lattice covers one period with a whole number of
    /// cells (spacing within h·(1 ± 1/n)) and its last cube joins the last node to node 0.
    MarchingTetrahedra(const ImplicitShape& shape, double h, const MeshPeriods& periods,
                       const CancellationToken& cancel)
        : m_shape(shape), m_h(Vec3::Constant(h)), m_periods(periods), m_cancel(cancel) {
        Box3 b = shape.bounds();
        if (b.isEmpty())
            throw std::runtime_error("shape has empty bounds");
        for (int a = 0; a < 3; ++a)
            if (periods.wraps(a)) {  // the shape may be unbounded along a wrapping axis
                b.min()[a] = periods.origin[a];
                b.max()[a] = periods.origin[a] + periods.length[a];
            }
        if (!b.min().allFinite() || !b.max().allFinite())
            throw std::invalid_argument(
                "shape is unbounded (e.g. a half-space): intersect it with a box");
        m_origin = b.min() - Vec3::Constant(PADDING_CELLS * h);
        // Counted in double first: a huge shape or a tiny h must not overflow the int counts.
        std::array<double, 3> n{};
        for (int i = 0; i < 3; ++i) {
            n[i] = std::ceil(b.sizes()[i] / h) + 2 * PADDING_CELLS + 1;
            if (periods.wraps(i)) {
                n[i] = std::max(3.0, std::round(periods.length[i] / h));
                m_h[i] = periods.length[i] / n[i];
                m_origin[i] = periods.origin[i];
            }
        }
        const double nodes = n[0] * n[1] * n[2];
        if (!(nodes <= MAX_NODES) || !(h > 0.0)) {
            std::ostringstream s;
            s << "edge_length: too small for the shape's size (the meshing grid would need "
              << std::setprecision(3) << nodes << " nodes, at most " << MAX_NODES << ")";
            throw std::invalid_argument(s.str());
        }
        for (int i = 0; i < 3; ++i) {
            m_n[i] = static_cast<int>(n[i]);
            m_cubes[i] = periods.wraps(i) ? m_n[i] : m_n[i] - 1;
        }
        m_phi.resize(static_cast<size_t>(nodes));
        for (int k = 0; k < m_n[2]; ++k) {
            m_cancel.throw_if_requested("meshing the initial surface");
            for (int j = 0; j < m_n[1]; ++j)
                for (int i = 0; i < m_n[0]; ++i) {
                    double v = shape.value(node_position(i, j, k));
                    if (v == 0.0)
                        v = std::numeric_limits<double>::min();  // zero counts as outside
                    m_phi[node_index(i, j, k)] = v;
                }
        }
        check_periodic();
    }

    SurfaceMesh build() {
        for (int k = 0; k < m_cubes[2]; ++k) {
            m_cancel.throw_if_requested("meshing the initial surface");
            for (int j = 0; j < m_cubes[1]; ++j)
                for (int i = 0; i < m_cubes[0]; ++i)
                    march_cube(i, j, k);
        }
        SurfaceMesh mesh(std::move(m_positions), m_triangles);
        if (m_periods.any())
            mesh.set_periods(m_periods);
        return mesh;
    }

private:
    static constexpr double MAX_NODES = 2.0e8;

    /// Node (i, j, k), an index n along a wrapping axis being node 0.
    size_t node_index(int i, int j, int k) const {
        const auto wrapped = [&](int v, int a) {
            return v == m_n[a] && m_periods.wraps(a) ? 0 : v;
        };
        return (static_cast<size_t>(wrapped(k, 2)) * m_n[1] + wrapped(j, 1)) * m_n[0] +
               wrapped(i, 0);
    }
    /// Node (i, j, k)'s position; index n along a wrapping axis is node 0's image one period on.
    Vec3 node_position(int i, int j, int k) const {
        return m_origin + m_h.cwiseProduct(Vec3(i, j, k));
    }

    /// A shape meshed on a periodic lattice must be periodic itself: φ one period on (at the
    /// images of the nodes of the lattice's first plane) must have the sign it has there.
    void check_periodic() const {
        static const char* names[3] = {"x", "y", "z"};
        for (int a = 0; a < 3; ++a) {
            if (!m_periods.wraps(a))
                continue;
            const int b = (a + 1) % 3, c = (a + 2) % 3;
            for (int q = 0; q < m_n[c]; ++q)
                for (int r = 0; r < m_n[b]; ++r) {
                    std::array<int, 3> idx{};
                    idx[b] = r;
                    idx[c] = q;
                    const double here = m_phi[node_index(idx[0], idx[1], idx[2])];
                    idx[a] = m_n[a];
                    const double there = m_shape.value(node_position(idx[0], idx[1], idx[2]));
                    if ((here < 0.0) != (there < 0.0))
                        throw std::invalid_argument(
                            std::string("periods: the shape is not periodic along ") + names[a] +
                            ": it is inside at a point of one face of the box and outside at "
                            "the same point of the opposite face");
                }
        }
    }

    int crossing_vertex(size_t n0, const Vec3& p0, size_t n1, const Vec3& p1) {
        const std::uint64_t key =
            n0 < n1 ? (std::uint64_t(n0) << 32 | n1) : (std::uint64_t(n1) << 32 | n0);
        auto it = m_edge_vertex.find(key);
        if (it != m_edge_vertex.end())
            return it->second;
        // Regula falsi (Illinois) on φ along the segment, bracketed by the node values.
        double s0 = 0.0, s1 = 1.0, f0 = m_phi[n0], f1 = m_phi[n1];
        double s = f0 / (f0 - f1);
        for (int it2 = 0; it2 < ROOT_ITERATIONS; ++it2) {
            s = (s0 * f1 - s1 * f0) / (f1 - f0);
            const double f = m_shape.value(p0 + s * (p1 - p0));
            if (f == 0.0)
                break;
            if ((f < 0.0) == (f0 < 0.0)) {
                s0 = s;
                f0 = f;
                f1 *= 0.5;
            } else {
                s1 = s;
                f1 = f;
                f0 *= 0.5;
            }
        }
        s = std::clamp(s, MIN_CROSSING_PARAMETER, 1.0 - MIN_CROSSING_PARAMETER);
        const int vi = static_cast<int>(m_positions.size());
        m_positions.push_back(m_periods.any() ? m_periods.wrap(p0 + s * (p1 - p0))
                                              : Vec3(p0 + s * (p1 - p0)));
        m_edge_vertex.emplace(key, vi);
        return vi;
    }

    /// Crossing vertex vi's position at its image nearest `reference`.
    Vec3 near(int vi, const Vec3& reference) const {
        return m_periods.nearest_image(m_positions[static_cast<size_t>(vi)], reference);
    }

    void emit(int a, int b, int c, const Vec3& inside_to_outside) {
        const Vec3& pa = m_positions[static_cast<size_t>(a)];
        const Vec3 n = (near(b, pa) - pa).cross(near(c, pa) - pa);
        if (n.dot(inside_to_outside) >= 0.0)
            m_triangles.push_back({a, b, c});
        else
            m_triangles.push_back({a, c, b});
    }

    void march_cube(int i, int j, int k) {
        std::array<size_t, 8> node;
        std::array<Vec3, 8> pos;
        for (int c = 0; c < 8; ++c) {
            node[c] = node_index(i + CORNER[c][0], j + CORNER[c][1], k + CORNER[c][2]);
            pos[c] = node_position(i + CORNER[c][0], j + CORNER[c][1], k + CORNER[c][2]);
        }
        for (const auto& tet : KUHN_TETS) {
            std::array<int, 4> in, out;
            int n_in = 0, n_out = 0;
            for (int c : tet)
                (m_phi[node[c]] < 0.0 ? in[n_in++] : out[n_out++]) = c;
            if (n_in == 0 || n_out == 0)
                continue;
            Vec3 c_in = Vec3::Zero(), c_out = Vec3::Zero();
            for (int q = 0; q < n_in; ++q)
                c_in += pos[in[q]] / n_in;
            for (int q = 0; q < n_out; ++q)
                c_out += pos[out[q]] / n_out;
            const Vec3 dir = c_out - c_in;
            const auto cross = [&](int a, int b) {
                return crossing_vertex(node[a], pos[a], node[b], pos[b]);
            };
            if (n_in == 1 || n_out == 1) {
                const bool lone_in = n_in == 1;
                const int lone = lone_in ? in[0] : out[0];
                const auto& others = lone_in ? out : in;
                emit(cross(lone, others[0]), cross(lone, others[1]), cross(lone, others[2]), dir);
            } else {
                // Two in, two out: a quad, split along its shorter diagonal.
                const int a = cross(in[0], out[0]), b = cross(in[0], out[1]);
                const int c = cross(in[1], out[1]), d = cross(in[1], out[0]);
                const Vec3& pa = m_positions[static_cast<size_t>(a)];
                const Vec3& pb = m_positions[static_cast<size_t>(b)];
                if ((pa - near(c, pa)).squaredNorm() <= (pb - near(d, pb)).squaredNorm()) {
                    emit(a, b, c, dir);
                    emit(a, c, d, dir);
                } else {
                    emit(a, b, d, dir);
                    emit(b, c, d, dir);
                }
            }
        }
    }

    const ImplicitShape& m_shape;
    Vec3 m_h;  // spacing per axis: h, or a period over a whole number of cells
    MeshPeriods m_periods;
    CancellationToken m_cancel;
    Vec3 m_origin;
    std::array<int, 3> m_n{};      // nodes per axis
    std::array<int, 3> m_cubes{};  // cubes per axis: m_n − 1, or m_n along a wrapping axis
    std::vector<double> m_phi;
    std::vector<Vec3> m_positions;
    std::vector<Triangle> m_triangles;
    std::unordered_map<std::uint64_t, int> m_edge_vertex;
};

Vec3 unit_normal(const ImplicitShape& shape, const Vec3& x) {
    const Vec3 g = shape.gradient(x);
    const double n = g.norm();
    return n > 0.0 ? Vec3(g / n) : Vec3::Zero();
}

/// Midpoints of the edges whose end normals turn by more than `angle`: points within half an
/// edge of the shape's creases.
std::vector<Vec3> crease_points(const SurfaceMesh& mesh, const ImplicitShape& shape, double angle,
                                int* crease_vertices) {
    std::vector<Vec3> normal(static_cast<size_t>(mesh.num_vertices()), Vec3::Zero());
    for (int vi = 0; vi < mesh.num_vertices(); ++vi)
        if (mesh.vertex_alive(vi))
            normal[static_cast<size_t>(vi)] = unit_normal(shape, mesh.position(vi));
    const double min_cos = std::cos(angle);
    std::vector<Vec3> points;
    std::vector<std::uint8_t> marked(normal.size(), 0);
    for (int ei = 0; ei < mesh.num_edges(); ++ei) {
        if (!mesh.edge_alive(ei))
            continue;
        const auto& e = mesh.edge(ei);
        if (normal[static_cast<size_t>(e[0])].dot(normal[static_cast<size_t>(e[1])]) >= min_cos)
            continue;
        points.push_back(0.5 * (mesh.position(e[0]) + mesh.position(e[1])));
        marked[static_cast<size_t>(e[0])] = marked[static_cast<size_t>(e[1])] = 1;
    }
    if (crease_vertices)
        *crease_vertices = static_cast<int>(std::count(marked.begin(), marked.end(), 1));
    return points;
}

/// True when a crease point lies within `radius` of x (`hash` holds the points as boxes).
bool near_crease(const SpatialHash& hash, const std::vector<Vec3>& points, const Vec3& x,
                 double radius, std::vector<int>& candidates) {
    hash.query(Box3d(x - Vec3::Constant(radius), x + Vec3::Constant(radius)), candidates);
    for (int i : candidates)
        if ((points[static_cast<size_t>(i)] - x).squaredNorm() <= radius * radius)
            return true;
    return false;
}

/// ImplicitMeshOptions' crease refinement; returns the edges split.
int refine_creases(SurfaceMesh& mesh, const ImplicitShape& shape,
                   const ImplicitMeshOptions& options, int* crease_vertices) {
    const CreaseRefinementOptions& crease = options.crease;
    const double band =
        crease.band > 0.0 ? crease.band : DEFAULT_CREASE_BAND_EDGES * options.edge_length;
    int splits = 0;
    for (int pass = 0; pass < crease.levels; ++pass) {
        options.cancel.throw_if_requested("refining creases");
        const std::vector<Vec3> points =
            crease_points(mesh, shape, crease.angle, pass == 0 ? crease_vertices : nullptr);
        if (points.empty())
            break;
        SpatialHash hash(band);
        for (size_t i = 0; i < points.size(); ++i)
            hash.insert(static_cast<int>(i), Box3d(points[i], points[i]));
        std::vector<int> candidates;
        const double min_length = options.edge_length * std::ldexp(1.0, -(pass + 1));
        const int edges = mesh.num_edges();  // edges made by this pass wait for the next
        for (int ei = 0; ei < edges; ++ei) {
            if (!mesh.edge_alive(ei))
                continue;
            const auto& e = mesh.edge(ei);
            const Vec3 a = mesh.position(e[0]), b = mesh.position(e[1]);
            const Vec3 mid = 0.5 * (a + b);
            if ((a - b).norm() <= min_length || !near_crease(hash, points, mid, band, candidates))
                continue;
            mesh.split_edge(ei, project_to_zero_set(shape, mid, options.projection_iterations));
            ++splits;
        }
    }
    return splits;
}

}  // namespace

void ImplicitMeshOptions::validate() const {
    if (!(edge_length > 0.0) || !std::isfinite(edge_length))
        throw std::invalid_argument("edge_length: expected a number > 0");
    if (remesh_iterations < 0)
        throw std::invalid_argument("remesh_iterations: expected an integer >= 0");
    if (projection_iterations < 0)
        throw std::invalid_argument("projection_iterations: expected an integer >= 0");
    crease.validate();
    periods.validate();
    if (periods.any() && (crease.levels > 0 || crease.snap))
        throw std::invalid_argument(
            "crease: crease refinement and snapping are not available on periodic meshes");
    for (int a = 0; a < 3; ++a)
        if (periods.wraps(a) && periods.length[a] < MeshPeriods::PERIOD_TO_EDGE_RATIO * edge_length)
            throw std::invalid_argument(
                std::string("periods/length/") + "xyz"[a] + ": shorter than " +
                std::to_string(static_cast<int>(MeshPeriods::PERIOD_TO_EDGE_RATIO)) +
                " edge lengths (the minimum image of an element must be unambiguous)");
}

void CreaseRefinementOptions::validate() const {
    if (levels < 0 || levels > MAX_LEVELS)
        throw std::invalid_argument("crease.levels: expected an integer in [0, " +
                                    std::to_string(MAX_LEVELS) + "]");
    if (!(angle > 0.0 && angle < M_PI))
        throw std::invalid_argument("crease.angle: expected radians in (0, pi)");
    if (snap && !(angle < 0.5 * M_PI))
        throw std::invalid_argument("crease.angle: expected radians in (0, pi/2) with snap");
    if (!(band >= 0.0) || !std::isfinite(band))
        throw std::invalid_argument("crease.band: expected a number >= 0");
}

Vec3 project_to_zero_set(const ImplicitShape& shape, const Vec3& x, int iterations) {
    Vec3 p = x;
    for (int it = 0; it < iterations; ++it) {
        const double v = shape.value(p);
        if (v == 0.0)
            break;
        const Vec3 g = shape.gradient(p);
        const double g2 = g.squaredNorm();
        if (!(g2 > 0.0))
            break;
        p -= (v / g2) * g;
    }
    return p;
}

SurfaceMesh mesh_implicit_shape(const ImplicitShape& shape, const ImplicitMeshOptions& options,
                                ImplicitMeshReport* report) {
    options.validate();
    MarchingTetrahedra marching(shape, GRID_SPACING_FRACTION * options.edge_length, options.periods,
                                options.cancel);
    SurfaceMesh mesh = marching.build();
    if (mesh.count_live_triangles() == 0) {
        std::ostringstream s;
        s << "the shape has no surface at edge_length " << options.edge_length
          << " m (is it smaller than one edge?)";
        throw std::runtime_error(s.str());
    }
    IsotropicRemeshOptions remesh;
    remesh.target_edge_length = options.edge_length;
    remesh.iterations = options.remesh_iterations;
    remesh.cancel = options.cancel;
    const int newton = options.projection_iterations;
    isotropic_remesh(mesh, remesh, [&shape, newton](const Vec3& p) {
        return project_to_zero_set(shape, p, newton);
    });
    CreaseSnapReport snapped;
    if (options.crease.snap) {
        CreaseSnapOptions snap;
        snap.angle = options.crease.angle;
        snap.projection_iterations = options.projection_iterations;
        snapped = snap_to_creases(mesh, shape, snap);
    }
    const double unrefined_mean_edge_length = edge_length_stats(mesh).mean;
    int crease_vertices = 0;
    const int crease_splits = refine_creases(mesh, shape, options, &crease_vertices);
    if (report) {
        report->unrefined_mean_edge_length = unrefined_mean_edge_length;
        report->crease_vertices = crease_vertices;
        report->crease_splits = crease_splits;
        report->crease_snaps = snapped.snaps;
        report->crease_flips = snapped.flips;
        report->snapped_vertices = snapped.crease_vertices;
        report->vertices = mesh.count_live_vertices();
        report->triangles = mesh.count_live_triangles();
        report->mean_edge_length = edge_length_stats(mesh).mean;
        const AngleStats angles = angle_stats(mesh);
        report->min_angle_degrees = angles.min_degrees;
        report->max_angle_degrees = angles.max_degrees;
        report->max_abs_phi = 0.0;
        for (int vi = 0; vi < mesh.num_vertices(); ++vi)
            report->max_abs_phi =
                std::max(report->max_abs_phi, std::abs(shape.value(mesh.position(vi))));
    }
    return mesh;
}

}  // namespace meniscus::tracker
