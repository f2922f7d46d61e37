#include "tracker/collision_candidates.h"

#include "tracker/ordered_collect.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace meniscus::tracker {

namespace {

/// Extra padding of the shared broad phase, in units of ε_p: the candidate pairs found once for
/// the repulsion (static boxes at t0, padded ε_p/2) and the first CCD sweep (swept boxes) stay a
/// superset for any later displacement within half of this of the one they were built for, so
/// repulsion impulses and small CCD impulses do not force a new broad phase. (ε_p is ~10⁻³ ξ,
/// so the extra candidates are a few per cent.)
constexpr double CANDIDATE_SLACK_FRACTION = 8.0;
/// The reuse test leaves this fraction of the slack unused, for the rounding of box corners.
constexpr double CANDIDATE_SLACK_SAFETY = 0.5;
/// Box corners are rounded sums of coordinates; the slack must dwarf their rounding error
/// (this many units in the last place of the largest coordinate) or the candidates are rebuilt.
constexpr double CANDIDATE_ROUNDING_ULPS = 64.0;
/// When the candidates no longer cover the displacements (impulses and impact zones moved a
/// vertex by more than the slack allows), the new slack is this many times that move: later
/// corrections are usually no larger, and each rebuild is a broad phase over the whole mesh
/// (A4 at 50k triangles rebuilt 4–6 times per step with the fixed slack).
constexpr double CANDIDATE_SLACK_GROWTH = 4.0;
/// ... but at most this fraction of the largest displacement coordinate (a shortened step or a
/// rigid zone moves vertices by a large share of their motion) and of the mean edge length:
/// boxes padded by more would pair far too many elements.
constexpr double CANDIDATE_SLACK_CAP = 0.25;
constexpr double CANDIDATE_SLACK_EDGE_CAP = 0.05;

}  // namespace

void pair_positions(const SurfaceMesh& mesh, const std::vector<Vec3>& x0,
                    const std::vector<Vec3>& x1, const std::array<int, 4>& v,
                    std::array<Vec3, 4>& p0, std::array<Vec3, 4>& p1) {
    if (!mesh.periodic()) {
        for (std::size_t k = 0; k < 4; ++k) {
            p0[k] = x0[static_cast<std::size_t>(v[k])];
            p1[k] = x1[static_cast<std::size_t>(v[k])];
        }
        return;
    }
    const MeshPeriods& periods = mesh.periods();
    const Vec3& ref = x0[static_cast<std::size_t>(v[0])];
    for (std::size_t k = 0; k < 4; ++k) {
        const auto i = static_cast<std::size_t>(v[k]);
        const Vec3 s = k == 0 ? Vec3::Zero() : periods.shift_towards(x0[i], ref);
        p0[k] = x0[i] + s;
        p1[k] = x1[i] + s;
    }
}

CollisionCandidates::CollisionCandidates(const SurfaceMesh& mesh, const std::vector<Vec3>& x0,
                                         double proximity_epsilon)
    : m_mesh(mesh), m_x0(x0), m_epsilon(proximity_epsilon) {
    if (!(proximity_epsilon > 0.0))
        throw std::invalid_argument("CollisionCandidates: proximity_epsilon must be > 0");
}

void CollisionCandidates::build(const std::vector<Vec3>& d, double padding) {
    build_padded(d, padding + CANDIDATE_SLACK_FRACTION * m_epsilon);
}

bool CollisionCandidates::cover(const std::vector<Vec3>& d) {
    double moved = 0.0;  // how far the displacements left the candidates' reference
    if (covers(d, &moved))
        return false;
    double largest = 0.0;  // largest displacement coordinate: bounds the useful slack
    for (const Vec3& di : d)
        largest = std::max(largest, di.cwiseAbs().maxCoeff());
    const double slack = CANDIDATE_SLACK_FRACTION * m_epsilon;
    const double grown = std::min({CANDIDATE_SLACK_GROWTH * moved, CANDIDATE_SLACK_CAP * largest,
                                   CANDIDATE_SLACK_EDGE_CAP * mean_edge_length()});
    build_padded(d, std::isfinite(grown) ? std::max(slack, grown) : slack);
    return true;
}

void CollisionCandidates::build_padded(const std::vector<Vec3>& d, double padding) {
    std::vector<Vec3> x1(m_x0.size());
    for (std::size_t i = 0; i < x1.size(); ++i)
        x1[i] = m_x0[i] + d[i];
    const BroadPhase broad(m_mesh, m_x0, x1, padding);
    m_vertex_triangle = broad.vertex_triangle_pairs();
    m_edge_edge = broad.edge_edge_pairs();
    m_d_ref = d;
    m_padding = padding;
}

bool CollisionCandidates::covers(const std::vector<Vec3>& d, double* moved_out) const {
    if (moved_out)
        *moved_out = 0.0;
    if (m_d_ref.size() != d.size() || !(m_padding > 0.0))
        return false;
    double moved = 0.0, coordinate = 0.0;
    for (std::size_t i = 0; i < d.size(); ++i) {
        moved = std::max(moved, (d[i] - m_d_ref[i]).cwiseAbs().maxCoeff());
        coordinate = std::max({coordinate, m_x0[i].cwiseAbs().maxCoeff(),
                               (m_x0[i] + d[i]).cwiseAbs().maxCoeff(),
                               (m_x0[i] + m_d_ref[i]).cwiseAbs().maxCoeff()});
    }
    if (moved_out)
        *moved_out = moved;
    const double rounding =
        CANDIDATE_ROUNDING_ULPS * std::numeric_limits<double>::epsilon() * coordinate;
    return std::isfinite(moved) && std::isfinite(coordinate) &&
           CANDIDATE_SLACK_SAFETY * m_padding > rounding &&
           moved <= CANDIDATE_SLACK_SAFETY * m_padding - rounding;
}

std::array<int, 4> CollisionCandidates::vertices(std::size_t i, std::size_t* split) const {
    if (i < m_vertex_triangle.size()) {
        const VertexTrianglePair& p = m_vertex_triangle[i];
        const Triangle& t = m_mesh.triangle(p.ti);
        if (split)
            *split = 1;
        return {p.vi, t[0], t[1], t[2]};
    }
    const EdgeEdgePair& p = m_edge_edge[i - m_vertex_triangle.size()];
    const Edge& a = m_mesh.edge(p.ei);
    const Edge& b = m_mesh.edge(p.ej);
    if (split)
        *split = 2;
    return {a[0], a[1], b[0], b[1]};
}

bool CollisionCandidates::static_boxes_overlap(const std::array<int, 4>& v, std::size_t split,
                                               double padding, std::array<Vec3, 4>& p0) const {
    if (!m_mesh.periodic()) {
        for (std::size_t k = 0; k < 4; ++k)
            p0[k] = x0(v[k]);
        return split == 1 ? boxes_overlap(static_box({v[0]}, padding),
                                          static_box({v[1], v[2], v[3]}, padding))
                          : boxes_overlap(static_box({v[0], v[1]}, padding),
                                          static_box({v[2], v[3]}, padding));
    }
    const MeshPeriods& periods = m_mesh.periods();
    const Vec3& ref = x0(v[0]);
    p0[0] = ref;
    for (std::size_t k = 1; k < 4; ++k)
        p0[k] = periods.nearest_image(x0(v[k]), ref);
    Box3d a, b;
    for (std::size_t k = 0; k < 4; ++k)
        (k < split ? a : b).extend(p0[k]);
    a.min().array() -= padding;
    a.max().array() += padding;
    b.min().array() -= padding;
    b.max().array() += padding;
    return boxes_overlap(a, b);
}

std::vector<VertexTrianglePair> CollisionCandidates::moving_vertex_triangle(
    const std::vector<Vec3>& x1, const std::vector<std::uint8_t>& changed) const {
    return ordered_parallel_collect<VertexTrianglePair>(
        m_vertex_triangle.size(), [&](std::size_t i, std::vector<VertexTrianglePair>& out) {
            const VertexTrianglePair& p = m_vertex_triangle[i];
            const Triangle& t = m_mesh.triangle(p.ti);
            if (!any_changed(changed, {p.vi, t[0], t[1], t[2]}))
                return;
            if (m_mesh.periodic() ? swept_boxes_overlap({p.vi, t[0], t[1], t[2]}, 1, x1)
                                  : boxes_overlap(moving_box({p.vi}, x1),
                                                  moving_box({t[0], t[1], t[2]}, x1)))
                out.push_back(p);
        });
}

std::vector<EdgeEdgePair> CollisionCandidates::moving_edge_edge(
    const std::vector<Vec3>& x1, const std::vector<std::uint8_t>& changed) const {
    return ordered_parallel_collect<EdgeEdgePair>(
        m_edge_edge.size(), [&](std::size_t i, std::vector<EdgeEdgePair>& out) {
            const EdgeEdgePair& p = m_edge_edge[i];
            const Edge& a = m_mesh.edge(p.ei);
            const Edge& b = m_mesh.edge(p.ej);
            if (!any_changed(changed, {a[0], a[1], b[0], b[1]}))
                return;
            if (m_mesh.periodic() ? swept_boxes_overlap({a[0], a[1], b[0], b[1]}, 2, x1)
                                  : boxes_overlap(moving_box({a[0], a[1]}, x1),
                                                  moving_box({b[0], b[1]}, x1)))
                out.push_back(p);
        });
}

double CollisionCandidates::mean_edge_length() {
    if (m_mean_edge_length < 0.0) {
        double sum = 0.0;
        int count = 0;
        for (int ei = 0; ei < m_mesh.num_edges(); ++ei)
            if (m_mesh.edge_alive(ei)) {
                const Edge& e = m_mesh.edge(ei);
                sum += m_mesh.periodic() ? m_mesh.periods().difference(x0(e[1]), x0(e[0])).norm()
                                         : (x0(e[1]) - x0(e[0])).norm();
                ++count;
            }
        m_mean_edge_length = count > 0 ? sum / count : 0.0;
    }
    return m_mean_edge_length;
}

Box3d CollisionCandidates::static_box(std::initializer_list<int> vertices, double padding) const {
    Box3d b;
    for (int vi : vertices)
        b.extend(x0(vi));
    b.min().array() -= padding;
    b.max().array() += padding;
    return b;
}

Box3d CollisionCandidates::moving_box(std::initializer_list<int> vertices,
                                      const std::vector<Vec3>& x1) const {
    Box3d b;
    for (int vi : vertices) {
        b.extend(x0(vi));
        b.extend(x1[static_cast<std::size_t>(vi)]);
    }
    return b;
}

bool CollisionCandidates::swept_boxes_overlap(const std::array<int, 4>& v, std::size_t split,
                                              const std::vector<Vec3>& x1) const {
    std::array<Vec3, 4> p0, p1;
    pair_positions(m_mesh, m_x0, x1, v, p0, p1);
    Box3d a, b;
    for (std::size_t k = 0; k < 4; ++k) {
        Box3d& box = k < split ? a : b;
        box.extend(p0[k]);
        box.extend(p1[k]);
    }
    return boxes_overlap(a, b);
}

}  // namespace meniscus::tracker
