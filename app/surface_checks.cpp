#include "app/surface_checks.h"

#include "app/errors.h"
#include "tracker/mesh_intersections.h"
#include "tracker/mesh_measures.h"
#include "tracker/mesh_validate.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>

namespace meniscus::app {

namespace {

using tracker::MeshData;
using tracker::SurfaceMesh;
using tracker::Vec3;

/// Problems listed in a message before "and N more".
constexpr size_t MAX_LISTED = 5;
/// Doubles resolve an edge of length ℓ at coordinates up to about ℓ · 1e12.
constexpr double MAX_COORDINATE_TO_EDGE = 1e12;
/// Coordinates beyond this overflow products of a few of them.
constexpr double MAX_COORDINATE = 1e30;
/// A point is inside a closed component when its winding number exceeds this.
constexpr double INSIDE_WINDING = 0.5;

std::string format_number(double v) {
    char text[32];
    std::snprintf(text, sizeof text, "%.4g", v);
    return text;
}

std::string format_point(const Vec3& p) {
    return "(" + format_number(p.x()) + ", " + format_number(p.y()) + ", " + format_number(p.z()) +
           ")";
}

/// Faces and vertices as the file numbers them: OBJ vertices from 1 (the order of its `v`
/// lines) and faces by line; PLY elements from 0.
class FileTerms {
public:
    explicit FileTerms(const MeshData& data) : m_data(data), m_obj(!data.face_line.empty()) {}
    std::string number(int vi) const {
        return std::to_string(static_cast<long long>(vi) + (m_obj ? 1 : 0));
    }
    std::string vertex(int vi) const { return "vertex " + number(vi); }
    /// "vertices a, b, c"
    std::string vertices(const tracker::Triangle& t) const {
        return "vertices " + number(t[0]) + ", " + number(t[1]) + ", " + number(t[2]);
    }
    std::string face_of_triangle(int ti) const {
        const auto t = static_cast<size_t>(ti);
        const int face = t < m_data.triangle_face.size() ? m_data.triangle_face[t] : ti;
        const auto f = static_cast<size_t>(face);
        if (m_obj && f < m_data.face_line.size())
            return "the face on line " + std::to_string(m_data.face_line[f]);
        return "face " + std::to_string(face);
    }
    std::string numbering() const {
        return m_obj ? "vertices numbered from 1, faces by line" : "elements numbered from 0";
    }

private:
    const MeshData& m_data;
    bool m_obj;
};

std::string describe(const SurfaceMesh& mesh, const tracker::MeshViolation& v,
                     const FileTerms& terms) {
    using tracker::ViolationKind;
    const std::string kind = tracker::to_string(v.kind);
    switch (v.kind) {
        case ViolationKind::DuplicateTriangle:
        case ViolationKind::DegenerateTriangle:
        case ViolationKind::RepeatedVertex:
        case ViolationKind::InvalidVertexIndex: {
            const tracker::Triangle& t = mesh.triangle(v.index);
            std::string text =
                kind + ": " + terms.face_of_triangle(v.index) + " (" + terms.vertices(t) + ")";
            if (v.kind == ViolationKind::DuplicateTriangle) {
                // The library's message names the earlier triangle last.
                const auto pos = v.message.rfind("triangle ");
                if (pos != std::string::npos) {
                    const int other = std::atoi(v.message.c_str() + pos + 9);
                    text += " has the same vertices as " + terms.face_of_triangle(other);
                }
            } else if (v.kind == ViolationKind::DegenerateTriangle) {
                text += " has zero area";
            }
            return text;
        }
        case ViolationKind::BoundaryEdge:
        case ViolationKind::OddEdgeValence:
        case ViolationKind::InconsistentOrientation: {
            const tracker::Edge& e = mesh.edge(v.index);
            const auto& tris = mesh.edge_triangles(v.index);
            std::string text = kind + ": the edge between vertices " + terms.number(e[0]) +
                               " and " + terms.number(e[1]);
            if (v.kind == ViolationKind::BoundaryEdge)
                return text + " belongs to " + terms.face_of_triangle(tris[0]) +
                       " only: the surface is not closed";
            text += " is shared by " + std::to_string(tris.size()) + " faces (" +
                    terms.face_of_triangle(tris[0]);
            for (size_t k = 1; k < tris.size() && k < MAX_LISTED; ++k)
                text += ", " + terms.face_of_triangle(tris[k]);
            text += ")";
            if (v.kind == ViolationKind::InconsistentOrientation)
                text += " that do not all run along it in alternating directions: neighbouring "
                        "faces must list their shared edge in opposite orders";
            return text;
        }
        case ViolationKind::AdjacencyMismatch:
            break;
    }
    return kind + ": " + v.message;
}

/// Winding number of the closed triangle set `triangles` around p (±1 inside, 0 outside).
double winding_number(const SurfaceMesh& mesh, const std::vector<int>& triangles, const Vec3& p) {
    double solid_angle = 0.0;
    for (int ti : triangles) {
        const tracker::Triangle& t = mesh.triangle(ti);
        const Vec3 a = mesh.position(t[0]) - p, b = mesh.position(t[1]) - p,
                   c = mesh.position(t[2]) - p;
        const double la = a.norm(), lb = b.norm(), lc = c.norm();
        const double numerator = a.dot(b.cross(c));
        const double denominator = la * lb * lc + a.dot(b) * lc + a.dot(c) * lb + b.dot(c) * la;
        solid_angle += 2.0 * std::atan2(numerator, denominator);
    }
    return solid_angle / (4.0 * M_PI);
}

/// Closed surfaces must face outward, and a surface inside another must face the other way
/// (a bubble in a drop): then each side of every triangle is one phase.
void check_orientation(const SurfaceMesh& mesh, const Scene& scene, const FileTerms& terms) {
    const tracker::Components components = tracker::triangle_components(mesh);
    const std::vector<double> volumes = tracker::component_volumes(mesh, components);
    const auto count = static_cast<size_t>(components.count);
    std::vector<std::vector<int>> triangles(count);
    std::vector<tracker::Box3> boxes(count);
    std::vector<Vec3> probe(count);
    for (int ti = 0; ti < mesh.num_triangles(); ++ti) {
        if (!mesh.triangle_alive(ti))
            continue;
        const auto c = static_cast<size_t>(components.triangle_component[static_cast<size_t>(ti)]);
        if (triangles[c].empty())
            probe[c] = mesh.position(mesh.triangle(ti)[0]);
        triangles[c].push_back(ti);
        for (int vi : mesh.triangle(ti))
            boxes[c].extend(mesh.position(vi));
    }
    const std::string file = scene.surface.mesh_file;
    const bool all_inside_out =
        std::all_of(volumes.begin(), volumes.end(), [](double v) { return v < 0.0; });
    for (size_t c = 0; c < count; ++c) {
        int depth = 0;
        size_t enclosing = c;
        for (size_t d = 0; d < count; ++d)
            if (d != c && boxes[d].contains(probe[c]) &&
                std::abs(winding_number(mesh, triangles[d], probe[c])) > INSIDE_WINDING) {
                ++depth;
                enclosing = d;
            }
        const bool outward = volumes[c] > 0.0;
        if (outward == (depth % 2 == 0))
            continue;
        std::ostringstream s;
        s << file << ": ";
        if (depth == 0) {
            s << (all_inside_out && count == 1 ? "the surface is inside-out"
                                               : "a surface is inside-out")
              << ": its " << triangles[c].size() << " faces (e.g. "
              << terms.face_of_triangle(triangles[c].front())
              << ") wind clockwise seen from outside, enclosing a volume of "
              << format_number(volumes[c])
              << " m^3. Faces must wind counter-clockwise seen from outside (README): reverse "
                 "the vertex order of every face; to make the enclosed region gas, keep the "
                 "winding and set /surface/inside to \"gas\"";
        } else {
            s << "a surface of " << triangles[c].size() << " faces (e.g. "
              << terms.face_of_triangle(triangles[c].front()) << ") lies inside another (e.g. "
              << terms.face_of_triangle(triangles[enclosing].front())
              << ") and winds the same way; a surface inside another must wind the opposite "
                 "way (clockwise seen from its own outside), so that the region between them "
                 "is one phase";
        }
        throw InputError(s.str());
    }
}

}  // namespace

MeshData read_surface_file(const Scene& scene) {
    const std::string& file = scene.surface.mesh_file;
    MeshData data;
    try {
        data = tracker::read_mesh_file(file);
    } catch (const std::runtime_error& e) {
        throw InputError(e.what());
    }
    if (data.triangles.empty())
        throw InputError(file + ": no faces (" + std::to_string(data.positions.size()) +
                         " vertices, 0 faces): the initial surface needs a closed triangle mesh");
    // Before anything indexes the positions with them (the area estimate, the mesh).
    const FileTerms terms(data);
    const auto nv = static_cast<long long>(data.positions.size());
    for (size_t ti = 0; ti < data.triangles.size(); ++ti)
        for (int vi : data.triangles[ti])
            if (vi < 0 || vi >= nv)
                throw InputError(file + ": " + terms.face_of_triangle(static_cast<int>(ti)) +
                                 " refers to " + terms.vertex(vi) + ", but the file has " +
                                 std::to_string(nv) + " vertices (" + terms.numbering() + ")");
    return data;
}

SurfaceMesh checked_surface_mesh(const MeshData& data, const Scene& scene) {
    const std::string& file = scene.surface.mesh_file;
    const FileTerms terms(data);
    for (size_t ti = 0; ti < data.triangles.size(); ++ti) {
        const tracker::Triangle& t = data.triangles[ti];
        if (t[0] == t[1] || t[1] == t[2] || t[0] == t[2])
            throw InputError(file + ": " + terms.face_of_triangle(static_cast<int>(ti)) +
                             " uses a vertex twice (" + terms.vertices(t) +
                             "): a degenerate face");
    }
    SurfaceMesh mesh(data.positions, data.triangles);

    tracker::ValidationOptions validation;
    validation.allow_boundary = scene.surface.open;
    const auto violations = tracker::validate_mesh(mesh, validation);
    if (!violations.empty()) {
        std::ostringstream s;
        s << file << ": not a valid " << (scene.surface.open ? "open" : "closed") << " surface ("
          << violations.size() << " problems; " << terms.numbering() << "):";
        for (size_t i = 0; i < violations.size() && i < MAX_LISTED; ++i)
            s << "\n  " << describe(mesh, violations[i], terms);
        if (violations.size() > MAX_LISTED)
            s << "\n  ... and " << violations.size() - MAX_LISTED << " more";
        throw InputError(s.str());
    }

    // Scale before any geometric test: products of huge coordinates overflow.
    double extent = 0.0;
    for (const Vec3& p : data.positions)
        extent = std::max(extent, p.cwiseAbs().maxCoeff());
    const double mean_edge = tracker::edge_length_stats(mesh).mean;
    if (!(extent <= MAX_COORDINATE) || !(extent <= MAX_COORDINATE_TO_EDGE * mean_edge))
        throw InputError(file + ": vertices reach " + format_number(extent) +
                         " m from the origin with edges of " + format_number(mean_edge) +
                         " m on average: too far for double precision (at most " +
                         format_number(MAX_COORDINATE_TO_EDGE) + " edge lengths and " +
                         format_number(MAX_COORDINATE) + " m); move the mesh nearer the origin");

    const tracker::IntersectionReport r = tracker::find_self_intersections(mesh);
    if (!r.intersection_free()) {
        std::ostringstream s;
        s << file << ": the surface intersects itself (" << r.triangle_pairs.size()
          << " pairs of triangles), e.g.";
        for (size_t i = 0; i < r.triangle_pairs.size() && i < MAX_LISTED; ++i)
            s << (i == 0 ? " " : "; ") << terms.face_of_triangle(r.triangle_pairs[i].ti)
              << " and " << terms.face_of_triangle(r.triangle_pairs[i].tj);
        throw InputError(s.str());
    }
    if (!scene.surface.open)
        check_orientation(mesh, scene, terms);
    return mesh;
}

void check_surface_meets_fluid_box(const Scene& scene, const Eigen::Vector3d& surface_min,
                                   const Eigen::Vector3d& surface_max, const std::string& what) {
    if (scene.flow.type != "fluid")
        return;
    const Eigen::Vector3d lo = scene.domain.min, hi = scene.domain.min + scene.domain.size;
    if ((surface_max.array() >= lo.array()).all() && (surface_min.array() <= hi.array()).all())
        return;
    throw InputError(scene.source_path + ": " + what + " (within " + format_point(surface_min) +
                     " to " + format_point(surface_max) +
                     " m) lies entirely outside the fluid box /domain (" + format_point(lo) +
                     " to " + format_point(hi) +
                     " m): the fluid would never move it; move the surface or the box");
}

}  // namespace meniscus::app
