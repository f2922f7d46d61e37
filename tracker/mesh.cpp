#include "tracker/mesh.h"

#include "common/assert.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <limits>
#include <stdexcept>
#include <string>

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
      m_vertex_edges(other.m_vertex_edges) {}

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
    // The result is exactly the mesh SurfaceMesh(live positions, live triangles, labels) would
    // build — edges numbered in order of first appearance around the live triangles, every
    // adjacency list in increasing index order — but renumbered in place: no edge lookups, no
    // reallocation of the adjacency lists.
    std::vector<int> vertex_map(m_positions.size(), INVALID_INDEX);
    int nv = 0;
    for (size_t vi = 0; vi < m_positions.size(); ++vi)
        if (m_vertex_alive[vi])
            vertex_map[vi] = nv++;
    std::vector<int> triangle_map(m_triangles.size(), INVALID_INDEX);
    std::vector<int> edge_map(m_edges.size(), INVALID_INDEX);
    int nt = 0, ne = 0;
    for (size_t ti = 0; ti < m_triangles.size(); ++ti) {
        if (m_triangles[ti][0] < 0)
            continue;
        triangle_map[ti] = nt++;
        for (int ei : m_triangle_edges[ti])
            if (edge_map[static_cast<size_t>(ei)] == INVALID_INDEX)
                edge_map[static_cast<size_t>(ei)] = ne++;
    }
    const auto remap_sorted = [](std::vector<int>& list, const std::vector<int>& map) {
        size_t kept = 0;
        for (int old : list) {
            const int now = map[static_cast<size_t>(old)];
            if (now != INVALID_INDEX)
                list[kept++] = now;
        }
        list.resize(kept);
        // Insertion sort: the lists are a valence long, and mostly sorted already.
        for (size_t i = 1; i < kept; ++i) {
            const int v = list[i];
            size_t j = i;
            for (; j > 0 && list[j - 1] > v; --j)
                list[j] = list[j - 1];
            list[j] = v;
        }
    };

    // Vertices (the maps are increasing, so an element's new index never exceeds its old one
    // and moving forward in place is safe).
    for (size_t vi = 0; vi < m_positions.size(); ++vi) {
        const int now = vertex_map[vi];
        if (now == INVALID_INDEX)
            continue;
        const size_t n = static_cast<size_t>(now);
        m_positions[n] = m_positions[vi];
        m_vertex_marked[n] = m_vertex_marked[vi];
        if (n != vi) {
            m_vertex_triangles[n] = std::move(m_vertex_triangles[vi]);
            m_vertex_edges[n] = std::move(m_vertex_edges[vi]);
        }
    }
    m_positions.resize(static_cast<size_t>(nv));
    m_vertex_alive.assign(static_cast<size_t>(nv), 1);
    m_vertex_marked.resize(static_cast<size_t>(nv));
    m_vertex_triangles.resize(static_cast<size_t>(nv));
    m_vertex_edges.resize(static_cast<size_t>(nv));
    tbb::parallel_for(0, nv, [&](int vi) {
        remap_sorted(m_vertex_triangles[static_cast<size_t>(vi)], triangle_map);
        remap_sorted(m_vertex_edges[static_cast<size_t>(vi)], edge_map);
    });

    // Triangles.
    for (size_t ti = 0; ti < triangle_map.size(); ++ti) {
        const int now = triangle_map[ti];
        if (now == INVALID_INDEX)
            continue;
        const size_t n = static_cast<size_t>(now);
        const Triangle t = m_triangles[ti];
        const std::array<int, 3> e = m_triangle_edges[ti];
        for (size_t k = 0; k < 3; ++k) {
            m_triangles[n][k] = vertex_map[static_cast<size_t>(t[k])];
            m_triangle_edges[n][k] = edge_map[static_cast<size_t>(e[k])];
        }
        m_labels[n] = m_labels[ti];
        m_triangle_marked[n] = m_triangle_marked[ti];
    }
    m_triangles.resize(static_cast<size_t>(nt));
    m_triangle_edges.resize(static_cast<size_t>(nt));
    m_labels.resize(static_cast<size_t>(nt));
    m_triangle_marked.resize(static_cast<size_t>(nt));

    // Edges: new order is first appearance, not old order, so permute through scratch.
    std::vector<Edge> edges(static_cast<size_t>(ne));
    std::vector<std::vector<int>> edge_triangles(static_cast<size_t>(ne));
    for (size_t ei = 0; ei < edge_map.size(); ++ei) {
        const int now = edge_map[ei];
        if (now == INVALID_INDEX)
            continue;
        const size_t n = static_cast<size_t>(now);
        edges[n] = {vertex_map[static_cast<size_t>(m_edges[ei][0])],
                    vertex_map[static_cast<size_t>(m_edges[ei][1])]};
        edge_triangles[n] = std::move(m_edge_triangles[ei]);
    }
    tbb::parallel_for(0, ne, [&](int ei) {
        remap_sorted(edge_triangles[static_cast<size_t>(ei)], triangle_map);
    });
    m_edges = std::move(edges);
    m_edge_triangles = std::move(edge_triangles);

    for (MeshObserver* o : m_observers)
        o->on_compact(vertex_map);
    return vertex_map;
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
    *this = std::move(m);
}

}  // namespace meniscus::tracker
