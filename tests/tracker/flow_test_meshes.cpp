#include "tests/tracker/flow_test_meshes.h"

#include "tracker/implicit_mesher.h"
#include "tracker/implicit_shape.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <utility>
#include <vector>

namespace meniscus::tracker::testing {

SurfaceMesh meshed_sphere(const Vec3& center, double radius, double edge_length) {
    ImplicitMeshOptions options;
    options.edge_length = edge_length;
    return mesh_implicit_shape(*make_sphere(center, radius), options);
}

/// Moves each vertex onto the sphere exactly (the mesher leaves |φ| ≲ 1e-3 ℓ).
void project_to_sphere(SurfaceMesh& mesh, const Vec3& center, double radius) {
    for (int vi = 0; vi < mesh.num_vertices(); ++vi)
        if (mesh.vertex_alive(vi))
            mesh.set_position(vi, center + radius * (mesh.position(vi) - center).normalized());
}

std::vector<Vec3> moved(const SurfaceMesh& mesh, const std::vector<Vec3>& d) {
    std::vector<Vec3> p = mesh.positions();
    for (size_t i = 0; i < p.size(); ++i)
        p[i] += d[i];
    return p;
}

void displace(SurfaceMesh& mesh, const std::vector<Vec3>& d) {
    mesh.set_positions(moved(mesh, d));
}

/// Cube [−a, a]³ with n × n quads per face, two triangles per quad, outward normals, shared
/// vertices along edges and corners: sharp edges by construction.
SurfaceMesh cube_mesh(double a, int n) {
    std::map<std::array<int, 3>, int> index;
    std::vector<Vec3> positions;
    std::vector<Triangle> triangles;
    auto vertex = [&](std::array<int, 3> ijk) {
        const auto it = index.find(ijk);
        if (it != index.end())
            return it->second;
        positions.push_back(
            Vec3(-a + 2.0 * a * ijk[0] / n, -a + 2.0 * a * ijk[1] / n, -a + 2.0 * a * ijk[2] / n));
        index[ijk] = static_cast<int>(positions.size()) - 1;
        return index[ijk];
    };
    for (int axis = 0; axis < 3; ++axis)
        for (int side = 0; side < 2; ++side) {
            const int u = (axis + 1) % 3, v = (axis + 2) % 3;
            Vec3 outward = Vec3::Zero();
            outward[axis] = side == 0 ? -1.0 : 1.0;
            for (int i = 0; i < n; ++i)
                for (int j = 0; j < n; ++j) {
                    auto at = [&](int di, int dj) {
                        std::array<int, 3> ijk{};
                        ijk[static_cast<size_t>(axis)] = side * n;
                        ijk[static_cast<size_t>(u)] = i + di;
                        ijk[static_cast<size_t>(v)] = j + dj;
                        return vertex(ijk);
                    };
                    const int p00 = at(0, 0), p10 = at(1, 0), p11 = at(1, 1), p01 = at(0, 1);
                    for (Triangle t : {Triangle{p00, p10, p11}, Triangle{p00, p11, p01}}) {
                        const Vec3& x0 = positions[static_cast<size_t>(t[0])];
                        const Vec3 nrm = (positions[static_cast<size_t>(t[1])] - x0)
                                             .cross(positions[static_cast<size_t>(t[2])] - x0);
                        if (nrm.dot(outward) < 0.0)
                            std::swap(t[1], t[2]);
                        triangles.push_back(t);
                    }
                }
        }
    return SurfaceMesh(positions, triangles);
}

/// Open V-shaped valley z = slope·|x| over [−1, 1] × [0, 1] (n × n quads per side), normals
/// up (+z side): a concave crease along x = 0 seen from the side the normals point to.
SurfaceMesh valley_mesh(double slope, int n) {
    std::vector<Vec3> positions;
    std::vector<Triangle> triangles;
    const int nx = 2 * n + 1, ny = n + 1;
    for (int j = 0; j < ny; ++j)
        for (int i = 0; i < nx; ++i) {
            const double x = -1.0 + 2.0 * i / (nx - 1), y = static_cast<double>(j) / n;
            positions.push_back(Vec3(x, y, slope * std::abs(x)));
        }
    auto id = [nx](int i, int j) { return j * nx + i; };
    for (int j = 0; j + 1 < ny; ++j)
        for (int i = 0; i + 1 < nx; ++i) {
            triangles.push_back({id(i, j), id(i + 1, j), id(i + 1, j + 1)});
            triangles.push_back({id(i, j), id(i + 1, j + 1), id(i, j + 1)});
        }
    return SurfaceMesh(positions, triangles);
}

/// Subdivided icosahedron: `levels` midpoint subdivisions, every vertex projected onto the
/// sphere. Nearly regular (valence 6 except 12 valence-5 vertices), unlike the mesher's output.
SurfaceMesh icosphere(const Vec3& center, double radius, int levels) {
    const double g = (1.0 + std::sqrt(5.0)) / 2.0;
    std::vector<Vec3> p = {{-1, g, 0}, {1, g, 0}, {-1, -g, 0}, {1, -g, 0},
                           {0, -1, g}, {0, 1, g}, {0, -1, -g}, {0, 1, -g},
                           {g, 0, -1}, {g, 0, 1}, {-g, 0, -1}, {-g, 0, 1}};
    std::vector<Triangle> tris = {{0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11},
                                  {1, 5, 9},  {5, 11, 4}, {11, 10, 2}, {10, 7, 6}, {7, 1, 8},
                                  {3, 9, 4},  {3, 4, 2},  {3, 2, 6},   {3, 6, 8},  {3, 8, 9},
                                  {4, 9, 5},  {2, 4, 11}, {6, 2, 10},  {8, 6, 7},  {9, 8, 1}};
    for (Vec3& x : p)
        x.normalize();
    for (int level = 0; level < levels; ++level) {
        std::map<std::pair<int, int>, int> midpoint;
        auto mid = [&](int a, int b) {
            const std::pair<int, int> key(std::min(a, b), std::max(a, b));
            const auto it = midpoint.find(key);
            if (it != midpoint.end())
                return it->second;
            p.push_back((p[static_cast<size_t>(a)] + p[static_cast<size_t>(b)]).normalized());
            return midpoint[key] = static_cast<int>(p.size()) - 1;
        };
        std::vector<Triangle> finer;
        for (const Triangle& t : tris) {
            const int ab = mid(t[0], t[1]), bc = mid(t[1], t[2]), ca = mid(t[2], t[0]);
            finer.insert(finer.end(),
                         {{t[0], ab, ca}, {ab, t[1], bc}, {ca, bc, t[2]}, {ab, bc, ca}});
        }
        tris = finer;
    }
    for (Vec3& x : p)
        x = center + radius * x;
    return SurfaceMesh(p, tris);
}

/// Two overlapping balls of radius r around (∓a, 0, 0) (a < r) meshed as two latitude–longitude
/// caps sharing the ring where the spheres meet: every vertex on the exact union's boundary, a
/// concave crease exactly on the ring. Spacing ≈ ξ along latitude lines and at the equator.
SurfaceMesh peanut_mesh(double a, double r, double xi) {
    const double phi_max = std::acos(-a / r);
    const int n_lat = std::max(2, static_cast<int>(std::lround(r * phi_max / xi)));
    const int n_lon = std::max(6, static_cast<int>(std::lround(2.0 * M_PI * r / xi)));
    std::vector<Vec3> p;
    std::vector<Triangle> tris;
    std::vector<int> shared_ring;
    for (int j = 0; j < n_lon; ++j) {
        const double psi = 2.0 * M_PI * j / n_lon;
        p.push_back(r * std::sin(phi_max) * Vec3(0.0, std::cos(psi), std::sin(psi)));
        shared_ring.push_back(static_cast<int>(p.size()) - 1);
    }
    for (double side : {-1.0, 1.0}) {
        const Vec3 c(side * a, 0.0, 0.0), e(side, 0.0, 0.0);
        p.push_back(c + r * e);
        const int pole = static_cast<int>(p.size()) - 1;
        std::vector<std::vector<int>> rings;
        for (int k = 1; k < n_lat; ++k) {
            const double phi = phi_max * k / n_lat;
            std::vector<int> ring;
            for (int j = 0; j < n_lon; ++j) {
                const double psi = 2.0 * M_PI * j / n_lon;
                p.push_back(c + r * (std::cos(phi) * e +
                                     std::sin(phi) * Vec3(0.0, std::cos(psi), std::sin(psi))));
                ring.push_back(static_cast<int>(p.size()) - 1);
            }
            rings.push_back(ring);
        }
        rings.push_back(shared_ring);
        auto add = [&](Triangle t) {
            const Vec3& x0 = p[static_cast<size_t>(t[0])];
            const Vec3 n =
                (p[static_cast<size_t>(t[1])] - x0).cross(p[static_cast<size_t>(t[2])] - x0);
            if (n.dot(x0 - c) < 0.0)
                std::swap(t[1], t[2]);
            tris.push_back(t);
        };
        for (int j = 0; j < n_lon; ++j) {
            const size_t j0 = static_cast<size_t>(j), j1 = static_cast<size_t>((j + 1) % n_lon);
            add({pole, rings[0][j0], rings[0][j1]});
            for (size_t k = 0; k + 1 < rings.size(); ++k) {
                add({rings[k][j0], rings[k + 1][j0], rings[k + 1][j1]});
                add({rings[k][j0], rings[k + 1][j1], rings[k][j1]});
            }
        }
    }
    return SurfaceMesh(p, tris);
}

double observed_order(double coarse_error, double fine_error, double coarse_h, double fine_h) {
    return std::log(coarse_error / fine_error) / std::log(coarse_h / fine_h);
}

}  // namespace meniscus::tracker::testing
