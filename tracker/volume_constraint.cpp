#include "tracker/volume_constraint.h"

#include "tracker/mesh_measures.h"

#include <array>
#include <stdexcept>
#include <string>

namespace meniscus::tracker {

namespace {

/// Six times the signed volume of the tetrahedron (ref, a, b, c).
double tet6(const Vec3& ref, const Vec3& a, const Vec3& b, const Vec3& c) {
    return (a - ref).dot((b - ref).cross(c - ref));
}

/// The axis of the divergence theorem for a periodic mesh (issue 39): V = ∮ (x_a − c) n_a dA,
/// exact for a surface closed in the periodic box when axis a does not wrap (the field is then
/// periodic along the others). The first axis that does not wrap; z when all three do — the
/// volume is then defined up to a constant per component, which the differences that
/// resolve_collisions corrects do not see (positions x0 + d move continuously, so each
/// triangle keeps its image), and its gradient is still ⅓ Σ A_t.
int divergence_axis(const MeshPeriods& periods) {
    for (int a = 0; a < 3; ++a)
        if (!periods.wraps(a))
            return a;
    return 2;
}

/// Corners of triangle t at `positions`, each at its image nearest the first (periodic mesh).
std::array<Vec3, 3> unwrapped_corners(const MeshPeriods& periods,
                                      const std::vector<Vec3>& positions, const Triangle& t) {
    const Vec3& a = positions[static_cast<size_t>(t[0])];
    return {a, periods.nearest_image(positions[static_cast<size_t>(t[1])], a),
            periods.nearest_image(positions[static_cast<size_t>(t[2])], a)};
}

void check_size(const char* what, size_t got, size_t expected) {
    if (got != expected)
        throw std::invalid_argument("volume_restoring_displacements: " + std::string(what) +
                                    " has " + std::to_string(got) + " entries for " +
                                    std::to_string(expected));
}

}  // namespace

VolumeComponents volume_components(const SurfaceMesh& mesh) {
    const Components triangles = triangle_components(mesh);
    VolumeComponents c;
    c.count = triangles.count;
    c.triangle_component = triangles.triangle_component;
    c.closed.assign(static_cast<size_t>(c.count), 1);
    for (int ei = 0; ei < mesh.num_edges(); ++ei) {
        if (!mesh.edge_alive(ei))
            continue;
        const std::vector<int>& incident = mesh.edge_triangles(ei);
        if (incident.size() < 2 && !incident.empty())
            c.closed[static_cast<size_t>(
                c.triangle_component[static_cast<size_t>(incident.front())])] = 0;
    }
    c.vertex_component.assign(static_cast<size_t>(mesh.num_vertices()), INVALID_INDEX);
    for (int vi = 0; vi < mesh.num_vertices(); ++vi) {
        if (!mesh.vertex_alive(vi))
            continue;
        int component = INVALID_INDEX;
        bool shared = false;
        for (int ti : mesh.vertex_triangles(vi)) {
            const int ct = c.triangle_component[static_cast<size_t>(ti)];
            if (ct == INVALID_INDEX)
                continue;
            if (component == INVALID_INDEX)
                component = ct;
            else if (ct != component)
                shared = true;
        }
        if (component != INVALID_INDEX && !shared && c.closed[static_cast<size_t>(component)])
            c.vertex_component[static_cast<size_t>(vi)] = component;
    }
    return c;
}

std::vector<double> component_volumes_at(const SurfaceMesh& mesh,
                                         const VolumeComponents& components,
                                         const std::vector<Vec3>& positions) {
    if (positions.size() != static_cast<size_t>(mesh.num_vertices()))
        throw std::invalid_argument("component_volumes_at: " + std::to_string(positions.size()) +
                                    " positions for " + std::to_string(mesh.num_vertices()) +
                                    " vertex slots");
    const size_t n = static_cast<size_t>(components.count);
    if (mesh.periodic()) {
        const MeshPeriods& periods = mesh.periods();
        const int axis = divergence_axis(periods);
        const double c = periods.origin[axis];
        std::vector<double> volume(n, 0.0);
        for (int ti = 0; ti < mesh.num_triangles(); ++ti) {
            if (!mesh.triangle_alive(ti))
                continue;
            const auto k =
                static_cast<size_t>(components.triangle_component[static_cast<size_t>(ti)]);
            const std::array<Vec3, 3> x = unwrapped_corners(periods, positions, mesh.triangle(ti));
            const double area_a = 0.5 * (x[1] - x[0]).cross(x[2] - x[0])[axis];
            volume[k] += ((x[0][axis] + x[1][axis] + x[2][axis]) / 3.0 - c) * area_a;
        }
        return volume;
    }
    // Each component about one of its own vertices, to keep round-off small.
    std::vector<double> six_v(n, 0.0);
    std::vector<Vec3> ref(n, Vec3::Zero());
    std::vector<std::uint8_t> has_ref(n, 0);
    for (int ti = 0; ti < mesh.num_triangles(); ++ti) {
        if (!mesh.triangle_alive(ti))
            continue;
        const auto c = static_cast<size_t>(components.triangle_component[static_cast<size_t>(ti)]);
        const Triangle& t = mesh.triangle(ti);
        const auto x = [&](int k) -> const Vec3& { return positions[static_cast<size_t>(t[k])]; };
        if (!has_ref[c]) {
            ref[c] = x(0);
            has_ref[c] = 1;
        }
        six_v[c] += tet6(ref[c], x(0), x(1), x(2));
    }
    for (double& v : six_v)
        v /= 6.0;
    return six_v;
}

std::vector<Vec3> volume_restoring_displacements(const SurfaceMesh& mesh,
                                                 const VolumeComponents& components,
                                                 const std::vector<Vec3>& positions,
                                                 const std::vector<double>& volume_errors,
                                                 const std::vector<std::uint8_t>& movable,
                                                 const std::vector<double>& inv_mass) {
    const size_t n = static_cast<size_t>(mesh.num_vertices());
    check_size("positions", positions.size(), n);
    check_size("movable", movable.size(), n);
    check_size("inv_mass", inv_mass.size(), n);
    check_size("vertex_component", components.vertex_component.size(), n);
    check_size("volume_errors", volume_errors.size(), static_cast<size_t>(components.count));
    // g_v = ∂V/∂x_v = ⅓ Σ area vectors of the incident triangles.
    std::vector<Vec3> gradient(n, Vec3::Zero());
    for (int ti = 0; ti < mesh.num_triangles(); ++ti) {
        if (!mesh.triangle_alive(ti))
            continue;
        const Triangle& t = mesh.triangle(ti);
        Vec3 third_area;  // ⅓ of the area vector
        if (mesh.periodic()) {
            const std::array<Vec3, 3> x = unwrapped_corners(mesh.periods(), positions, t);
            third_area = (x[1] - x[0]).cross(x[2] - x[0]) / 6.0;
        } else {
            const Vec3& a = positions[static_cast<size_t>(t[0])];
            const Vec3& b = positions[static_cast<size_t>(t[1])];
            const Vec3& c = positions[static_cast<size_t>(t[2])];
            third_area = (b - a).cross(c - a) / 6.0;
        }
        for (int vi : t)
            gradient[static_cast<size_t>(vi)] += third_area;
    }
    const auto free_component = [&](size_t v) {
        const int c = components.vertex_component[v];
        return c != INVALID_INDEX && movable[v] != 0 && inv_mass[v] > 0.0 ? c : INVALID_INDEX;
    };
    // gᵀ M⁻¹ g per component over its free vertices.
    std::vector<double> norm(static_cast<size_t>(components.count), 0.0);
    for (size_t v = 0; v < n; ++v) {
        const int c = free_component(v);
        if (c != INVALID_INDEX)
            norm[static_cast<size_t>(c)] += inv_mass[v] * gradient[v].squaredNorm();
    }
    std::vector<Vec3> delta(n, Vec3::Zero());
    for (size_t v = 0; v < n; ++v) {
        const int c = free_component(v);
        if (c == INVALID_INDEX)
            continue;
        const double e = volume_errors[static_cast<size_t>(c)];
        const double q = norm[static_cast<size_t>(c)];
        if (e != 0.0 && q > 0.0)
            delta[v] = (e * inv_mass[v] / q) * gradient[v];
    }
    return delta;
}

}  // namespace meniscus::tracker
