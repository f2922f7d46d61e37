#include "tracker/flows/curl_noise.h"
#include "tracker/flows/face_offsetting.h"
#include "tracker/flows/flow_errors.h"
#include "tracker/flows/flow_runner.h"
#include "tracker/flows/mean_curvature.h"
#include "tracker/flows/vertex_normal_motion.h"
#include "tracker/implicit_mesher.h"
#include "tracker/implicit_shape.h"
#include "tracker/mesh_measures.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <iostream>
#include <map>
#include <random>
#include <utility>
#include <vector>

namespace meniscus::tracker {
namespace {

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

// ---- Meyer et al. mean curvature ---------------------------------------------------------

/// Relative errors of Meyer's κ against 2/R on a sphere mesh whose vertices lie on the sphere.
struct CurvatureErrors {
    double max = 0.0;       ///< max over vertices of |κ R / 2 − 1|
    double rms = 0.0;       ///< root mean square of the same
    double integral = 0.0;  ///< |Σ Aᵢ κᵢ / (8πR) − 1| (∫ κ dA = 8πR on a sphere)
    double h = 0.0;         ///< mean edge length
};

CurvatureErrors curvature_errors(const SurfaceMesh& mesh, double radius) {
    const std::vector<double> kappa = mean_curvatures(mesh);
    const std::vector<Vec3> k_normal = mean_curvature_normals(mesh);
    const std::vector<Vec3> normals = area_weighted_vertex_normals(mesh);
    const std::vector<double> areas = mixed_voronoi_areas(mesh);
    CurvatureErrors e;
    double sum_sq = 0.0, area_sum = 0.0, integral = 0.0;
    int count = 0;
    for (int vi = 0; vi < mesh.num_vertices(); ++vi) {
        if (!mesh.vertex_alive(vi))
            continue;
        const size_t i = static_cast<size_t>(vi);
        const double rel = std::abs(kappa[i] * radius / 2.0 - 1.0);
        e.max = std::max(e.max, rel);
        sum_sq += rel * rel;
        ++count;
        area_sum += areas[i];
        integral += areas[i] * kappa[i];
        EXPECT_GT(kappa[i], 0.0);
        EXPECT_GT(k_normal[i].dot(normals[i]), 0.0);  // K points outward, along the normal
    }
    EXPECT_NEAR(area_sum, surface_area(mesh), 1e-12 * surface_area(mesh));
    e.rms = std::sqrt(sum_sq / count);
    e.integral = std::abs(integral / (8.0 * M_PI * radius) - 1.0);
    e.h = edge_length_stats(mesh).mean;
    return e;
}

TEST(MeanCurvature, SphereGivesTwoOverRConvergingOnRegularMeshes) {
    const double radius = 0.5;
    const Vec3 center(0.1, -0.2, 0.05);
    std::vector<CurvatureErrors> errors;
    for (int level = 2; level <= 5; ++level) {
        errors.push_back(curvature_errors(icosphere(center, radius, level), radius));
        std::cout << "[ measured ] Meyer κ, icosphere level " << level << " R=" << radius
                  << " h=" << errors.back().h << ": max rel error " << errors.back().max << ", rms "
                  << errors.back().rms << ", ∫κ " << errors.back().integral << "\n";
    }
    for (size_t i = 1; i < errors.size(); ++i) {
        const double order =
            observed_order(errors[i - 1].max, errors[i].max, errors[i - 1].h, errors[i].h);
        std::cout << "[ measured ] observed order (max) " << order << "\n";
        EXPECT_GT(order, 1.8);
    }
    EXPECT_LT(errors.back().max, 1e-3);
}

TEST(MeanCurvature, SphereIrregularMeshErrorIsBoundedAndIntegralConverges) {
    // On irregular meshes the cotangent formula is known not to converge pointwise (Xu 2004;
    // Hildebrandt, Polthier and Wardetzky 2006): the max error stalls at a few percent while
    // the integrated curvature still converges.
    const double radius = 0.5;
    const Vec3 center(0.1, -0.2, 0.05);
    std::vector<CurvatureErrors> errors;
    for (double h : {0.1, 0.05, 0.025}) {
        SurfaceMesh mesh = meshed_sphere(center, radius, h);
        project_to_sphere(mesh, center, radius);
        errors.push_back(curvature_errors(mesh, radius));
        std::cout << "[ measured ] Meyer κ, mesher sphere R=" << radius << " h=" << errors.back().h
                  << ": max rel error " << errors.back().max << ", rms " << errors.back().rms
                  << ", ∫κ " << errors.back().integral << "\n";
        EXPECT_LT(errors.back().max, 0.15);
        EXPECT_LT(errors.back().rms, 0.01);
    }
    for (size_t i = 1; i < errors.size(); ++i) {
        const double order = observed_order(errors[i - 1].integral, errors[i].integral,
                                            errors[i - 1].h, errors[i].h);
        std::cout << "[ measured ] observed order (∫κ) " << order << "\n";
        EXPECT_GT(order, 1.5);
    }
}

TEST(MeanCurvature, PlaneHasZeroCurvatureAndBoundaryVerticesStayFixed) {
    SurfaceMesh mesh = valley_mesh(0.0, 4);
    const std::vector<Vec3> k = mean_curvature_normals(mesh);
    for (int vi = 0; vi < mesh.num_vertices(); ++vi)
        EXPECT_LT(k[static_cast<size_t>(vi)].norm(), 1e-12);
    // A crease is curved; its boundary vertices still do not move.
    mesh = valley_mesh(0.5, 4);
    const std::vector<Vec3> d = mean_curvature_displacements(mesh, 1e-3);
    for (int vi = 0; vi < mesh.num_vertices(); ++vi)
        if (mesh.is_boundary_vertex(vi)) {
            EXPECT_EQ(d[static_cast<size_t>(vi)], Vec3::Zero());
        }
}

TEST(MeanCurvature, SphereFlowFollowsExactRadius) {
    const double r0 = 0.5;
    const Vec3 center(0.0, 0.0, 0.0);
    const double t_end = 0.2 * r0 * r0 / 4.0;  // a fifth of the extinction time
    std::vector<double> errors, mean_edges;
    for (double h : {0.1, 0.05}) {
        SurfaceMesh mesh = meshed_sphere(center, r0, h);
        project_to_sphere(mesh, center, r0);
        mean_edges.push_back(edge_length_stats(mesh).mean);
        double t = 0.0;
        int steps = 0;
        while (t < t_end) {
            const double dt = std::min(mean_curvature_time_step(mesh), t_end - t);
            displace(mesh, mean_curvature_displacements(mesh, dt));
            t += dt;
            ++steps;
        }
        const double exact = sphere_mean_curvature_radius(r0, t_end);
        const SurfaceError e = sphere_error(mesh, center, exact);
        errors.push_back(e.vertex_linf);
        std::cout << "[ measured ] MCF sphere h=" << mean_edges.back() << " steps=" << steps
                  << " R_exact=" << exact << " vertex L∞=" << e.vertex_linf << " L1=" << e.l1
                  << "\n";
        EXPECT_LT(e.vertex_linf, 0.02 * exact);
    }
    EXPECT_LT(errors[1], errors[0]);
}

TEST(MeanCurvature, TimeStepValidatesAndScalesWithShortestEdge) {
    const SurfaceMesh mesh = cube_mesh(1.0, 4);  // all edges ≥ 0.5
    MeanCurvatureFlowOptions options;
    EXPECT_NEAR(mean_curvature_time_step(mesh, options), options.cfl_number * 0.25, 1e-15);
    options.cfl_number = 0.0;
    EXPECT_THROW(mean_curvature_time_step(mesh, options), std::invalid_argument);
}

// ---- face offsetting ---------------------------------------------------------------------

TEST(FaceOffsetting, SphereRadiusChangesBySpeedTimesDt) {
    const double radius = 0.2;
    const Vec3 center(0.25, 0.0, 0.0);
    const double h = 0.001;  // 0.2 m/s × 0.005 s, the A1 step
    std::vector<double> errors, mean_edges;
    for (double edge : {0.04, 0.02, 0.01}) {
        SurfaceMesh mesh = meshed_sphere(center, radius, edge);
        project_to_sphere(mesh, center, radius);
        mean_edges.push_back(edge_length_stats(mesh).mean);
        for (double sign : {1.0, -1.0}) {
            const FaceOffset offset = face_offset_displacements(mesh, sign * 0.2, 0.005);
            double max_error = 0.0;
            int rank_one = 0, live = 0;
            for (int vi = 0; vi < mesh.num_vertices(); ++vi) {
                if (!mesh.vertex_alive(vi))
                    continue;
                const Vec3 p = mesh.position(vi) + offset.displacements[static_cast<size_t>(vi)];
                max_error =
                    std::max(max_error, std::abs((p - center).norm() - (radius + sign * h)));
                rank_one += offset.primary_rank[static_cast<size_t>(vi)] == 1;
                ++live;
            }
            if (sign > 0.0) {
                errors.push_back(max_error / h);
                std::cout << "[ measured ] face offsetting sphere R=0.2 h=" << mean_edges.back()
                          << ": max |Δr − sΔt| / sΔt = " << max_error / h << ", rank-1 vertices "
                          << rank_one << "/" << live << "\n";
            }
            EXPECT_LT(max_error, 0.05 * h);
        }
    }
    EXPECT_LT(errors[1], errors[0]);
    EXPECT_LT(errors[2], errors[1]);
    EXPECT_GT(observed_order(errors[0], errors[2], mean_edges[0], mean_edges[2]), 1.5);
}

TEST(FaceOffsetting, AngleWeightsAlsoOffsetTheSphere) {
    const double radius = 0.2, h = 0.001;
    SurfaceMesh mesh = meshed_sphere(Vec3::Zero(), radius, 0.02);
    project_to_sphere(mesh, Vec3::Zero(), radius);
    FaceOffsettingOptions options;
    options.weighting = OffsetWeighting::angle;
    const FaceOffset offset = face_offset_displacements(mesh, 0.2, 0.005, options);
    const SurfaceError before = sphere_error(mesh, Vec3::Zero(), radius);
    displace(mesh, offset.displacements);
    const SurfaceError after = sphere_error(mesh, Vec3::Zero(), radius + h);
    EXPECT_LT(after.vertex_linf, 0.05 * h);
    EXPECT_LT(before.vertex_linf, 1e-15);
}

TEST(FaceOffsetting, FirstStepOfTwoSphereTestAgreesWithExactSolution) {
    const TwoSphereNormalFlow flow;  // VALIDATION.md A1
    const double dt = 0.005;
    for (double edge : {0.04, 0.02}) {
        SurfaceMesh mesh =
            mesh_implicit_shape(*make_union({make_sphere(flow.center0, flow.initial_radius),
                                             make_sphere(flow.center1, flow.initial_radius)}),
                                ImplicitMeshOptions{edge});
        for (int vi = 0; vi < mesh.num_vertices(); ++vi) {
            const Vec3& p = mesh.position(vi);
            const Vec3& c = p.x() < 0.0 ? flow.center0 : flow.center1;
            mesh.set_position(vi, c + flow.initial_radius * (p - c).normalized());
        }
        const SurfaceError before = two_sphere_normal_flow_error(mesh, flow, 0.0);
        const FaceOffsetStep step = face_offset_step(
            mesh,
            std::vector<double>(static_cast<size_t>(mesh.num_triangles()), flow.normal_speed(0.0)),
            dt);
        EXPECT_FALSE(step.shortened);
        EXPECT_EQ(step.dt, dt);
        displace(mesh, step.displacements);
        const SurfaceError after = two_sphere_normal_flow_error(mesh, flow, dt);
        std::cout << "[ measured ] A1 first step ξ=" << edge << ": vertex L∞ " << after.vertex_linf
                  << " (sΔt = " << flow.speed * dt << "), L∞ " << after.linf << " (before "
                  << before.linf << "), L1 " << after.l1 << " (before " << before.l1 << ")\n";
        EXPECT_LT(after.vertex_linf, 0.05 * flow.speed * dt);
        // The chord error of the sphere mesh is the floor: one step must not add to it.
        EXPECT_LT(after.linf, before.linf * 1.05 + 0.05 * flow.speed * dt);
        EXPECT_LT(after.l1, before.l1 * 1.05 + 0.05 * flow.speed * dt);
    }
}

TEST(FaceOffsetting, ShrinkingCubeStaysSharpWhereVertexNormalsRoundIt) {
    const double a = 0.5, h = 0.05;
    const SurfaceMesh mesh = cube_mesh(a, 6);
    const ShapePtr exact = make_box(Vec3::Constant(-(a - h)), Vec3::Constant(a - h));
    const FaceOffset offset = face_offset_displacements(mesh, -1.0, h);
    const std::vector<Vec3> vn = vertex_normal_displacements(mesh, -1.0, h);
    double fo_error = 0.0, vn_error = 0.0;
    for (int vi = 0; vi < mesh.num_vertices(); ++vi) {
        const Vec3& p = mesh.position(vi);
        const int on_faces = (std::abs(std::abs(p.x()) - a) < 1e-12) +
                             (std::abs(std::abs(p.y()) - a) < 1e-12) +
                             (std::abs(std::abs(p.z()) - a) < 1e-12);
        EXPECT_EQ(offset.primary_rank[static_cast<size_t>(vi)], on_faces);
        fo_error = std::max(
            fo_error, std::abs(exact->value(p + offset.displacements[static_cast<size_t>(vi)])));
        vn_error = std::max(vn_error, std::abs(exact->value(p + vn[static_cast<size_t>(vi)])));
    }
    std::cout << "[ measured ] shrinking cube by h: face offsetting max |φ| / h = " << fo_error / h
              << ", vertex normals " << vn_error / h << "\n";
    EXPECT_LT(fo_error, 1e-12);
    EXPECT_GT(vn_error, 0.2 * h);  // edges: (1 − 1/√2) h for symmetric fans

    // Expanding: the exact solution is the rounded dilation {dist(x, cube) = h}. The Huygens
    // rule puts every vertex exactly on it (edge and corner vertices move by h inside their
    // normal cones), as vertex normals also do here; the plane rule keeps a sharp box of
    // half-width a + h instead.
    const ShapePtr cube = make_box(Vec3::Constant(-a), Vec3::Constant(a));
    const ShapePtr sharp = make_box(Vec3::Constant(-(a + h)), Vec3::Constant(a + h));
    const FaceOffset grow = face_offset_displacements(mesh, 1.0, h);
    FaceOffsettingOptions planes;
    planes.expansion = ExpansionRule::planes;
    const FaceOffset grow_sharp = face_offset_displacements(mesh, 1.0, h, planes);
    const std::vector<Vec3> vn_grow = vertex_normal_displacements(mesh, 1.0, h);
    double fo_rounded = 0.0, vn_rounded = 0.0, planes_sharp = 0.0;
    int expanding = 0;
    for (int vi = 0; vi < mesh.num_vertices(); ++vi) {
        const size_t i = static_cast<size_t>(vi);
        const Vec3& p = mesh.position(vi);
        fo_rounded = std::max(fo_rounded, std::abs(cube->value(p + grow.displacements[i]) - h));
        vn_rounded = std::max(vn_rounded, std::abs(cube->value(p + vn_grow[i]) - h));
        planes_sharp =
            std::max(planes_sharp, std::abs(sharp->value(p + grow_sharp.displacements[i])));
        expanding += grow.expanding[i];
        EXPECT_EQ(offset.expanding[i], 0);  // shrinking a convex body: shocks only
    }
    EXPECT_LT(fo_rounded, 1e-12);
    EXPECT_LT(vn_rounded, 1e-12);
    EXPECT_LT(planes_sharp, 1e-12);
    EXPECT_GT(expanding, 0);
}

TEST(FaceOffsetting, ConcaveCreaseRisesToThePlanesIntersection) {
    const double slope = 0.5, h = 0.01;
    const SurfaceMesh mesh = valley_mesh(slope, 4);
    const int crease = 2 * 4 + 1 + 4;  // row j = 1, column i = n: the point (0, 0.25, 0)
    ASSERT_NEAR(mesh.position(crease).x(), 0.0, 1e-15);
    ASSERT_FALSE(mesh.is_boundary_vertex(crease));
    const FaceOffset offset = face_offset_displacements(mesh, 1.0, h);
    const std::vector<Vec3> vn = vertex_normal_displacements(mesh, 1.0, h);
    const double cos_theta = 1.0 / std::sqrt(1.0 + slope * slope);
    const Vec3 expected(0.0, 0.0, h / cos_theta);  // on both offset planes: the entropy solution
    EXPECT_EQ(offset.primary_rank[static_cast<size_t>(crease)], 2);
    EXPECT_LT((offset.displacements[static_cast<size_t>(crease)] - expected).norm(), 1e-14);
    // Vertex normals move the crease by h only: it lags behind both planes.
    EXPECT_NEAR(vn[static_cast<size_t>(crease)].z(), h, 1e-14);
    const double gap =
        (offset.displacements[static_cast<size_t>(crease)] - vn[static_cast<size_t>(crease)])
            .norm();
    std::cout << "[ measured ] valley crease, slope " << slope << ": face offsetting − vertex "
              << "normal = " << gap / h << " h (exact h(1/cosθ − 1) = " << (1.0 / cos_theta - 1.0)
              << " h)\n";
    EXPECT_NEAR(gap, h * (1.0 / cos_theta - 1.0), 1e-14);
    EXPECT_EQ(offset.expanding[static_cast<size_t>(crease)], 0);

    // Moving down the valley opens an expansion fan: the exact crease point is h below
    // (Huygens); the plane intersection would overshoot to h / cos θ.
    const FaceOffset down = face_offset_displacements(mesh, -1.0, h);
    EXPECT_EQ(down.expanding[static_cast<size_t>(crease)], 1);
    EXPECT_LT((down.displacements[static_cast<size_t>(crease)] - Vec3(0, 0, -h)).norm(), 1e-14);
    FaceOffsettingOptions planes;
    planes.expansion = ExpansionRule::planes;
    const FaceOffset down_sharp = face_offset_displacements(mesh, -1.0, h, planes);
    EXPECT_LT((down_sharp.displacements[static_cast<size_t>(crease)] + expected).norm(), 1e-14);
}

TEST(FaceOffsetting, NearFoldOffsetIsCapped) {
    // A valley with slope 10 (normals 2·84.3° apart): the planes meet 10.05 h above the crease;
    // the cap (default 4) holds the crease vertex to 4 h along the same direction.
    const double h = 0.01;
    const SurfaceMesh mesh = valley_mesh(10.0, 4);
    const size_t crease = 2 * 4 + 1 + 4;
    const FaceOffset capped = face_offset_displacements(mesh, 1.0, h);
    FaceOffsettingOptions loose;
    loose.max_offset_ratio = 20.0;
    const FaceOffset uncapped = face_offset_displacements(mesh, 1.0, h, loose);
    EXPECT_EQ(capped.capped[crease], 1);
    EXPECT_EQ(uncapped.capped[crease], 0);
    EXPECT_NEAR(uncapped.displacements[crease].z(), h * std::sqrt(101.0), 1e-12);
    EXPECT_LT((capped.displacements[crease] - Vec3(0, 0, 4.0 * h)).norm(), 1e-12);
    loose.max_offset_ratio = 0.5;
    EXPECT_THROW(face_offset_displacements(mesh, 1.0, h, loose), std::invalid_argument);
}

TEST(FaceOffsetting, InversionLimitIsExactForOneTriangle) {
    const SurfaceMesh mesh({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}, {{0, 1, 2}});
    // Vertex 2 moves straight down through the opposite edge: area ∝ (1 − 2τ).
    const std::vector<Vec3> d = {Vec3::Zero(), Vec3::Zero(), Vec3(0, -2, 0)};
    InversionLimitOptions options;
    options.min_area_fraction = 0.0;
    EXPECT_NEAR(max_non_inverting_step_fraction(mesh, d, options), 0.5, 1e-15);
    options.min_area_fraction = 0.1;
    EXPECT_NEAR(max_non_inverting_step_fraction(mesh, d, options), 0.45, 1e-15);
    // Moving in-plane without inverting, or rigidly, is unrestricted.
    EXPECT_EQ(max_non_inverting_step_fraction(mesh, {Vec3(1, 1, 5), Vec3(1, 1, 5), Vec3(1, 1, 5)},
                                              options),
              1.0);
    options.min_area_fraction = 1.0;
    EXPECT_THROW(max_non_inverting_step_fraction(mesh, d, options), std::invalid_argument);
}

TEST(FaceOffsetting, StepIsShortenedSoNoTriangleInverts) {
    const double radius = 0.2;
    SurfaceMesh mesh = meshed_sphere(Vec3::Zero(), radius, 0.04);
    project_to_sphere(mesh, Vec3::Zero(), radius);
    const std::vector<double> speeds(static_cast<size_t>(mesh.num_triangles()), -1.0);
    const FaceOffsetStep step = face_offset_step(mesh, speeds, 1.0);  // would shrink through 0
    EXPECT_TRUE(step.shortened);
    EXPECT_EQ(step.attempts, 1);  // linear in Δt: the displacements are scaled, not recomputed
    // A shrinking sphere's triangles scale by (1 − s t / R)²: 10 % area left at
    // t ≈ (1 − √0.1) R / s; on a coarse irregular mesh the offsets of a step of 5R are not
    // exactly radial, so only roughly.
    EXPECT_NEAR(step.dt, (1.0 - std::sqrt(0.1)) * radius, 0.1 * radius);
    const std::vector<Vec3> p1 = moved(mesh, step.displacements);
    double min_fraction = 1.0;
    for (int ti = 0; ti < mesh.num_triangles(); ++ti) {
        const Triangle& t = mesh.triangle(ti);
        const Vec3& a = mesh.position(t[0]);
        const Vec3 n0 = (mesh.position(t[1]) - a).cross(mesh.position(t[2]) - a);
        const Vec3 n1 = (p1[static_cast<size_t>(t[1])] - p1[static_cast<size_t>(t[0])])
                            .cross(p1[static_cast<size_t>(t[2])] - p1[static_cast<size_t>(t[0])]);
        min_fraction = std::min(min_fraction, n1.dot(n0.normalized()) / n0.norm());
    }
    EXPECT_GT(min_fraction, 0.1 - 1e-9);
    EXPECT_LT(min_fraction, 0.1 + 1e-6);

    FaceOffsettingOptions smoothing;
    smoothing.null_space_smoothing = 0.5;
    const FaceOffsetStep smoothed = face_offset_step(mesh, speeds, 1.0, smoothing);
    EXPECT_TRUE(smoothed.shortened);
    EXPECT_GE(max_non_inverting_step_fraction(mesh, smoothed.displacements), 1.0);
}

TEST(FaceOffsetting, NormalTurnCheckForRemeshing) {
    const Vec3 up(0, 0, 1);
    const Vec3 a(0, 0, 0), b(1, 0, 0);
    auto tilted = [](double degrees) {
        const double r = degrees * M_PI / 180.0;
        return Vec3(0, std::cos(r), std::sin(r));  // normal turned by `degrees` about x
    };
    EXPECT_FALSE(triangle_normal_turn_too_large(up, a, b, tilted(20.0)));
    EXPECT_TRUE(triangle_normal_turn_too_large(up, a, b, tilted(40.0)));
    EXPECT_TRUE(triangle_normal_turn_too_large(up, a, b, Vec3(0, -1, 0)));  // inverted
    EXPECT_TRUE(triangle_normal_turn_too_large(up, a, b, Vec3(2, 0, 0)));   // degenerate
    NormalTurnLimit wide;
    wide.max_angle_degrees = 45.0;
    EXPECT_FALSE(triangle_normal_turn_too_large(up, a, b, tilted(40.0), wide));
    EXPECT_THROW(triangle_normal_turn_too_large(Vec3::Zero(), a, b, tilted(0)),
                 std::invalid_argument);

    // Flip of a flat quad is fine; flipping a sharp roof ridge turns normals too far.
    const Vec3 p0(0, 0, 0), p1(1, 0, 0), p2(1, 1, 0), p3(0, 1, 0);
    EXPECT_FALSE(operation_turns_normals_too_far({{p0, p1, p2}, {p0, p2, p3}},
                                                 {{p0, p1, p3}, {p1, p2, p3}}));
    const Vec3 r2(1, 1, 2.0);  // roof folded along the diagonal p0–r2 (new normal turns 55°)
    EXPECT_TRUE(operation_turns_normals_too_far({{p0, p1, r2}, {p0, r2, p3}},
                                                {{p0, p1, p3}, {p1, r2, p3}}));
    NormalTurnLimit bad;
    bad.max_angle_degrees = 180.0;
    EXPECT_THROW(bad.validate(), std::invalid_argument);
}

TEST(FaceOffsetting, OptionsAndInputsAreValidated) {
    const SurfaceMesh mesh = cube_mesh(1.0, 1);
    FaceOffsettingOptions options;
    options.primary_eigenvalue_ratio = 0.0;
    EXPECT_THROW(face_offset_displacements(mesh, 1.0, 0.1, options), std::invalid_argument);
    options = {};
    options.null_space_smoothing = 2.0;
    EXPECT_THROW(face_offset_displacements(mesh, 1.0, 0.1, options), std::invalid_argument);
    EXPECT_THROW(face_offset_displacements(mesh, std::vector<double>(3, 1.0), 0.1),
                 std::invalid_argument);
    EXPECT_THROW(face_offset_step(mesh, std::vector<double>(12, 1.0), 0.0), std::invalid_argument);
}

// ---- curl noise ----------------------------------------------------------------------------

TEST(CurlNoise, DivergenceFreeAndGradientMatchesFiniteDifferences) {
    for (bool planar : {false, true}) {
        CurlNoiseOptions options;
        options.seed = 42;
        options.planar = planar;
        options.time_frequency = 1.5;
        const CurlNoiseField field(options);
        std::mt19937_64 rng(7);
        std::uniform_real_distribution<double> coord(-1.0, 1.0);
        const double step = 1e-5;  // central differences, error ~ step² |∇³u|
        double worst_divergence = 0.0, worst_gradient = 0.0;
        for (int sample = 0; sample < 50; ++sample) {
            const Vec3 x(coord(rng), coord(rng), coord(rng));
            const double t = coord(rng);
            Eigen::Matrix3d fd;
            for (int j = 0; j < 3; ++j) {
                const Vec3 dx = step * Vec3::Unit(j);
                fd.col(j) = (field.velocity(x + dx, t) - field.velocity(x - dx, t)) / (2 * step);
            }
            const Eigen::Matrix3d g = field.velocity_gradient(x, t);
            const double scale = fd.norm();
            ASSERT_GT(scale, 0.0);
            worst_divergence = std::max(worst_divergence, std::abs(fd.trace()) / scale);
            worst_gradient = std::max(worst_gradient, (g - fd).norm() / scale);
            EXPECT_LT(std::abs(g.trace()), 1e-12 * g.norm());
            if (planar) {
                EXPECT_EQ(field.velocity(x, t).z(), 0.0);
            }
        }
        std::cout << "[ measured ] curl noise" << (planar ? " (planar)" : "")
                  << ": max |div u|_FD / |∇u| = " << worst_divergence
                  << ", max |∇u − FD| / |∇u| = " << worst_gradient << "\n";
        EXPECT_LT(worst_divergence, 1e-7);
        EXPECT_LT(worst_gradient, 1e-7);
    }
}

TEST(CurlNoise, VelocityIsTheCurlOfThePotential) {
    const CurlNoiseField field;
    const Vec3 x(0.3, -0.1, 0.7);
    const double step = 1e-5;
    Eigen::Matrix3d dpsi;  // dpsi(i, j) = ∂ψᵢ/∂xⱼ
    for (int j = 0; j < 3; ++j) {
        const Vec3 dx = step * Vec3::Unit(j);
        dpsi.col(j) = (field.potential(x + dx, 0.0) - field.potential(x - dx, 0.0)) / (2 * step);
    }
    const Vec3 curl(dpsi(2, 1) - dpsi(1, 2), dpsi(0, 2) - dpsi(2, 0), dpsi(1, 0) - dpsi(0, 1));
    EXPECT_LT((curl - field.velocity(x, 0.0)).norm(), 1e-7 * field.velocity(x, 0.0).norm());
}

TEST(CurlNoise, SeedReproducibleAndRmsSpeedAsRequested) {
    CurlNoiseOptions options;
    options.seed = 123;
    options.rms_speed = 2.0;
    const CurlNoiseField a(options), b(options);
    options.seed = 124;
    const CurlNoiseField c(options);
    std::mt19937_64 rng(3);
    std::uniform_real_distribution<double> coord(-5.0, 5.0);
    double sum_sq = 0.0;
    const int samples = 4000;
    for (int i = 0; i < samples; ++i) {
        const Vec3 x(coord(rng), coord(rng), coord(rng));
        EXPECT_EQ(a.velocity(x, 0.0), b.velocity(x, 0.0));
        if (i < 10) {
            EXPECT_NE(a.velocity(x, 0.0), c.velocity(x, 0.0));
        }
        sum_sq += a.velocity(x, 0.0).squaredNorm();
    }
    const double rms = std::sqrt(sum_sq / samples);
    std::cout << "[ measured ] curl noise sampled RMS speed " << rms << " (requested 2)\n";
    EXPECT_NEAR(rms, 2.0, 0.2);
    // Seed 1 at one point, pinned so that a change of the mode generator is noticed (the
    // engine's sequence and our transforms are fixed; only libm's sin/cos/log may round
    // differently).
    const Vec3 u = CurlNoiseField().velocity(Vec3(0.1, 0.2, 0.3), 0.0);
    EXPECT_LT((u - Vec3(-0.75997098276854835, 0.7760196192985982, -0.14080315452288916)).norm(),
              1e-12);
}

TEST(CurlNoise, Rk4AdvectionNearlyPreservesVolume) {
    CurlNoiseOptions options;
    options.rms_speed = 0.5;
    const CurlNoiseField field(options);
    SurfaceMesh mesh = meshed_sphere(Vec3(0.1, 0.0, -0.1), 0.2, 0.02);
    const double v0 = enclosed_volume(mesh);
    const double dt = 0.01;
    for (int s = 0; s < 20; ++s)
        displace(mesh, rk4_displacements(mesh, field, s * dt, dt));
    const double change = relative_volume_change(mesh, v0);
    std::cout << "[ measured ] curl noise RK4 20 steps of 0.01 s, ξ=0.02: relative volume change "
              << change << "\n";
    EXPECT_LT(std::abs(change), 5e-3);
}

TEST(CurlNoise, OptionsValidated) {
    CurlNoiseOptions options;
    options.octaves = 0;
    EXPECT_THROW(CurlNoiseField{options}, std::invalid_argument);
    options = {};
    options.base_wavelength = -1.0;
    EXPECT_THROW(CurlNoiseField{options}, std::invalid_argument);
}

// ---- exact solutions and error measures --------------------------------------------------

TEST(TwoSphereNormalFlow, ExactDistanceAtKnownPoints) {
    const TwoSphereNormalFlow flow;
    const double tol = 1e-14;
    // t = 0: two disjoint spheres of radius 0.2.
    EXPECT_NEAR(flow.signed_distance(Vec3(0.45, 0, 0), 0.0), 0.0, tol);
    EXPECT_NEAR(flow.signed_distance(Vec3(0.25, 0, 0), 0.0), -0.2, tol);
    EXPECT_NEAR(flow.signed_distance(Vec3(0, 0, 0), 0.0), 0.05, tol);
    // t = 0.5: radius 0.3, merged; ring at x = 0 of radius sqrt(0.3² − 0.25²).
    const double ring05 = std::sqrt(0.09 - 0.0625);
    EXPECT_NEAR(flow.signed_distance(Vec3(0.55, 0, 0), 0.5), 0.0, tol);
    EXPECT_NEAR(flow.signed_distance(Vec3(0, ring05, 0), 0.5), 0.0, tol);
    EXPECT_NEAR(flow.signed_distance(Vec3(0, 0, 0), 0.5), -ring05, tol);
    EXPECT_NEAR(flow.signed_distance(Vec3(0.25, 0, 0), 0.5), -0.3, tol);
    EXPECT_NEAR(flow.signed_distance(Vec3(1, 0, 0), 0.5), 0.45, tol);
    // t = 1: radius 0.4.
    const double ring1 = std::sqrt(0.16 - 0.0625);
    EXPECT_NEAR(flow.signed_distance(Vec3(0, 0, ring1), 1.0), 0.0, tol);
    EXPECT_NEAR(flow.signed_distance(Vec3(0, 0, 0), 1.0), -ring1, tol);
    EXPECT_NEAR(flow.signed_distance(Vec3(-0.65, 0, 0), 1.0), 0.0, tol);
    // t = 1.5: eroded by 0.1.
    EXPECT_NEAR(flow.signed_distance(Vec3(0.55, 0, 0), 1.5), 0.0, tol);
    EXPECT_NEAR(flow.signed_distance(Vec3(0, 0, 0), 1.5), 0.1 - ring1, tol);
    EXPECT_NEAR(flow.signed_distance(Vec3(0, ring1, 0), 1.5), 0.1, tol);
    // t = 2: eroded by 0.2 — the neck stays, of radius ring1 − 0.2 (not two r = 0.2 spheres).
    EXPECT_NEAR(flow.signed_distance(Vec3(0.45, 0, 0), 2.0), 0.0, tol);
    EXPECT_NEAR(flow.signed_distance(Vec3(0, ring1 - 0.2, 0), 2.0), 0.0, tol);
    EXPECT_NEAR(flow.signed_distance(Vec3(0, 0, 0), 2.0), 0.2 - ring1, tol);
    EXPECT_LT(flow.signed_distance(Vec3(0, 0, 0), 2.0), 0.0);  // inside: merged
    // (0, 0.3, 0) is inside U but within 0.2 of the ring: outside at t = 2.
    EXPECT_NEAR(flow.signed_distance(Vec3(0, 0.3, 0), 2.0), 0.2 - (ring1 - 0.3), tol);
    EXPECT_NEAR(flow.signed_distance(Vec3(0.25, 0, 0), 2.0), -0.2, tol);
    EXPECT_EQ(flow.normal_speed(0.5), 0.2);
    EXPECT_EQ(flow.normal_speed(1.5), -0.2);
    EXPECT_THROW(flow.signed_distance(Vec3::Zero(), -0.1), std::invalid_argument);
}

TEST(TwoSphereNormalFlow, UnionDistanceMatchesBruteForceOverTheBoundary) {
    // Dense samples of ∂U (sphere points outside the other ball, plus the ring).
    const Vec3 c0(-0.25, 0, 0), c1(0.25, 0, 0);
    const double r = 0.4;
    std::vector<Vec3> boundary;
    const int n = 60000;
    const double golden = M_PI * (3.0 - std::sqrt(5.0));
    for (const Vec3* c : {&c0, &c1}) {
        const Vec3& other = c == &c0 ? c1 : c0;
        for (int i = 0; i < n; ++i) {
            const double z = 1.0 - 2.0 * (i + 0.5) / n, rho = std::sqrt(1.0 - z * z);
            const Vec3 p = *c + r * Vec3(z, rho * std::cos(golden * i), rho * std::sin(golden * i));
            if ((p - other).norm() >= r)
                boundary.push_back(p);
        }
    }
    const double ring = std::sqrt(r * r - 0.0625);
    for (int i = 0; i < 2000; ++i) {
        const double phi = 2.0 * M_PI * i / 2000;
        boundary.push_back(Vec3(0, ring * std::cos(phi), ring * std::sin(phi)));
    }
    std::mt19937_64 rng(11);
    std::uniform_real_distribution<double> coord(-0.8, 0.8);
    double worst = 0.0;
    for (int s = 0; s < 300; ++s) {
        const Vec3 x(coord(rng), 0.6 * coord(rng), 0.6 * coord(rng));
        double brute = std::numeric_limits<double>::infinity();
        for (const Vec3& p : boundary)
            brute = std::min(brute, (x - p).norm());
        const double exact = two_ball_union_signed_distance(x, c0, c1, r);
        const bool inside = (x - c0).norm() < r || (x - c1).norm() < r;
        EXPECT_EQ(exact < 0.0, inside);
        worst = std::max(worst, std::abs(std::abs(exact) - brute));
        EXPECT_LE(std::abs(exact), brute + 1e-12);  // sampled boundary: brute ≥ exact
    }
    EXPECT_LT(worst, 0.006);  // sample spacing ≈ r·sqrt(4π/n) ≈ 0.006
}

TEST(SurfaceErrorMeasure, ExactSphereSampleHasZeroVertexError) {
    const double r0 = 0.3, t = 0.01;
    const double radius = sphere_mean_curvature_radius(r0, t);
    EXPECT_NEAR(radius, std::sqrt(0.09 - 0.04), 1e-15);
    SurfaceMesh mesh = meshed_sphere(Vec3(0.1, 0.1, 0.1), radius, 0.02);
    project_to_sphere(mesh, Vec3(0.1, 0.1, 0.1), radius);
    const SurfaceError e = sphere_error(mesh, Vec3(0.1, 0.1, 0.1), radius);
    EXPECT_LT(e.vertex_linf, 1e-15);
    EXPECT_LT(e.vertex_l1, 1e-15);
    // Chords cut inside the sphere by at most ℓ²/(8R); L1 is a fraction of that.
    const double longest = edge_length_stats(mesh).max;
    EXPECT_GT(e.linf, 0.0);
    EXPECT_LE(e.linf, longest * longest / (4.0 * radius));
    EXPECT_LT(e.l1, e.linf);
    EXPECT_NEAR(e.area, surface_area(mesh), 1e-12);
    EXPECT_THROW(sphere_mean_curvature_radius(r0, 0.03), std::invalid_argument);
}

TEST(SurfaceErrorMeasure, L1IsTheAreaWeightedMeanDistance) {
    // A flat unit square 0.1 above the plane z = 0: every sample is at distance 0.1.
    const SurfaceMesh square({{0, 0, 0.1}, {1, 0, 0.1}, {1, 1, 0.1}, {0, 1, 0.1}},
                             {{0, 1, 2}, {0, 2, 3}});
    auto plane = [](const Vec3& x) { return x.z(); };
    SurfaceError e = surface_error(square, plane);
    EXPECT_NEAR(e.l1, 0.1, 1e-15);
    EXPECT_NEAR(e.linf, 0.1, 1e-15);
    EXPECT_EQ(e.samples, 4 + 2 * (16 + 12));  // vertices + m² centroids + non-corner lattice
    // A tilted square z = x: mean of |x| over the unit square is 1/2 (midpoint rule exact).
    const SurfaceMesh tilted({{0, 0, 0}, {1, 0, 1}, {1, 1, 1}, {0, 1, 0}}, {{0, 1, 2}, {0, 2, 3}});
    e = surface_error(tilted, plane);
    EXPECT_NEAR(e.l1, 0.5, 1e-14);
    EXPECT_NEAR(e.linf, 1.0, 1e-15);
    // Vertex L1: areas/3 per corner; triangle (0,1,2) has |φ| = 0, 1, 1 and (0,2,3) 0, 1, 0.
    EXPECT_NEAR(e.vertex_l1, (0.5 / 3.0) * (0 + 1 + 1) + (0.5 / 3.0) * (0 + 1 + 0), 1e-15);
    EXPECT_NEAR(relative_volume_change(2.0, 2.1), 0.05, 1e-15);
    EXPECT_THROW(relative_volume_change(0.0, 1.0), std::invalid_argument);
    SurfaceErrorOptions bad;
    bad.triangle_subdivisions = 0;
    EXPECT_THROW(surface_error(square, plane, bad), std::invalid_argument);
}

// ---- flow runner -------------------------------------------------------------------------

TEST(FlowRunner, FaceOffsettingSphereFollowsExactRadiusBothWays) {
    const Vec3 center(0.25, 0.0, 0.0);
    const double r0 = 0.2, speed = 0.2, t_end = 0.5;
    for (double sign : {1.0, -1.0}) {
        std::vector<double> errors, mean_edges;
        for (double xi : {0.04, 0.02}) {
            SurfaceMesh mesh = meshed_sphere(center, r0, xi);
            project_to_sphere(mesh, center, r0);
            mean_edges.push_back(edge_length_stats(mesh).mean);
            const FaceOffsettingStepper stepper([&](double) { return sign * speed; });
            const FlowRunReport report = run_flow(mesh, stepper, 0.0, t_end);
            EXPECT_EQ(report.stop, FlowRunStop::reached_end);
            EXPECT_EQ(report.t, t_end);
            EXPECT_EQ(report.steps, 100);
            EXPECT_EQ(report.shortened_steps, 0);
            const SurfaceError e = sphere_error(mesh, center, r0 + sign * speed * t_end);
            errors.push_back(e.vertex_linf);
            std::cout << "[ measured ] face offsetting sphere 0.2 → " << r0 + sign * speed * t_end
                      << ", ξ=" << mean_edges.back() << ", 100 steps: vertex L∞ " << e.vertex_linf
                      << ", L∞ " << e.linf << ", L1 " << e.l1 << "\n";
            EXPECT_LT(e.vertex_linf, 0.02 * speed * t_end);
        }
        // Second order, or exact to 1e-4 of the distance travelled (the mean-normal move of
        // smooth vertices is exact on a sphere up to the tilt of irregular fans).
        const double order = observed_order(errors[0], errors[1], mean_edges[0], mean_edges[1]);
        EXPECT_TRUE(order > 1.5 || errors[0] < 1e-4 * speed * t_end) << "order " << order;
    }
}

TEST(FlowRunner, ShrinkingSphereVerticesDoNotDriftInsideTheExactSphere) {
    // Issue #5: on a shrinking sphere the planes' intersection moves each vertex by h / cos θ
    // (θ the spread of its face normals) instead of h; the excess accumulates step after step
    // into a uniform inward bias (A1: 1.1e-3 at ξ = 0.04 after 1 s of shrinking). Smooth
    // vertices take the mean offset along the mean normal instead.
    const Vec3 center(0.25, 0.0, 0.0);
    const double r0 = 0.4, speed = -0.2, t_end = 1.0;
    double mean_error[2] = {0.0, 0.0};
    for (int rule = 0; rule < 2; ++rule) {
        SurfaceMesh mesh = meshed_sphere(center, r0, 0.04);
        project_to_sphere(mesh, center, r0);
        FaceOffsettingOptions options;
        options.smooth_dihedral_degrees = rule == 0 ? 0.0 : 20.0;  // 0: planes wherever convex
        const FaceOffsettingStepper stepper([&](double) { return speed; }, options);
        const FlowRunReport report = run_flow(mesh, stepper, 0.0, t_end);
        EXPECT_EQ(report.stop, FlowRunStop::reached_end);
        const double exact = r0 + speed * t_end;
        int live = 0;
        for (int vi = 0; vi < mesh.num_vertices(); ++vi)
            if (mesh.vertex_alive(vi)) {
                mean_error[rule] += (mesh.position(vi) - center).norm() - exact;
                ++live;
            }
        mean_error[rule] /= live;
    }
    std::cout << "[ measured ] sphere 0.4 → 0.2, ξ = 0.04: mean signed vertex error, planes "
              << mean_error[0] << ", smooth rule " << mean_error[1] << "\n";
    EXPECT_LT(mean_error[0], -2e-4);
    EXPECT_LT(std::abs(mean_error[1]), 0.25 * std::abs(mean_error[0]));
}

TEST(FlowRunner, NeckFaceOffsettingConvergesWhereVertexNormalsDoNot) {
    // Two overlapping balls expanding: characteristics merge at the concave ring (a shock).
    // Exact solution: the union of the two balls of radius r + s t (TwoSphereNormalFlow with
    // centres ±a). Face offsetting tracks it; vertex normals lag at the ring by
    // s t (1/cos θ − 1) whatever the resolution (paper Fig. 4.2).
    TwoSphereNormalFlow flow;
    const double a = 0.1;
    flow.center0 = Vec3(-a, 0, 0);
    flow.center1 = Vec3(a, 0, 0);
    flow.initial_radius = 0.3;
    flow.reversal_time = 1.0;
    const double t_end = 0.1;  // s t = 0.02
    std::vector<double> fo_errors, vn_errors, xis;
    for (double xi : {0.04, 0.02, 0.01}) {
        const SurfaceMesh initial = peanut_mesh(a, flow.initial_radius, xi);
        ASSERT_LT(two_sphere_normal_flow_error(initial, flow, 0.0).vertex_linf, 1e-15);
        SurfaceMesh fo = initial, vn = initial;
        const NormalSpeed speed = [&flow](double t) { return flow.normal_speed(t); };
        const FlowRunReport fo_report = run_flow(fo, FaceOffsettingStepper(speed), 0.0, t_end);
        const FlowRunReport vn_report = run_flow(vn, VertexNormalStepper(speed), 0.0, t_end);
        EXPECT_EQ(fo_report.stop, FlowRunStop::reached_end);
        EXPECT_EQ(vn_report.stop, FlowRunStop::reached_end);
        fo_errors.push_back(two_sphere_normal_flow_error(fo, flow, t_end).vertex_linf);
        vn_errors.push_back(two_sphere_normal_flow_error(vn, flow, t_end).vertex_linf);
        xis.push_back(edge_length_stats(initial).mean);
        std::cout << "[ measured ] expanding neck ξ=" << xis.back()
                  << ": vertex L∞ face offsetting " << fo_errors.back() << ", vertex normals "
                  << vn_errors.back() << "\n";
    }
    const double fo_order = observed_order(fo_errors[0], fo_errors[2], xis[0], xis[2]);
    const double vn_order = observed_order(vn_errors[0], vn_errors[2], xis[0], xis[2]);
    std::cout << "[ measured ] observed order: face offsetting " << fo_order << ", vertex normals "
              << vn_order << "\n";
    EXPECT_GT(fo_order, 0.8);
    EXPECT_LT(std::abs(vn_order), 0.2);
    EXPECT_LT(fo_errors.back(), 0.2 * vn_errors.back());
}

TEST(FlowRunner, ShrinkingNeckNeedsTheHuygensRuleToConverge) {
    // Two overlapping balls moving inward: the concave ring opens an expansion fan; the exact
    // solution is the erosion {dist(x, complement of U) > s t} with a rounded neck
    // (TwoSphereNormalFlow with the reversal at t = 0). The plane-intersection rule keeps the
    // crease sharp and overshoots by s t (1/cos θ − 1) at every resolution.
    TwoSphereNormalFlow flow;
    const double a = 0.1;
    flow.center0 = Vec3(-a, 0, 0);
    flow.center1 = Vec3(a, 0, 0);
    flow.initial_radius = 0.3;
    flow.reversal_time = 0.0;
    const double t_end = 0.1;  // s t = 0.02
    FaceOffsettingOptions planes;
    planes.expansion = ExpansionRule::planes;
    std::vector<double> huygens_errors, planes_errors, xis;
    for (double xi : {0.04, 0.02, 0.01}) {
        const SurfaceMesh initial = peanut_mesh(a, flow.initial_radius, xi);
        SurfaceMesh huygens = initial, sharp = initial;
        const NormalSpeed speed = [&flow](double t) { return flow.normal_speed(t); };
        EXPECT_EQ(run_flow(huygens, FaceOffsettingStepper(speed), 0.0, t_end).stop,
                  FlowRunStop::reached_end);
        EXPECT_EQ(run_flow(sharp, FaceOffsettingStepper(speed, planes), 0.0, t_end).stop,
                  FlowRunStop::reached_end);
        huygens_errors.push_back(two_sphere_normal_flow_error(huygens, flow, t_end).vertex_linf);
        planes_errors.push_back(two_sphere_normal_flow_error(sharp, flow, t_end).vertex_linf);
        xis.push_back(edge_length_stats(initial).mean);
        std::cout << "[ measured ] shrinking neck ξ=" << xis.back() << ": vertex L∞ Huygens rule "
                  << huygens_errors.back() << ", plane rule " << planes_errors.back() << "\n";
    }
    const double huygens_order =
        observed_order(huygens_errors[0], huygens_errors[2], xis[0], xis[2]);
    const double planes_order = observed_order(planes_errors[0], planes_errors[2], xis[0], xis[2]);
    std::cout << "[ measured ] observed order: Huygens rule " << huygens_order << ", plane rule "
              << planes_order << "\n";
    // Second order, or exact to rounding of the mesh's own tilt: since smooth vertices take the
    // mean-normal move (issue #5) the ball parts no longer carry the plane rule's O(ξ²) excess.
    const double travelled = flow.speed * t_end;
    const bool all_within =
        *std::max_element(huygens_errors.begin(), huygens_errors.end()) < 1e-3 * travelled;
    EXPECT_TRUE(huygens_order > 1.5 || all_within) << "order " << huygens_order;
    EXPECT_LT(huygens_errors.back(), 0.02 * planes_errors.back());
    EXPECT_GT(planes_errors.back(), 0.9 * planes_errors.front());  // no convergence
}

TEST(FlowRunner, MeanCurvatureStepsAreCflLimited) {
    SurfaceMesh mesh = meshed_sphere(Vec3::Zero(), 0.3, 0.04);
    project_to_sphere(mesh, Vec3::Zero(), 0.3);
    const double t_end = 0.005;
    const FlowRunReport report = run_flow(mesh, MeanCurvatureStepper(), 0.0, t_end);
    EXPECT_EQ(report.stop, FlowRunStop::reached_end);
    EXPECT_GT(report.shortened_steps, 0);
    EXPECT_LE(report.max_dt, MeanCurvatureFlowOptions{}.cfl_number * 0.04 * 0.04);
    const SurfaceError e =
        sphere_error(mesh, Vec3::Zero(), sphere_mean_curvature_radius(0.3, t_end));
    EXPECT_LT(e.vertex_linf, 1e-3);
}

TEST(FlowRunner, IntegratorMayApplyPartOfTheMotion) {
    /// Uniform translation along +x at 1 m/s.
    class Uniform final : public VelocityField {
    public:
        Vec3 velocity(const Vec3&, double) const override { return Vec3::UnitX(); }
    };
    const Uniform field;
    SurfaceMesh mesh = cube_mesh(0.1, 1);
    const Vec3 start = mesh.position(0);
    int hook_calls = 0;
    FlowRunOptions options;
    options.max_dt = 0.01;
    // A cautious integrator: applies only half of the motion of full-length steps.
    const FlowIntegrator half = [](SurfaceMesh& m, const std::vector<Vec3>& d, double dt) {
        const double fraction = dt > 0.006 ? 0.5 : 1.0;
        std::vector<Vec3> part = d;
        for (Vec3& v : part)
            v *= fraction;
        move_vertices(m, part, dt);
        return fraction * dt;
    };
    const FlowRunReport report =
        run_flow(mesh, VelocityFieldStepper(field), 0.0, 0.1, options, half,
                 [&hook_calls](SurfaceMesh&, double) { ++hook_calls; });
    EXPECT_EQ(report.stop, FlowRunStop::reached_end);
    EXPECT_EQ(report.t, 0.1);
    EXPECT_EQ(report.steps, 20);  // twice as many as 0.1 / 0.01
    EXPECT_EQ(report.partial_steps, 19);
    EXPECT_EQ(hook_calls, report.steps);
    EXPECT_NEAR((mesh.position(0) - start).x(), 0.1, 1e-12);

    // An integrator that never moves anything stalls the run, which is reported.
    const FlowIntegrator stuck = [](SurfaceMesh&, const std::vector<Vec3>&, double) { return 0.0; };
    const FlowRunReport stalled =
        run_flow(mesh, VelocityFieldStepper(field), 0.0, 0.1, options, stuck);
    EXPECT_EQ(stalled.stop, FlowRunStop::step_stalled);
    EXPECT_EQ(stalled.steps, 1);
    options.max_steps = 3;
    EXPECT_EQ(run_flow(mesh, VelocityFieldStepper(field), 0.0, 0.1, options).stop,
              FlowRunStop::max_steps);
    EXPECT_THROW(run_flow(mesh, VelocityFieldStepper(field), 0.1, 0.1), std::invalid_argument);
}

}  // namespace
}  // namespace meniscus::tracker
