#include "tracker/mesh_validate.h"

#include <algorithm>
#include <map>
#include <string>

namespace meniscus::tracker {

namespace {

std::string describe_triangle(const SurfaceMesh& mesh, int ti) {
    const Triangle& t = mesh.triangle(ti);
    return "triangle " + std::to_string(ti) + " (" + std::to_string(t[0]) + ", " +
           std::to_string(t[1]) + ", " + std::to_string(t[2]) + ")";
}

std::string describe_edge(const SurfaceMesh& mesh, int ei) {
    const Edge& e = mesh.edge(ei);
    return "edge " + std::to_string(ei) + " (" + std::to_string(e[0]) + ", " +
           std::to_string(e[1]) + ")";
}

class Collector {
public:
    explicit Collector(int max) : m_max(max) {}
    bool full() const { return m_max > 0 && static_cast<int>(m_out.size()) >= m_max; }
    void add(ViolationKind kind, int index, std::string message) {
        if (!full())
            m_out.push_back({kind, index, std::move(message)});
    }
    std::vector<MeshViolation> take() { return std::move(m_out); }

private:
    int m_max;
    std::vector<MeshViolation> m_out;
};

void check_triangles(const SurfaceMesh& mesh, const ValidationOptions& options, Collector& out) {
    std::map<std::array<int, 3>, int> seen;
    for (int ti = 0; ti < mesh.num_triangles() && !out.full(); ++ti) {
        if (!mesh.triangle_alive(ti))
            continue;
        const Triangle& t = mesh.triangle(ti);
        bool indices_ok = true;
        for (int vi : t) {
            if (vi < 0 || vi >= mesh.num_vertices() || !mesh.vertex_alive(vi)) {
                out.add(ViolationKind::InvalidVertexIndex, ti,
                        describe_triangle(mesh, ti) + " refers to missing vertex " +
                            std::to_string(vi));
                indices_ok = false;
            }
        }
        if (!indices_ok)
            continue;
        if (t[0] == t[1] || t[1] == t[2] || t[0] == t[2]) {
            out.add(ViolationKind::RepeatedVertex, ti,
                    describe_triangle(mesh, ti) + " repeats a vertex");
            continue;
        }
        std::array<int, 3> key = t;
        std::sort(key.begin(), key.end());
        auto [it, inserted] = seen.emplace(key, ti);
        if (!inserted)
            out.add(ViolationKind::DuplicateTriangle, ti,
                    describe_triangle(mesh, ti) + " has the same vertices as triangle " +
                        std::to_string(it->second));
        if (options.check_degenerate_area) {
            // A periodic mesh's triangle is read by the minimum image (its raw corners may lie
            // a period apart).
            const Vec3& a = mesh.position(t[0]);
            const Vec3 b = mesh.position_near(t[1], a);
            const Vec3 c = mesh.position_near(t[2], a);
            const double twice_area = (b - a).cross(c - a).norm();
            const double longest_sq =
                std::max({(b - a).squaredNorm(), (c - b).squaredNorm(), (a - c).squaredNorm()});
            if (!(twice_area > options.degenerate_area_fraction * longest_sq))
                out.add(ViolationKind::DegenerateTriangle, ti,
                        describe_triangle(mesh, ti) + " has zero area");
        }
    }
}

void check_edges(const SurfaceMesh& mesh, const ValidationOptions& options, Collector& out) {
    for (int ei = 0; ei < mesh.num_edges() && !out.full(); ++ei) {
        if (!mesh.edge_alive(ei))
            continue;
        const auto& tris = mesh.edge_triangles(ei);
        const int n = static_cast<int>(tris.size());
        if (n == 0) {
            out.add(ViolationKind::AdjacencyMismatch, ei,
                    describe_edge(mesh, ei) + " has no triangle");
            continue;
        }
        if (n == 1) {
            if (!options.allow_boundary)
                out.add(ViolationKind::BoundaryEdge, ei,
                        describe_edge(mesh, ei) + " is a boundary edge (only triangle " +
                            std::to_string(tris[0]) + "): the surface is not closed");
            continue;
        }
        if (n % 2 == 1) {
            out.add(ViolationKind::OddEdgeValence, ei,
                    describe_edge(mesh, ei) + " has " + std::to_string(n) + " triangles");
            continue;
        }
        int forward = 0;
        for (int ti : tris)
            forward += mesh.edge_orientation_in_triangle(ti, ei) > 0 ? 1 : 0;
        if (2 * forward != n)
            out.add(ViolationKind::InconsistentOrientation, ei,
                    describe_edge(mesh, ei) + " is traversed " + std::to_string(forward) +
                        " times forward and " + std::to_string(n - forward) +
                        " times backward by its triangles: orientation is inconsistent");
    }
}

void check_adjacency(const SurfaceMesh& mesh, Collector& out) {
    for (int ti = 0; ti < mesh.num_triangles() && !out.full(); ++ti) {
        if (!mesh.triangle_alive(ti))
            continue;
        const Triangle& t = mesh.triangle(ti);
        for (int k = 0; k < 3; ++k) {
            const int ei = mesh.triangle_edges(ti)[k];
            const Edge& e = mesh.edge(ei);
            const int lo = std::min(t[k], t[(k + 1) % 3]), hi = std::max(t[k], t[(k + 1) % 3]);
            const auto& et = mesh.edge_triangles(ei);
            const auto& vt = mesh.vertex_triangles(t[k]);
            if (e[0] != lo || e[1] != hi || std::find(et.begin(), et.end(), ti) == et.end() ||
                std::find(vt.begin(), vt.end(), ti) == vt.end())
                out.add(ViolationKind::AdjacencyMismatch, ti,
                        describe_triangle(mesh, ti) + ": adjacency tables disagree at corner " +
                            std::to_string(k));
        }
    }
}

}  // namespace

std::vector<MeshViolation> validate_mesh(const SurfaceMesh& mesh,
                                         const ValidationOptions& options) {
    Collector out(options.max_violations);
    check_triangles(mesh, options, out);
    check_edges(mesh, options, out);
    check_adjacency(mesh, out);
    return out.take();
}

const char* to_string(ViolationKind kind) {
    switch (kind) {
        case ViolationKind::InvalidVertexIndex:
            return "invalid vertex index";
        case ViolationKind::RepeatedVertex:
            return "repeated vertex";
        case ViolationKind::DuplicateTriangle:
            return "duplicate triangle";
        case ViolationKind::BoundaryEdge:
            return "boundary edge";
        case ViolationKind::OddEdgeValence:
            return "odd edge valence";
        case ViolationKind::InconsistentOrientation:
            return "inconsistent orientation";
        case ViolationKind::DegenerateTriangle:
            return "degenerate triangle";
        case ViolationKind::AdjacencyMismatch:
            return "adjacency mismatch";
    }
    return "unknown";
}

}  // namespace meniscus::tracker
