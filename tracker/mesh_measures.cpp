#include "tracker/mesh_measures.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace meniscus::tracker {

namespace {

constexpr double RADIANS_TO_DEGREES = 180.0 / M_PI;

/// Six times the signed volume of the tetrahedron (origin, a, b, c), about a reference point to
/// keep round-off small for meshes far from the origin.
double tet6(const Vec3& ref, const Vec3& a, const Vec3& b, const Vec3& c) {
    return (a - ref).dot((b - ref).cross(c - ref));
}

Vec3 reference_point(const SurfaceMesh& mesh, const std::vector<Vec3>& positions) {
    for (int vi = 0; vi < mesh.num_vertices(); ++vi)
        if (mesh.vertex_alive(vi))
            return positions[static_cast<size_t>(vi)];
    return Vec3::Zero();
}

/// Triangle t's corners: as stored, or on a periodic mesh at the images nearest the first
/// (the minimum image; the same values as mesh.triangle_positions(), without the call).
std::array<Vec3, 3> corners(const SurfaceMesh& mesh, const Triangle& t) {
    const Vec3& a = mesh.position(t[0]);
    if (!mesh.periodic())
        return {a, mesh.position(t[1]), mesh.position(t[2])};
    return {a, mesh.position_near(t[1], a), mesh.position_near(t[2], a)};
}

/// The axis a periodic mesh's volume is integrated along: the first that does not wrap.
int periodic_volume_axis(const MeshPeriods& periods, const char* caller) {
    for (int a = 0; a < 3; ++a)
        if (!periods.wraps(a))
            return a;
    throw std::invalid_argument(std::string(caller) +
                                ": the mesh wraps around all three axes; the enclosed volume needs "
                                "an axis without a period");
}

/// Six times ∫_T (x_a − c) n_a dA over the triangle with corners p (unwrapped, in order): the
/// flux of F = (x_a − c) e_a, whose divergence is 1. F does not change along the other axes, so
/// it is periodic along every wrapping axis (a does not wrap) and the sum over a surface closed
/// in the periodic box is the enclosed volume, whichever image each triangle is read at.
double flux6(const std::array<Vec3, 3>& p, int a, double c) {
    return (p[1] - p[0]).cross(p[2] - p[0])[a] * (p[0][a] + p[1][a] + p[2][a] - 3.0 * c);
}

}  // namespace

double enclosed_volume(const SurfaceMesh& mesh) {
    return enclosed_volume(mesh, mesh.positions());
}

double enclosed_volume(const SurfaceMesh& mesh, const std::vector<Vec3>& positions) {
    if (positions.size() != static_cast<size_t>(mesh.num_vertices()))
        throw std::invalid_argument("enclosed_volume: " + std::to_string(positions.size()) +
                                    " positions for " + std::to_string(mesh.num_vertices()) +
                                    " vertex slots");
    const auto x = [&](int vi) -> const Vec3& { return positions[static_cast<size_t>(vi)]; };
    double six_v = 0.0;
    if (mesh.periodic()) {
        const MeshPeriods& periods = mesh.periods();
        const int a = periodic_volume_axis(periods, "enclosed_volume");
        for (int ti = 0; ti < mesh.num_triangles(); ++ti) {
            if (!mesh.triangle_alive(ti))
                continue;
            const Triangle& t = mesh.triangle(ti);
            const Vec3& p0 = x(t[0]);
            six_v +=
                flux6({p0, periods.nearest_image(x(t[1]), p0), periods.nearest_image(x(t[2]), p0)},
                      a, periods.origin[a]);
        }
        return six_v / 6.0;
    }
    const Vec3 ref = reference_point(mesh, positions);
    for (int ti = 0; ti < mesh.num_triangles(); ++ti) {
        if (!mesh.triangle_alive(ti))
            continue;
        const Triangle& t = mesh.triangle(ti);
        six_v += tet6(ref, x(t[0]), x(t[1]), x(t[2]));
    }
    return six_v / 6.0;
}

double surface_area(const SurfaceMesh& mesh) {
    double twice = 0.0;
    for (int ti = 0; ti < mesh.num_triangles(); ++ti) {
        if (!mesh.triangle_alive(ti))
            continue;
        const std::array<Vec3, 3> p = corners(mesh, mesh.triangle(ti));
        twice += (p[1] - p[0]).cross(p[2] - p[0]).norm();
    }
    return twice / 2.0;
}

EdgeLengthStats edge_length_stats(const SurfaceMesh& mesh) {
    EdgeLengthStats s;
    s.min = std::numeric_limits<double>::infinity();
    double sum = 0.0;
    for (int ei = 0; ei < mesh.num_edges(); ++ei) {
        if (!mesh.edge_alive(ei))
            continue;
        const Edge& e = mesh.edge(ei);
        const Vec3& a = mesh.position(e[0]);
        const double l = (mesh.position_near(e[1], a) - a).norm();
        s.min = std::min(s.min, l);
        s.max = std::max(s.max, l);
        sum += l;
        ++s.count;
    }
    if (s.count == 0)
        return EdgeLengthStats{};
    s.mean = sum / s.count;
    return s;
}

AngleStats angle_stats(const SurfaceMesh& mesh) {
    AngleStats s{std::numeric_limits<double>::infinity(), 0.0};
    bool any = false;
    for (int ti = 0; ti < mesh.num_triangles(); ++ti) {
        if (!mesh.triangle_alive(ti))
            continue;
        const std::array<Vec3, 3> p = corners(mesh, mesh.triangle(ti));
        for (size_t k = 0; k < 3; ++k) {
            const Vec3 u = p[(k + 1) % 3] - p[k];
            const Vec3 v = p[(k + 2) % 3] - p[k];
            const double angle = std::atan2(u.cross(v).norm(), u.dot(v)) * RADIANS_TO_DEGREES;
            s.min_degrees = std::min(s.min_degrees, angle);
            s.max_degrees = std::max(s.max_degrees, angle);
            any = true;
        }
    }
    return any ? s : AngleStats{};
}

Components triangle_components(const SurfaceMesh& mesh) {
    Components c;
    c.triangle_component.assign(static_cast<size_t>(mesh.num_triangles()), INVALID_INDEX);
    std::vector<int> stack;
    for (int seed = 0; seed < mesh.num_triangles(); ++seed) {
        if (!mesh.triangle_alive(seed) || c.triangle_component[static_cast<size_t>(seed)] >= 0)
            continue;
        const int id = c.count++;
        c.triangle_component[static_cast<size_t>(seed)] = id;
        stack.push_back(seed);
        while (!stack.empty()) {
            const int ti = stack.back();
            stack.pop_back();
            for (int ei : mesh.triangle_edges(ti)) {
                for (int tj : mesh.edge_triangles(ei)) {
                    if (c.triangle_component[static_cast<size_t>(tj)] >= 0)
                        continue;
                    c.triangle_component[static_cast<size_t>(tj)] = id;
                    stack.push_back(tj);
                }
            }
        }
    }
    return c;
}

std::vector<double> component_volumes(const SurfaceMesh& mesh, const Components& components) {
    std::vector<double> six_v(static_cast<size_t>(components.count), 0.0);
    if (mesh.periodic()) {
        const int a = periodic_volume_axis(mesh.periods(), "component_volumes");
        for (int ti = 0; ti < mesh.num_triangles(); ++ti) {
            if (!mesh.triangle_alive(ti))
                continue;
            six_v[static_cast<size_t>(components.triangle_component[static_cast<size_t>(ti)])] +=
                flux6(corners(mesh, mesh.triangle(ti)), a, mesh.periods().origin[a]);
        }
    } else {
        const Vec3 ref = reference_point(mesh, mesh.positions());
        for (int ti = 0; ti < mesh.num_triangles(); ++ti) {
            if (!mesh.triangle_alive(ti))
                continue;
            const Triangle& t = mesh.triangle(ti);
            six_v[static_cast<size_t>(components.triangle_component[static_cast<size_t>(ti)])] +=
                tet6(ref, mesh.position(t[0]), mesh.position(t[1]), mesh.position(t[2]));
        }
    }
    for (double& v : six_v)
        v /= 6.0;
    return six_v;
}

int euler_characteristic(const SurfaceMesh& mesh) {
    int used_vertices = 0;
    for (int vi = 0; vi < mesh.num_vertices(); ++vi)
        used_vertices += mesh.vertex_alive(vi) && !mesh.vertex_triangles(vi).empty() ? 1 : 0;
    return used_vertices - mesh.count_live_edges() + mesh.count_live_triangles();
}

std::vector<Vec3> area_weighted_vertex_normals(const SurfaceMesh& mesh) {
    std::vector<Vec3> normals(static_cast<size_t>(mesh.num_vertices()), Vec3::Zero());
    for (int ti = 0; ti < mesh.num_triangles(); ++ti) {
        if (!mesh.triangle_alive(ti))
            continue;
        const Triangle& t = mesh.triangle(ti);
        const std::array<Vec3, 3> p = corners(mesh, t);
        const Vec3 area_vector = (p[1] - p[0]).cross(p[2] - p[0]);
        for (int vi : t)
            normals[static_cast<size_t>(vi)] += area_vector;
    }
    for (Vec3& n : normals) {
        const double length = n.norm();
        n = length > 0.0 ? Vec3(n / length) : Vec3::Zero();
    }
    return normals;
}

}  // namespace meniscus::tracker
