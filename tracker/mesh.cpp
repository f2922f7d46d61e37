#include "tracker/mesh.h"

#include "common/assert.h"

#include <algorithm>
#include <cstdlib>
#include <limits>
#include <stdexcept>
#include <string>
#include <utility>

namespace meniscus::tracker {

namespace {

void erase_value(std::vector<int>& list, int value) {
    auto it = std::find(list.begin(), list.end(), value);
    MENISCUS_ASSERT(it != list.end(), "adjacency list is missing an entry");
    *it = list.back();
    list.pop_back();
}

bool contains(const Triangle& t, int vi) {
    return t[0] == vi || t[1] == vi || t[2] == vi;
}

constexpr Triangle DEAD_TRIANGLE = {INVALID_INDEX, INVALID_INDEX, INVALID_INDEX};
constexpr Edge DEAD_EDGE = {INVALID_INDEX, INVALID_INDEX};

/// A renumbering of one kind of element: `map` is old → new (INVALID_INDEX for dead slots),
/// `moved` the old indices of the elements that get a new index, in increasing new index, and
/// `count` the live count.
struct Renumbering {
    std::vector<int> map;
    std::vector<int> moved;
    int count = 0;
};

/// compact()'s renumbering: live elements below the live count keep their index, and those
/// above it fill the dead slots below it, lowest first.
template <typename IsAlive>
Renumbering fill_dead_slots(size_t slots, IsAlive alive) {
    Renumbering r;
    r.map.assign(slots, INVALID_INDEX);
    for (size_t i = 0; i < slots; ++i)
        if (alive(i)) {
            r.map[i] = static_cast<int>(i);
            ++r.count;
        }
    size_t hole = 0;
    for (size_t i = static_cast<size_t>(r.count); i < slots; ++i) {
        if (r.map[i] == INVALID_INDEX)
            continue;
        while (r.map[hole] != INVALID_INDEX)
            ++hole;
        r.map[i] = static_cast<int>(hole++);
        r.moved.push_back(static_cast<int>(i));
    }
    return r;
}

/// Marks `index` in `seen` and appends it to `list` the first time.
void collect_once(int index, std::vector<std::uint8_t>& seen, std::vector<int>& list) {
    if (!seen[static_cast<size_t>(index)]) {
        seen[static_cast<size_t>(index)] = 1;
        list.push_back(index);
    }
}

/// Bits 0..20 of x, y and z interleaved (x lowest): the position along the Z-order curve.
std::uint64_t morton_code(std::uint64_t x, std::uint64_t y, std::uint64_t z) {
    const auto spread = [](std::uint64_t b) {  // bit i to bit 3i
        b &= 0x1fffff;
        b = (b | b << 32) & 0x1f00000000ffffULL;
        b = (b | b << 16) & 0x1f0000ff0000ffULL;
        b = (b | b << 8) & 0x100f00f00f00f00fULL;
        b = (b | b << 4) & 0x10c30c30c30c30c3ULL;
        b = (b | b << 2) & 0x1249249249249249ULL;
        return b;
    };
    return spread(x) | spread(y) << 1 | spread(z) << 2;
}

/// The renumbering that sorts elements by (key, old index); `moved` lists every element.
Renumbering renumbering_by(std::vector<std::pair<std::uint64_t, int>>& keys) {
    std::sort(keys.begin(), keys.end());
    Renumbering r;
    r.count = static_cast<int>(keys.size());
    r.map.resize(keys.size());
    r.moved.resize(keys.size());
    for (size_t n = 0; n < keys.size(); ++n) {
        r.map[static_cast<size_t>(keys[n].second)] = static_cast<int>(n);
        r.moved[n] = keys[n].second;
    }
    return r;
}

void remap_list(std::vector<int>& list, const std::vector<int>& map) {
    for (int& i : list)
        i = map[static_cast<size_t>(i)];
}

}  // namespace

SurfaceMesh::SurfaceMesh(std::vector<Vec3> positions, const std::vector<Triangle>& triangles,
                         const std::vector<LabelPair>& labels) {
    if (!labels.empty() && labels.size() != triangles.size())
        throw std::invalid_argument("SurfaceMesh: " + std::to_string(labels.size()) +
                                    " label pairs for " + std::to_string(triangles.size()) +
                                    " triangles");
    m_positions = std::move(positions);
    m_vertex_alive.assign(m_positions.size(), 1);
    m_vertex_marked.assign(m_positions.size(), 1);
    m_vertex_triangles.resize(m_positions.size());
    m_vertex_edges.resize(m_positions.size());
    m_triangles.reserve(triangles.size());
    m_edges.reserve(triangles.size() * 3 / 2 + 1);
    for (size_t i = 0; i < triangles.size(); ++i)
        add_triangle(triangles[i], labels.empty() ? LabelPair{} : labels[i]);
}

SurfaceMesh::SurfaceMesh(const SurfaceMesh& other)
    : m_positions(other.m_positions),
      m_vertex_alive(other.m_vertex_alive),
      m_vertex_marked(other.m_vertex_marked),
      m_triangle_marked(other.m_triangle_marked),
      m_triangles(other.m_triangles),
      m_labels(other.m_labels),
      m_triangle_edges(other.m_triangle_edges),
      m_edges(other.m_edges),
      m_edge_triangles(other.m_edge_triangles),
      m_vertex_triangles(other.m_vertex_triangles),
      m_vertex_edges(other.m_vertex_edges),
      m_periods(other.m_periods),
      m_periodic(other.m_periodic) {}

SurfaceMesh& SurfaceMesh::operator=(const SurfaceMesh& other) {
    if (this != &other) {
        SurfaceMesh copy(other);
        copy.m_observers = m_observers;  // observers stay with the object they registered on
        *this = std::move(copy);
    }
    return *this;
}

int SurfaceMesh::count_live_vertices() const {
    return static_cast<int>(std::count(m_vertex_alive.begin(), m_vertex_alive.end(), 1));
}

int SurfaceMesh::count_live_triangles() const {
    int n = 0;
    for (const Triangle& t : m_triangles)
        n += t[0] >= 0 ? 1 : 0;
    return n;
}

int SurfaceMesh::count_live_edges() const {
    int n = 0;
    for (const Edge& e : m_edges)
        n += e[0] >= 0 ? 1 : 0;
    return n;
}

bool SurfaceMesh::has_dead_elements() const {
    return count_live_vertices() != num_vertices() || count_live_triangles() != num_triangles() ||
           count_live_edges() != num_edges();
}

void SurfaceMesh::set_positions(const std::vector<Vec3>& p) {
    if (p.size() != m_positions.size())
        throw std::invalid_argument("SurfaceMesh::set_positions: got " + std::to_string(p.size()) +
                                    " positions for " + std::to_string(m_positions.size()) +
                                    " vertices");
    m_positions = p;
}

void SurfaceMesh::set_periods(const MeshPeriods& periods) {
    periods.validate();
    m_periods = periods;
    m_periodic = periods.any();
    wrap_positions();
}

void SurfaceMesh::wrap_positions() {
    if (!m_periodic)
        return;
    for (size_t i = 0; i < m_positions.size(); ++i)
        if (m_vertex_alive[i])
            m_positions[i] = m_periods.wrap(m_positions[i]);
}

std::array<Vec3, 3> SurfaceMesh::triangle_positions(int ti) const {
    const Triangle& t = triangle(ti);
    const Vec3& a = position(t[0]);
    return {a, position_near(t[1], a), position_near(t[2], a)};
}

std::array<Vec3, 2> SurfaceMesh::edge_positions(int ei) const {
    const Edge& e = edge(ei);
    const Vec3& a = position(e[0]);
    return {a, position_near(e[1], a)};
}

int SurfaceMesh::find_edge(int v0, int v1) const {
    const auto& a = vertex_edges(v0);
    const auto& b = vertex_edges(v1);
    const auto& shorter = a.size() <= b.size() ? a : b;
    const int lo = std::min(v0, v1), hi = std::max(v0, v1);
    for (int ei : shorter) {
        const Edge& e = m_edges[static_cast<size_t>(ei)];
        if (e[0] == lo && e[1] == hi)
            return ei;
    }
    return INVALID_INDEX;
}

int SurfaceMesh::find_triangle(int v0, int v1, int v2) const {
    for (int ti : vertex_triangles(v0)) {
        const Triangle& t = triangle(ti);
        if (contains(t, v1) && contains(t, v2))
            return ti;
    }
    return INVALID_INDEX;
}

int SurfaceMesh::opposite_vertex(int ti, int ei) const {
    const Triangle& t = triangle(ti);
    const Edge& e = edge(ei);
    for (int vi : t)
        if (vi != e[0] && vi != e[1])
            return vi;
    MENISCUS_ASSERT(false, "edge is not an edge of the triangle");
    return INVALID_INDEX;
}

int SurfaceMesh::edge_orientation_in_triangle(int ti, int ei) const {
    const Triangle& t = triangle(ti);
    const Edge& e = edge(ei);
    for (int k = 0; k < 3; ++k) {
        if (t[k] == e[0] && t[(k + 1) % 3] == e[1])
            return +1;
        if (t[k] == e[1] && t[(k + 1) % 3] == e[0])
            return -1;
    }
    MENISCUS_ASSERT(false, "edge is not an edge of the triangle");
    return 0;
}

bool SurfaceMesh::is_boundary_vertex(int vi) const {
    for (int ei : vertex_edges(vi))
        if (is_boundary_edge(ei))
            return true;
    return false;
}

int SurfaceMesh::other_vertex(int ei, int vi) const {
    const Edge& e = edge(ei);
    MENISCUS_ASSERT(e[0] == vi || e[1] == vi, "vertex is not on the edge");
    return e[0] == vi ? e[1] : e[0];
}

int SurfaceMesh::append_vertex_slot(const Vec3& p) {
    m_positions.push_back(p);
    m_vertex_alive.push_back(1);
    m_vertex_marked.push_back(1);
    m_vertex_triangles.emplace_back();
    m_vertex_edges.emplace_back();
    return num_vertices() - 1;
}

int SurfaceMesh::add_vertex(const Vec3& p) {
    const int vi = append_vertex_slot(p);
    for (MeshObserver* o : m_observers)
        o->on_vertex_added(vi);
    return vi;
}

int SurfaceMesh::add_edge(int v0, int v1) {
    const int ei = num_edges();
    m_edges.push_back({std::min(v0, v1), std::max(v0, v1)});
    m_edge_triangles.emplace_back();
    m_vertex_edges[static_cast<size_t>(v0)].push_back(ei);
    m_vertex_edges[static_cast<size_t>(v1)].push_back(ei);
    return ei;
}

void SurfaceMesh::remove_edge(int ei) {
    const Edge e = edge(ei);
    MENISCUS_ASSERT(m_edge_triangles[static_cast<size_t>(ei)].empty(),
                    "removing an edge that still has triangles");
    erase_value(m_vertex_edges[static_cast<size_t>(e[0])], ei);
    erase_value(m_vertex_edges[static_cast<size_t>(e[1])], ei);
    m_edges[static_cast<size_t>(ei)] = DEAD_EDGE;
}

void SurfaceMesh::attach_triangle(int ti) {
    const Triangle& t = triangle(ti);
    auto& tri_edges = m_triangle_edges[static_cast<size_t>(ti)];
    for (int k = 0; k < 3; ++k) {
        const int a = t[k], b = t[(k + 1) % 3];
        int ei = find_edge(a, b);
        if (ei == INVALID_INDEX)
            ei = add_edge(a, b);
        tri_edges[k] = ei;
        m_edge_triangles[static_cast<size_t>(ei)].push_back(ti);
        m_vertex_triangles[static_cast<size_t>(t[k])].push_back(ti);
        m_vertex_marked[static_cast<size_t>(t[k])] = 1;
    }
}

void SurfaceMesh::detach_triangle(int ti) {
    const Triangle& t = triangle(ti);
    const auto tri_edges = m_triangle_edges[static_cast<size_t>(ti)];
    for (int k = 0; k < 3; ++k) {
        erase_value(m_vertex_triangles[static_cast<size_t>(t[k])], ti);
        m_vertex_marked[static_cast<size_t>(t[k])] = 1;
        auto& et = m_edge_triangles[static_cast<size_t>(tri_edges[k])];
        erase_value(et, ti);
        if (et.empty())
            remove_edge(tri_edges[k]);
    }
}

int SurfaceMesh::add_triangle(const Triangle& t, const LabelPair& labels) {
    for (int vi : t) {
        if (vi < 0 || vi >= num_vertices() || !vertex_alive(vi))
            throw std::invalid_argument("SurfaceMesh::add_triangle: vertex " + std::to_string(vi) +
                                        " does not exist");
    }
    if (t[0] == t[1] || t[1] == t[2] || t[0] == t[2])
        throw std::invalid_argument("SurfaceMesh::add_triangle: triangle (" + std::to_string(t[0]) +
                                    ", " + std::to_string(t[1]) + ", " + std::to_string(t[2]) +
                                    ") repeats a vertex");
    const int ti = num_triangles();
    m_triangles.push_back(t);
    m_labels.push_back(labels);
    m_triangle_edges.push_back({INVALID_INDEX, INVALID_INDEX, INVALID_INDEX});
    m_triangle_marked.push_back(1);
    attach_triangle(ti);
    return ti;
}

void SurfaceMesh::remove_triangle(int ti) {
    MENISCUS_ASSERT(triangle_alive(ti), "removing a dead triangle");
    detach_triangle(ti);
    m_triangles[static_cast<size_t>(ti)] = DEAD_TRIANGLE;
    m_triangle_edges[static_cast<size_t>(ti)] = {INVALID_INDEX, INVALID_INDEX, INVALID_INDEX};
}

void SurfaceMesh::remove_vertex(int vi) {
    if (!vertex_triangles(vi).empty())
        throw std::invalid_argument("SurfaceMesh::remove_vertex: vertex " + std::to_string(vi) +
                                    " still has triangles");
    MENISCUS_ASSERT(vertex_edges(vi).empty(), "a vertex without triangles still has edges");
    m_vertex_alive[static_cast<size_t>(vi)] = 0;
}

int SurfaceMesh::split_edge(int ei, const Vec3& position, double s) {
    MENISCUS_ASSERT(edge_alive(ei), "splitting a dead edge");
    const Edge e = edge(ei);
    const std::vector<int> incident = edge_triangles(ei);
    const int m = append_vertex_slot(position);
    for (int ti : incident) {
        const Triangle t = triangle(ti);
        const LabelPair l = labels(ti);
        // Rotate so that t = (a, b, c) with (a, b) the split edge in the triangle's direction.
        int k = 0;
        while (
            !((t[k] == e[0] || t[k] == e[1]) && (t[(k + 1) % 3] == e[0] || t[(k + 1) % 3] == e[1])))
            ++k;
        const int a = t[k], b = t[(k + 1) % 3], c = t[(k + 2) % 3];
        remove_triangle(ti);
        add_triangle({a, m, c}, l);
        add_triangle({m, b, c}, l);
    }
    for (MeshObserver* o : m_observers)
        o->on_edge_split(e[0], e[1], m, s);
    return m;
}

int SurfaceMesh::flip_edge(int ei, int t0, int t1) {
    MENISCUS_ASSERT(edge_alive(ei), "flipping a dead edge");
    const auto& et = edge_triangles(ei);
    const bool on_edge = std::find(et.begin(), et.end(), t0) != et.end() &&
                         std::find(et.begin(), et.end(), t1) != et.end() && t0 != t1;
    if (!on_edge || edge_orientation_in_triangle(t0, ei) == edge_orientation_in_triangle(t1, ei))
        throw std::invalid_argument(
            "SurfaceMesh::flip_edge: triangles are not an oppositely oriented pair on the edge");
    // t0 = (a, b, c) traversing a→b; t1 = (b, a, d). New: (c, a, d) and (d, b, c).
    const Triangle tri0 = triangle(t0);
    int k = 0;
    const Edge e = edge(ei);
    while (!((tri0[k] == e[0] || tri0[k] == e[1]) &&
             (tri0[(k + 1) % 3] == e[0] || tri0[(k + 1) % 3] == e[1])))
        ++k;
    const int a = tri0[k], b = tri0[(k + 1) % 3], c = tri0[(k + 2) % 3];
    const int d = opposite_vertex(t1, ei);
    const LabelPair l0 = labels(t0), l1 = labels(t1);
    remove_triangle(t0);
    remove_triangle(t1);
    add_triangle({c, a, d}, l0);
    add_triangle({d, b, c}, l1);
    return find_edge(c, d);
}

void SurfaceMesh::collapse_edge(int ei, int kept_vi, const Vec3& position, double s) {
    MENISCUS_ASSERT(edge_alive(ei), "collapsing a dead edge");
    const int removed_vi = other_vertex(ei, kept_vi);
    const std::vector<int> on_edge = edge_triangles(ei);
    for (int ti : on_edge)
        remove_triangle(ti);
    const std::vector<int> rewired = vertex_triangles(removed_vi);
    for (int ti : rewired) {
        Triangle t = triangle(ti);
        const LabelPair l = labels(ti);
        for (int& vi : t)
            if (vi == removed_vi)
                vi = kept_vi;
        remove_triangle(ti);
        add_triangle(t, l);
    }
    m_positions[static_cast<size_t>(kept_vi)] = position;
    remove_vertex(removed_vi);
    for (MeshObserver* o : m_observers)
        o->on_edge_collapse(kept_vi, removed_vi, s);
}

int SurfaceMesh::duplicate_vertex(int vi, const std::vector<int>& triangles,
                                  const Vec3& copy_position) {
    const int copy = append_vertex_slot(copy_position);
    for (int ti : triangles) {
        Triangle t = triangle(ti);
        if (!contains(t, vi))
            throw std::invalid_argument("SurfaceMesh::duplicate_vertex: triangle " +
                                        std::to_string(ti) + " does not contain vertex " +
                                        std::to_string(vi));
        const LabelPair l = labels(ti);
        for (int& v : t)
            if (v == vi)
                v = copy;
        remove_triangle(ti);
        add_triangle(t, l);
    }
    for (MeshObserver* o : m_observers)
        o->on_vertex_duplicated(vi, copy);
    return copy;
}

void SurfaceMesh::clear_triangle_marks() {
    std::fill(m_triangle_marked.begin(), m_triangle_marked.end(), 0);
}

std::vector<int> SurfaceMesh::compact() {
    // Each kind of element keeps its indices below its live count; the live elements above it
    // move into the dead slots below it (fill_dead_slots). Only the records that reference a
    // moved element are rewritten, and no list is reordered, so the cost follows the number of
    // dead slots rather than the size of the mesh.
    const Renumbering vr =
        fill_dead_slots(m_positions.size(), [&](size_t i) { return m_vertex_alive[i] != 0; });
    const Renumbering tr =
        fill_dead_slots(m_triangles.size(), [&](size_t i) { return m_triangles[i][0] >= 0; });
    const Renumbering er =
        fill_dead_slots(m_edges.size(), [&](size_t i) { return m_edges[i][0] >= 0; });

    // The records that hold a reference to a moved element (old indices, each once), found
    // through the moved element's own adjacency while every index is still the old one.
    std::vector<std::uint8_t> seen_v(m_positions.size(), 0), seen_t(m_triangles.size(), 0),
        seen_e(m_edges.size(), 0);
    std::vector<int> holders_v, holders_t, holders_e;
    for (int vi : vr.moved) {
        for (int ti : m_vertex_triangles[static_cast<size_t>(vi)])
            collect_once(ti, seen_t, holders_t);
        for (int ei : m_vertex_edges[static_cast<size_t>(vi)])
            collect_once(ei, seen_e, holders_e);
    }
    for (int ti : tr.moved) {
        for (int vi : m_triangles[static_cast<size_t>(ti)])
            collect_once(vi, seen_v, holders_v);
        for (int ei : m_triangle_edges[static_cast<size_t>(ti)])
            collect_once(ei, seen_e, holders_e);
    }
    for (int ei : er.moved) {
        for (int vi : m_edges[static_cast<size_t>(ei)])
            collect_once(vi, seen_v, holders_v);
        for (int ti : m_edge_triangles[static_cast<size_t>(ei)])
            collect_once(ti, seen_t, holders_t);
    }

    // Their references renumbered in place (each holder once, so each index is mapped once).
    for (int ti : holders_t) {
        for (int& vi : m_triangles[static_cast<size_t>(ti)])
            vi = vr.map[static_cast<size_t>(vi)];
        for (int& ei : m_triangle_edges[static_cast<size_t>(ti)])
            ei = er.map[static_cast<size_t>(ei)];
    }
    for (int ei : holders_e) {
        Edge& e = m_edges[static_cast<size_t>(ei)];
        e = {vr.map[static_cast<size_t>(e[0])], vr.map[static_cast<size_t>(e[1])]};
        if (e[0] > e[1])
            std::swap(e[0], e[1]);  // smaller index first
        remap_list(m_edge_triangles[static_cast<size_t>(ei)], tr.map);
    }
    for (int vi : holders_v) {
        remap_list(m_vertex_triangles[static_cast<size_t>(vi)], tr.map);
        remap_list(m_vertex_edges[static_cast<size_t>(vi)], er.map);
    }

    // The moved records into their new slots, then the tails cut off.
    for (int from : vr.moved) {
        const size_t f = static_cast<size_t>(from), to = static_cast<size_t>(vr.map[f]);
        m_positions[to] = m_positions[f];
        m_vertex_alive[to] = 1;
        m_vertex_marked[to] = m_vertex_marked[f];
        m_vertex_triangles[to] = std::move(m_vertex_triangles[f]);
        m_vertex_edges[to] = std::move(m_vertex_edges[f]);
    }
    const size_t nv = static_cast<size_t>(vr.count);
    m_positions.resize(nv);
    m_vertex_alive.resize(nv);
    m_vertex_marked.resize(nv);
    m_vertex_triangles.resize(nv);
    m_vertex_edges.resize(nv);

    for (int from : tr.moved) {
        const size_t f = static_cast<size_t>(from), to = static_cast<size_t>(tr.map[f]);
        m_triangles[to] = m_triangles[f];
        m_triangle_edges[to] = m_triangle_edges[f];
        m_labels[to] = m_labels[f];
        m_triangle_marked[to] = m_triangle_marked[f];
    }
    const size_t nt = static_cast<size_t>(tr.count);
    m_triangles.resize(nt);
    m_triangle_edges.resize(nt);
    m_labels.resize(nt);
    m_triangle_marked.resize(nt);

    for (int from : er.moved) {
        const size_t f = static_cast<size_t>(from), to = static_cast<size_t>(er.map[f]);
        m_edges[to] = m_edges[f];
        m_edge_triangles[to] = std::move(m_edge_triangles[f]);
    }
    const size_t ne = static_cast<size_t>(er.count);
    m_edges.resize(ne);
    m_edge_triangles.resize(ne);

    for (MeshObserver* o : m_observers)
        o->on_compact(vr.map);
    return vr.map;
}

double SurfaceMesh::far_edge_fraction() const {
    const int window = std::max(64, count_live_vertices() / 32);
    size_t live = 0, far = 0;
    for (const Edge& e : m_edges)
        if (e[0] >= 0) {
            ++live;
            far += std::abs(e[1] - e[0]) > window ? 1 : 0;
        }
    return live == 0 ? 0.0 : static_cast<double>(far) / static_cast<double>(live);
}

std::vector<int> SurfaceMesh::sort_spatially() {
    if (has_dead_elements())
        throw std::logic_error(
            "SurfaceMesh::sort_spatially: the mesh has dead slots (compact() first)");
    const size_t nv = m_positions.size(), nt = m_triangles.size(), ne = m_edges.size();
    const auto at = [](const std::vector<int>& map, int i) { return map[static_cast<size_t>(i)]; };

    // Vertices by the Morton code of their position quantized to 21 bits per axis.
    Eigen::AlignedBox3d box;
    for (const Vec3& p : m_positions)
        box.extend(p);
    const Vec3 scale = box.sizes().cwiseMax(1e-300).cwiseInverse() * 2097151.0;
    std::vector<std::pair<std::uint64_t, int>> keys(nv);
    for (size_t i = 0; i < nv; ++i) {
        const Vec3 q = (m_positions[i] - box.min()).cwiseProduct(scale);
        keys[i] = {morton_code(static_cast<std::uint64_t>(q.x()), static_cast<std::uint64_t>(q.y()),
                               static_cast<std::uint64_t>(q.z())),
                   static_cast<int>(i)};
    }
    Renumbering vr = renumbering_by(keys);
    // Triangles by their smallest new vertex, edges by their new vertex pair (ties: old order).
    keys.resize(nt);
    for (size_t t = 0; t < nt; ++t) {
        const Triangle& tri = m_triangles[t];
        const int lo = std::min({at(vr.map, tri[0]), at(vr.map, tri[1]), at(vr.map, tri[2])});
        keys[t] = {static_cast<std::uint64_t>(lo) << 32 | t, static_cast<int>(t)};
    }
    const Renumbering tr = renumbering_by(keys);
    keys.resize(ne);
    for (size_t e = 0; e < ne; ++e) {
        const int a = at(vr.map, m_edges[e][0]), b = at(vr.map, m_edges[e][1]);
        keys[e] = {static_cast<std::uint64_t>(std::min(a, b)) << 32 |
                       static_cast<std::uint32_t>(std::max(a, b)),
                   static_cast<int>(e)};
    }
    const Renumbering er = renumbering_by(keys);

    // Every record gathered into its new slot with its references renumbered (`moved` holds
    // the old index of each new slot).
    std::vector<Vec3> positions(nv);
    std::vector<std::uint8_t> vertex_marked(nv);
    std::vector<std::vector<int>> vertex_triangles(nv), vertex_edges(nv);
    for (size_t n = 0; n < nv; ++n) {
        const size_t old = static_cast<size_t>(vr.moved[n]);
        positions[n] = m_positions[old];
        vertex_marked[n] = m_vertex_marked[old];
        vertex_triangles[n] = std::move(m_vertex_triangles[old]);
        vertex_edges[n] = std::move(m_vertex_edges[old]);
        remap_list(vertex_triangles[n], tr.map);
        remap_list(vertex_edges[n], er.map);
    }
    m_positions = std::move(positions);
    m_vertex_marked = std::move(vertex_marked);
    m_vertex_triangles = std::move(vertex_triangles);
    m_vertex_edges = std::move(vertex_edges);

    std::vector<Triangle> triangles(nt);
    std::vector<std::array<int, 3>> triangle_edges(nt);
    std::vector<LabelPair> labels(nt);
    std::vector<std::uint8_t> triangle_marked(nt);
    for (size_t n = 0; n < nt; ++n) {
        const size_t old = static_cast<size_t>(tr.moved[n]);
        for (size_t k = 0; k < 3; ++k) {
            triangles[n][k] = at(vr.map, m_triangles[old][k]);
            triangle_edges[n][k] = at(er.map, m_triangle_edges[old][k]);
        }
        labels[n] = m_labels[old];
        triangle_marked[n] = m_triangle_marked[old];
    }
    m_triangles = std::move(triangles);
    m_triangle_edges = std::move(triangle_edges);
    m_labels = std::move(labels);
    m_triangle_marked = std::move(triangle_marked);

    std::vector<Edge> edges(ne);
    std::vector<std::vector<int>> edge_triangles(ne);
    for (size_t n = 0; n < ne; ++n) {
        const size_t old = static_cast<size_t>(er.moved[n]);
        const int a = at(vr.map, m_edges[old][0]), b = at(vr.map, m_edges[old][1]);
        edges[n] = {std::min(a, b), std::max(a, b)};
        edge_triangles[n] = std::move(m_edge_triangles[old]);
        remap_list(edge_triangles[n], tr.map);
    }
    m_edges = std::move(edges);
    m_edge_triangles = std::move(edge_triangles);

    for (MeshObserver* o : m_observers)
        o->on_compact(vr.map);
    return std::move(vr.map);
}

void SurfaceMesh::add_observer(MeshObserver* observer) {
    if (observer == nullptr)
        throw std::invalid_argument("SurfaceMesh::add_observer: null");
    if (std::find(m_observers.begin(), m_observers.end(), observer) == m_observers.end())
        m_observers.push_back(observer);
}

void SurfaceMesh::remove_observer(MeshObserver* observer) {
    m_observers.erase(std::remove(m_observers.begin(), m_observers.end(), observer),
                      m_observers.end());
}

// ---- exact state ----------------------------------------------------------------------------

namespace {

/// Throws FormatError unless every index of `lists` is in [0, limit).
void check_index_lists(const std::vector<std::vector<int>>& lists, int limit, const char* what) {
    for (const std::vector<int>& list : lists)
        for (int i : list)
            if (i < 0 || i >= limit)
                throw FormatError(std::string("mesh state: ") + what + " names element " +
                                  std::to_string(i) + " of " + std::to_string(limit));
}

/// Throws FormatError unless each entry is all −1 (dead) or all in [0, limit).
template <size_t N>
void check_index_tuples(const std::vector<std::array<int, N>>& tuples, int limit,
                        const char* what) {
    for (const std::array<int, N>& t : tuples) {
        const bool dead = t[0] < 0;
        for (int i : t)
            if (dead ? i != -1 : (i < 0 || i >= limit))
                throw FormatError(std::string("mesh state: ") + what + " names element " +
                                  std::to_string(i) + " of " + std::to_string(limit));
    }
}

}  // namespace

void SurfaceMesh::save_state(BinaryWriter& out) const {
    out.put_vector(m_positions);
    out.put_vector(m_vertex_alive);
    out.put_vector(m_triangles);
    out.put_vector(m_labels);
    out.put_vector(m_triangle_edges);
    out.put_vector(m_edges);
    out.put_nested(m_edge_triangles);
    out.put_nested(m_vertex_triangles);
    out.put_nested(m_vertex_edges);
}

void SurfaceMesh::load_state(BinaryReader& in) {
    SurfaceMesh m;
    m.m_positions = in.get_vector<Vec3>();
    m.m_vertex_alive = in.get_vector<std::uint8_t>();
    m.m_triangles = in.get_vector<Triangle>();
    m.m_labels = in.get_vector<LabelPair>();
    m.m_triangle_edges = in.get_vector<std::array<int, 3>>();
    m.m_edges = in.get_vector<Edge>();
    m.m_edge_triangles = in.get_nested<int>();
    m.m_vertex_triangles = in.get_nested<int>();
    m.m_vertex_edges = in.get_nested<int>();
    const size_t nv = m.m_positions.size(), nt = m.m_triangles.size(), ne = m.m_edges.size();
    if (m.m_vertex_alive.size() != nv || m.m_vertex_triangles.size() != nv ||
        m.m_vertex_edges.size() != nv || m.m_labels.size() != nt ||
        m.m_triangle_edges.size() != nt || m.m_edge_triangles.size() != ne ||
        nv > static_cast<size_t>(std::numeric_limits<int>::max()) ||
        nt > static_cast<size_t>(std::numeric_limits<int>::max()) ||
        ne > static_cast<size_t>(std::numeric_limits<int>::max()))
        throw FormatError("mesh state: array sizes disagree");
    for (std::uint8_t alive : m.m_vertex_alive)
        if (alive > 1)
            throw FormatError("mesh state: a vertex flag is neither 0 nor 1");
    for (const Vec3& p : m.m_positions)
        if (!p.allFinite())
            throw FormatError("mesh state: a vertex position is not finite");
    check_index_tuples(m.m_triangles, static_cast<int>(nv), "a triangle");
    for (size_t t = 0; t < nt; ++t)
        if (m.m_triangles[t][0] >= 0)
            for (int e : m.m_triangle_edges[t])
                if (e < 0 || e >= static_cast<int>(ne))
                    throw FormatError("mesh state: a triangle's edge names element " +
                                      std::to_string(e) + " of " + std::to_string(ne));
    check_index_tuples(m.m_edges, static_cast<int>(nv), "an edge");
    check_index_lists(m.m_edge_triangles, static_cast<int>(nt), "an edge's triangle list");
    check_index_lists(m.m_vertex_triangles, static_cast<int>(nt), "a vertex's triangle list");
    check_index_lists(m.m_vertex_edges, static_cast<int>(ne), "a vertex's edge list");
    // The marks are not saved: all set, separate() looks at everything once and finds what it
    // would have found from the saved marks (they only skip what it would have left alone).
    m.m_vertex_marked.assign(nv, 1);
    m.m_triangle_marked.assign(nt, 1);
    m.m_observers = std::move(m_observers);
    m.m_periods = m_periods;
    m.m_periodic = m_periodic;
    *this = std::move(m);
}

}  // namespace meniscus::tracker
