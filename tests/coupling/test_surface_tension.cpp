// Curvature at face crossings from the mesh: a sphere gives 2/R (converging with refinement),
// a bubble −2/R, and an end-to-end static drop through FluidSolver has the Laplace jump 2σ/R.
#include "coupling/surface_tension.h"

#include "fluid/fluid_solver.h"
#include "tracker/flows/mean_curvature.h"
#include "tracker/implicit_mesher.h"
#include "tracker/implicit_shape.h"
#include "tracker/mesh_measures.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <vector>

namespace meniscus::coupling {
namespace {

using Eigen::Vector3d;

tracker::SurfaceMesh sphere_mesh(const Vector3d& centre, double radius, double edge_length) {
    tracker::ImplicitMeshOptions options;
    options.edge_length = edge_length;
    return tracker::mesh_implicit_shape(*tracker::make_sphere(centre, radius), options);
}

/// Mean and max of |κ/(2/R) − 1| over the crossed faces.
struct CurvatureError {
    double mean = 0.0;
    double max = 0.0;
    long long faces = 0;
};

CurvatureError sphere_curvature_error(const fluid::InterfaceInput& in, double exact) {
    CurvatureError error;
    double sum = 0.0;
    for (int axis = 0; axis < 3; ++axis) {
        const fluid::Array3<double>& kappa = in.kappa(axis);
        const int di = axis == 0, dj = axis == 1, dk = axis == 2;
        for (int k = dk; k < kappa.nk() - dk; ++k)
            for (int j = dj; j < kappa.nj() - dj; ++j)
                for (int i = di; i < kappa.ni() - di; ++i) {
                    if (fluid::is_liquid(in.phi(i - di, j - dj, k - dk)) ==
                        fluid::is_liquid(in.phi(i, j, k)))
                        continue;
                    const double e = std::abs(kappa(i, j, k) / exact - 1.0);
                    sum += e;
                    error.max = std::max(error.max, e);
                    ++error.faces;
                }
    }
    error.mean = error.faces > 0 ? sum / static_cast<double>(error.faces) : 0.0;
    return error;
}

TEST(SurfaceTension, SphereCurvatureAtCrossingsIsTwoOverR) {
    // The mesher puts the vertices on the sphere, so the cotangent curvature is accurate at
    // every resolution; its pointwise scatter does not shrink (Meyer et al.'s operator is not
    // pointwise convergent on irregular meshes) but stays at a few per cent.
    const double radius = 0.3;
    const Vector3d centre(0.503, 0.497, 0.511);
    for (int n : {16, 32, 64}) {
        const fluid::MacGrid grid(n, n, n, 1.0 / n);
        const tracker::SurfaceMesh mesh = sphere_mesh(centre, radius, 1.0 / n);
        SurfaceTensionResult result;
        const fluid::InterfaceInput in = interface_from_mesh(mesh, grid, {}, {}, &result);
        EXPECT_EQ(result.faces_without_triangle, 0);
        const CurvatureError error = sphere_curvature_error(in, 2.0 / radius);
        EXPECT_EQ(error.faces, result.crossed_faces);
        std::printf(
            "sphere, %5.1f cells per diameter, edge = dx: %lld crossed faces, "
            "|kappa R/2 - 1| mean %.5f max %.4f (faces %.4f s)\n",
            2.0 * radius * n, error.faces, error.mean, error.max, result.face_seconds);
        EXPECT_LT(error.mean, 0.005);
        EXPECT_LT(error.max, 0.05);
    }
}

/// κ (1/m, sum of principal curvatures, outward normal) of the ellipsoid Σ (xᵢ/aᵢ)² = 1 centred
/// at the origin, at its point p: div(∇F/|∇F|) with F = Σ (xᵢ/aᵢ)².
double ellipsoid_curvature(const Vector3d& radii, const Vector3d& p) {
    const Vector3d inverse_squares = radii.cwiseProduct(radii).cwiseInverse();
    const Vector3d half_gradient = p.cwiseProduct(inverse_squares);
    const double g2 = half_gradient.squaredNorm();
    return (g2 * inverse_squares.sum() -
            half_gradient.cwiseProduct(half_gradient).dot(inverse_squares)) /
           std::pow(g2, 1.5);
}

TEST(SurfaceTension, EllipsoidCurvatureAtCrossingsConvergesUnderRefinement) {
    // κ varies over the surface, so where each crossing samples the mesh matters. Mesh edge = dx.
    const Vector3d centre(0.503, 0.497, 0.511);
    const Vector3d radii(0.32, 0.24, 0.18);
    const tracker::ShapePtr shape = tracker::make_ellipsoid(centre, radii);
    constexpr int PROJECTION_STEPS = 20;
    std::vector<double> rms_errors;
    for (int n : {16, 32, 64}) {
        const fluid::MacGrid grid(n, n, n, 1.0 / n);
        tracker::ImplicitMeshOptions mesher;
        mesher.edge_length = 1.0 / n;
        const tracker::SurfaceMesh mesh = tracker::mesh_implicit_shape(*shape, mesher);
        const fluid::InterfaceInput in = interface_from_mesh(mesh, grid);
        double sum_squares = 0.0;
        double max_error = 0.0;
        long long faces = 0;
        for (int axis = 0; axis < 3; ++axis) {
            const fluid::Array3<double>& kappa = in.kappa(axis);
            const int di = axis == 0, dj = axis == 1, dk = axis == 2;
            for (int k = dk; k < kappa.nk() - dk; ++k)
                for (int j = dj; j < kappa.nj() - dj; ++j)
                    for (int i = di; i < kappa.ni() - di; ++i) {
                        const double phi_lo = in.phi(i - di, j - dj, k - dk);
                        const double phi_hi = in.phi(i, j, k);
                        if (fluid::is_liquid(phi_lo) == fluid::is_liquid(phi_hi))
                            continue;
                        const Vector3d x_lo = grid.cell_centre(i - di, j - dj, k - dk);
                        const Vector3d x =
                            x_lo + phi_lo / (phi_lo - phi_hi) * (grid.cell_centre(i, j, k) - x_lo);
                        const Vector3d on_surface =
                            tracker::project_to_zero_set(*shape, x, PROJECTION_STEPS);
                        const double exact = ellipsoid_curvature(radii, on_surface - centre);
                        const double error = kappa(i, j, k) / exact - 1.0;
                        sum_squares += error * error;
                        max_error = std::max(max_error, std::abs(error));
                        ++faces;
                    }
        }
        const double rms = std::sqrt(sum_squares / static_cast<double>(faces));
        std::printf(
            "ellipsoid, dx = 1/%d, edge = dx: relative kappa error rms %.4f max %.4f "
            "over %lld crossed faces\n",
            n, rms, max_error, faces);
        EXPECT_LT(max_error, 0.1);
        rms_errors.push_back(rms);
    }
    for (size_t r = 1; r < rms_errors.size(); ++r)
        EXPECT_LT(rms_errors[r], rms_errors[r - 1]);
    EXPECT_LT(rms_errors.back(), 0.01);
}

TEST(SurfaceTension, SmoothingReducesTheScatterOfAnIrregularMesh) {
    const int n = 32;
    const double radius = 0.3;
    const fluid::MacGrid grid(n, n, n, 1.0 / n);
    // A mesh much finer than the grid: the cotangent curvature scatters at the mesh scale.
    const tracker::SurfaceMesh mesh = sphere_mesh(Vector3d::Constant(0.5), radius, 0.25 / n);
    const fluid::InterfaceInput raw = interface_from_mesh(mesh, grid);
    SurfaceTensionOptions smooth_options;
    smooth_options.smoothing_passes = 4;
    const fluid::InterfaceInput smooth = interface_from_mesh(mesh, grid, {}, smooth_options);
    const CurvatureError raw_error = sphere_curvature_error(raw, 2.0 / radius);
    const CurvatureError smooth_error = sphere_curvature_error(smooth, 2.0 / radius);
    std::printf("edge = dx/4: max |kappa R/2 - 1| raw %.4f, after 4 smoothing passes %.4f\n",
                raw_error.max, smooth_error.max);
    EXPECT_LE(smooth_error.max, raw_error.max);
    EXPECT_LT(smooth_error.mean, 0.03);
}

/// The roughest per-vertex pattern of `mesh`: power iteration on x ← x − (unweighted neighbour
/// mean of x), whose dominant eigenvector alternates in sign at the scale of one edge.
std::vector<double> roughest_pattern(const tracker::SurfaceMesh& mesh) {
    std::vector<double> x(static_cast<size_t>(mesh.num_vertices()));
    for (size_t v = 0; v < x.size(); ++v)
        x[v] = std::sin(12.9898 * static_cast<double>(v) + 78.233);  // deterministic noise
    std::vector<double> y(x.size());
    for (int iteration = 0; iteration < 300; ++iteration) {
        double norm = 0.0;
        for (int vi = 0; vi < mesh.num_vertices(); ++vi) {
            double mean = 0.0;
            for (int ei : mesh.vertex_edges(vi))
                mean += x[static_cast<size_t>(mesh.other_vertex(ei, vi))];
            mean /= static_cast<double>(mesh.vertex_edges(vi).size());
            y[static_cast<size_t>(vi)] = x[static_cast<size_t>(vi)] - mean;
            norm += y[static_cast<size_t>(vi)] * y[static_cast<size_t>(vi)];
        }
        norm = std::sqrt(norm);
        for (size_t v = 0; v < x.size(); ++v)
            x[v] = y[v] / norm;
    }
    return x;
}

TEST(SurfaceTension, SmoothingKeepsTheCapillaryForceOnMeshScaleWrinklesRestoring) {
    // Regression: the closed one-ring mean (vertex weighted like its ~6 neighbours) mapped the
    // mesh-scale pattern to about −0.27 times itself, so with 1 (or 3) passes a mesh-scale
    // wrinkle pushed outward got a *lower* κ there: the capillary force drove the wrinkle
    // instead of flattening it and the coupled oscillating drop blew up (max speed 0.024 m/s at
    // 2 ms, 0.41 m/s at 4 ms). The lazy pass damps every pattern by a factor in [0, 1].
    const double radius = 0.3;
    const double edge = 1.0 / 32;
    const tracker::SurfaceMesh mesh = sphere_mesh(Vector3d::Constant(0.5), radius, edge);
    const std::vector<double> pattern = roughest_pattern(mesh);
    const std::vector<double> area = tracker::mixed_voronoi_areas(mesh);
    const auto dot = [&](const std::vector<double>& a, const std::vector<double>& b) {
        double sum = 0.0;
        for (size_t v = 0; v < a.size(); ++v)
            sum += area[v] * a[v] * b[v];
        return sum;
    };
    for (int passes : {1, 2, 3}) {
        // Transfer of the smoothing on that pattern: the one-pass factor raised to `passes`.
        const double transfer =
            dot(pattern, smooth_vertex_values(mesh, pattern, passes)) / dot(pattern, pattern);
        std::printf("%d smoothing passes: transfer on the mesh-scale pattern %+.4f\n", passes,
                    transfer);
        EXPECT_GE(transfer, 0.0) << passes << " passes";
        EXPECT_LT(transfer, 1.0) << passes << " passes";
    }
    // Bump the sphere outward along that pattern by 1 % of an edge: κ (liquid inside, a drop)
    // must rise where the surface moved out, before and after smoothing.
    tracker::SurfaceMesh bumped = mesh;
    double largest = 0.0;
    for (double value : pattern)
        largest = std::max(largest, std::abs(value));
    for (int vi = 0; vi < mesh.num_vertices(); ++vi) {
        const Vector3d outward = (mesh.position(vi) - Vector3d::Constant(0.5)).normalized();
        bumped.set_position(vi, mesh.position(vi) + 0.01 * edge * pattern[static_cast<size_t>(vi)] /
                                                        largest * outward);
    }
    for (int passes : {0, 1, 2, 3}) {
        const std::vector<double> before = liquid_vertex_curvatures(mesh, 1, passes);
        const std::vector<double> after = liquid_vertex_curvatures(bumped, 1, passes);
        std::vector<double> change(before.size());
        for (size_t v = 0; v < change.size(); ++v)
            change[v] = after[v] - before[v];
        EXPECT_GT(dot(pattern, change), 0.0) << passes << " passes: the wrinkle is not restored";
    }
}

TEST(SurfaceTension, SubgridTensionFlattensMeshScaleWrinklesAndSparesTheSphere) {
    // The sub-grid velocity −D (K − S(K)) is mean-curvature flow restricted to what S removes:
    // a mesh-scale wrinkle decays, the sphere itself (K resolved) hardly moves and the volume
    // stays put.
    const double radius = 0.3;
    const double edge = 1.0 / 32;
    const Vector3d centre = Vector3d::Constant(0.5);
    const tracker::SurfaceMesh sphere = sphere_mesh(centre, radius, edge);
    const int passes = SurfaceTensionOptions{}.subgrid_resolved_passes;
    const int order = SurfaceTensionOptions{}.subgrid_filter_order;
    const double diffusivity = 1.0;
    const double dt = 0.05 * edge * edge / diffusivity;  // rate β = D Δt / h² = 0.05 per step
    // On the smooth sphere the sub-grid speed is a small fraction of the full flow speed κ·D.
    double sphere_speed = 0.0;
    for (const tracker::Vec3& v : subgrid_tension_velocities(sphere, diffusivity, passes, order))
        sphere_speed = std::max(sphere_speed, v.norm());
    std::printf("sub-grid speed on a sphere: %.4f of the mean-curvature flow speed\n",
                sphere_speed / (diffusivity * 2.0 / radius));
    EXPECT_LT(sphere_speed, 0.1 * diffusivity * 2.0 / radius);

    // Wrinkle: the roughest vertex pattern, 10 % of an edge radially.
    const std::vector<double> pattern = roughest_pattern(sphere);
    double largest = 0.0;
    for (double value : pattern)
        largest = std::max(largest, std::abs(value));
    tracker::SurfaceMesh wrinkled = sphere;
    for (int vi = 0; vi < sphere.num_vertices(); ++vi) {
        const Vector3d outward = (sphere.position(vi) - centre).normalized();
        wrinkled.set_position(vi, sphere.position(vi) + 0.1 * edge *
                                                            pattern[static_cast<size_t>(vi)] /
                                                            largest * outward);
    }
    const auto rms_radial_error = [&](const tracker::SurfaceMesh& mesh) {
        double sum = 0.0;
        for (int vi = 0; vi < mesh.num_vertices(); ++vi) {
            const double error =
                (mesh.position(vi) - centre).norm() - (sphere.position(vi) - centre).norm();
            sum += error * error;
        }
        return std::sqrt(sum / mesh.num_vertices());
    };
    const double error0 = rms_radial_error(wrinkled);
    const double volume0 = tracker::enclosed_volume(wrinkled);
    const int steps = 20;
    for (int step = 0; step < steps; ++step) {
        const std::vector<tracker::Vec3> velocity =
            subgrid_tension_velocities(wrinkled, diffusivity, passes, order);
        for (int vi = 0; vi < wrinkled.num_vertices(); ++vi)
            wrinkled.set_position(vi,
                                  wrinkled.position(vi) + dt * velocity[static_cast<size_t>(vi)]);
    }
    const double error1 = rms_radial_error(wrinkled);
    std::printf(
        "mesh-scale wrinkle: rms radial deviation %.3g -> %.3g edges in %d steps, volume "
        "change %.2e\n",
        error0 / edge, error1 / edge, steps, tracker::enclosed_volume(wrinkled) / volume0 - 1.0);
    EXPECT_LT(error1, 0.2 * error0);
    EXPECT_NEAR(tracker::enclosed_volume(wrinkled), volume0, 1e-4 * volume0);
    EXPECT_THROW(subgrid_tension_velocities(sphere, -1.0, passes, order), std::invalid_argument);
    EXPECT_THROW(subgrid_tension_velocities(sphere, 1.0, 0, order), std::invalid_argument);
}

TEST(SurfaceTension, SquaredSubgridFilterSparesResolvedWavesAndDampsWrinklesAlike) {
    // Regression for B4 (the capillary wave 5 % slow at 32 cells per wavelength): a resolved
    // pattern that the smoothing S keeps to 1 − ε leaks through the first-order high-pass
    // I − S as about ε and damps the resolved wave; through (I − S)² only ε². On a sphere with
    // ~20 edges per radius, a degree-3 spherical harmonic (a smooth, resolved wrinkle) and the
    // roughest pattern the mesh carries (mesh scale), each 5 % of an edge radially.
    const double radius = 0.3;
    const double edge = 1.0 / 64;
    const Vector3d centre = Vector3d::Constant(0.5);
    const tracker::SurfaceMesh sphere = sphere_mesh(centre, radius, edge);
    const int passes = SurfaceTensionOptions{}.subgrid_resolved_passes;
    const std::vector<double> roughest = roughest_pattern(sphere);
    const auto perturbed = [&](const std::function<double(int, const Vector3d&)>& pattern) {
        tracker::SurfaceMesh mesh = sphere;
        for (int vi = 0; vi < sphere.num_vertices(); ++vi) {
            const Vector3d n = (sphere.position(vi) - centre).normalized();
            mesh.set_position(vi, sphere.position(vi) + 0.05 * edge * pattern(vi, n) * n);
        }
        return mesh;
    };
    // The response of the radial sub-grid speed to the pattern (the unperturbed sphere's own
    // speed, its mesh-scale curvature noise, subtracted), projected on the pattern per unit
    // amplitude: the rate at which the filter damps it, per unit diffusivity.
    const auto damping = [&](const tracker::SurfaceMesh& mesh,
                             const std::function<double(int, const Vector3d&)>& pattern,
                             int order) {
        const std::vector<tracker::Vec3> v = subgrid_tension_velocities(mesh, 1.0, passes, order);
        const std::vector<tracker::Vec3> v0 =
            subgrid_tension_velocities(sphere, 1.0, passes, order);
        double along = 0.0, norm = 0.0;
        for (int vi = 0; vi < mesh.num_vertices(); ++vi) {
            const Vector3d n = (sphere.position(vi) - centre).normalized();
            const double p = pattern(vi, n);
            along += (v[static_cast<size_t>(vi)] - v0[static_cast<size_t>(vi)]).dot(n) * p;
            norm += p * p;
        }
        return -along / norm / (0.05 * edge);
    };
    const auto harmonic = [](int, const Vector3d& n) {
        return n.z() * (5.0 * n.z() * n.z() - 3.0);  // P₃(cos θ) up to a factor
    };
    const auto rough = [&](int vi, const Vector3d&) {
        return roughest[static_cast<size_t>(vi)];
    };
    const tracker::SurfaceMesh smooth_wrinkle = perturbed(harmonic);
    const tracker::SurfaceMesh mesh_wrinkle = perturbed(rough);
    const double smooth1 = damping(smooth_wrinkle, harmonic, 1);
    const double smooth2 = damping(smooth_wrinkle, harmonic, 2);
    const double rough1 = damping(mesh_wrinkle, rough, 1);
    const double rough2 = damping(mesh_wrinkle, rough, 2);
    std::printf("damping rate per unit D: P3 wrinkle %.4g (order 1) %.4g (order 2); mesh-scale "
                "%.4g, %.4g\n",
                smooth1, smooth2, rough1, rough2);
    // The mesh-scale pattern is damped at nearly the same rate; the resolved one far less.
    EXPECT_GT(rough2, 0.8 * rough1);
    EXPECT_GT(rough2, 0.0);
    EXPECT_LT(std::abs(smooth2), 0.1 * std::abs(smooth1));
    EXPECT_THROW(subgrid_tension_velocities(sphere, 1.0, passes, 0), std::invalid_argument);
    EXPECT_THROW(subgrid_tension_velocities(sphere, 1.0, passes, 4), std::invalid_argument);
}

TEST(SurfaceTension, SubgridTensionMovesOnlyActiveVerticesAndKeepsTheirVolume) {
    // Regression: a surface reaching past the fluid walls (the capillary-wave slab cut by a box
    // beyond the walls) has sharp creases outside the domain. Damping them moved the whole
    // component through the volume-neutral term and shrank B3's growth rate by 29 % and B4's
    // frequency by 17 %. Only flagged vertices move now, and they alone carry the volume
    // balance.
    tracker::ImplicitMeshOptions options;
    options.edge_length = 0.05;
    const tracker::SurfaceMesh box = tracker::mesh_implicit_shape(
        *tracker::make_box(Vector3d::Constant(0.2), Vector3d::Constant(0.8)), options);
    std::vector<char> active(static_cast<size_t>(box.num_vertices()), 0);
    for (int vi = 0; vi < box.num_vertices(); ++vi)
        active[static_cast<size_t>(vi)] = box.position(vi).x() < 0.5 ? 1 : 0;
    const std::vector<tracker::Vec3> velocity =
        subgrid_tension_velocities(box, 1.0, SurfaceTensionOptions{}.subgrid_resolved_passes,
                                   SurfaceTensionOptions{}.subgrid_filter_order, active);
    const std::vector<tracker::Vec3> all =
        subgrid_tension_velocities(box, 1.0, SurfaceTensionOptions{}.subgrid_resolved_passes,
                                   SurfaceTensionOptions{}.subgrid_filter_order);
    double moved = 0.0;
    for (int vi = 0; vi < box.num_vertices(); ++vi) {
        if (active[static_cast<size_t>(vi)])
            moved = std::max(moved, velocity[static_cast<size_t>(vi)].norm());
        else
            EXPECT_EQ(velocity[static_cast<size_t>(vi)].norm(), 0.0) << "vertex " << vi;
    }
    EXPECT_GT(moved, 0.0);  // the creases on the active side are damped
    // Rate of volume change Σ v·∇V (∇V of a vertex = a third of its triangles' area vectors).
    const auto volume_rate = [&](const std::vector<tracker::Vec3>& v) {
        double rate = 0.0, scale = 0.0;
        for (int ti = 0; ti < box.num_triangles(); ++ti) {
            if (!box.triangle_alive(ti))
                continue;
            const tracker::Triangle& t = box.triangle(ti);
            const Vector3d area = 0.5 * (box.position(t[1]) - box.position(t[0]))
                                            .cross(box.position(t[2]) - box.position(t[0]));
            for (int vi : t) {
                rate += v[static_cast<size_t>(vi)].dot(area) / 3.0;
                scale += v[static_cast<size_t>(vi)].norm() * area.norm() / 3.0;
            }
        }
        return std::abs(rate) / scale;
    };
    EXPECT_LT(volume_rate(velocity), 1e-12);
    EXPECT_LT(volume_rate(all), 1e-12);
    EXPECT_THROW(subgrid_tension_velocities(box, 1.0, 4, 1, std::vector<char>(3, 1)),
                 std::invalid_argument);
}

TEST(SurfaceTension, BubbleHasNegativeCurvature) {
    const int n = 24;
    const double radius = 0.3;
    const fluid::MacGrid grid(n, n, n, 1.0 / n);
    tracker::SurfaceMesh mesh = sphere_mesh(Vector3d::Constant(0.5), radius, 1.0 / n);
    for (int ti = 0; ti < mesh.num_triangles(); ++ti)
        if (mesh.triangle_alive(ti))
            mesh.set_labels(ti, tracker::LabelPair{0, 1});  // gas inside, liquid outside
    SurfaceTensionResult result;
    const fluid::InterfaceInput in = interface_from_mesh(mesh, grid, {}, {}, &result);
    EXPECT_GT(in.phi(n / 2, n / 2, n / 2), 0.0);
    EXPECT_LT(in.phi(0, 0, 0), 0.0);
    EXPECT_GT(result.crossed_faces, 0);
    EXPECT_LT(result.max_kappa, 0.0);
    const CurvatureError error = sphere_curvature_error(in, -2.0 / radius);
    EXPECT_LT(error.mean, 0.03);
}

/// Laplace jump (mean pressure well inside minus well outside) and max|u| of a static drop of
/// radius 0.26 in the unit box after `steps` capillary-limited steps.
struct StaticDrop {
    double jump = 0.0;
    double laplace = 0.0;
    double max_u = 0.0;
    double capillary_number = 0.0;  ///< max|u| sqrt(ρ_l D / σ)
};

StaticDrop static_drop(int n, int smoothing_passes, int steps) {
    const double dx = 1.0 / n;
    const double radius = 0.26;
    fluid::FluidOptions options;
    options.phases.rho_liquid = 1000.0;
    options.phases.rho_gas = 1.0;
    options.phases.sigma = 0.07;
    options.gravity = Vector3d::Zero();
    fluid::FluidSolver solver(n, n, n, dx, Vector3d::Zero(), options);
    const tracker::SurfaceMesh mesh = sphere_mesh(Vector3d(0.5, 0.49, 0.51), radius, dx);
    SurfaceTensionOptions tension;
    tension.smoothing_passes = smoothing_passes;
    const fluid::InterfaceInput in = interface_from_mesh(mesh, solver.grid(), {}, tension);

    const double dt = solver.time_step_limits().dt;
    for (int step = 0; step < steps; ++step) {
        const fluid::StepResult result = solver.step(dt, in);
        EXPECT_TRUE(result.pressure.converged);
    }
    constexpr double WELL_CELLS = 3.0;
    double inside = 0.0, outside = 0.0;
    long long n_inside = 0, n_outside = 0;
    for (int k = 0; k < n; ++k)
        for (int j = 0; j < n; ++j)
            for (int i = 0; i < n; ++i) {
                const double phi = in.phi(i, j, k);
                if (phi < -WELL_CELLS * dx) {
                    inside += solver.pressure()(i, j, k);
                    ++n_inside;
                } else if (phi > WELL_CELLS * dx) {
                    outside += solver.pressure()(i, j, k);
                    ++n_outside;
                }
            }
    EXPECT_GT(n_inside, 0);
    EXPECT_GT(n_outside, 0);
    StaticDrop drop;
    drop.jump = inside / static_cast<double>(n_inside) - outside / static_cast<double>(n_outside);
    drop.laplace = 2.0 * options.phases.sigma / radius;
    drop.max_u = solver.grid().max_abs_velocity().maxCoeff();
    drop.capillary_number =
        drop.max_u * std::sqrt(options.phases.rho_liquid * 2.0 * radius / options.phases.sigma);
    std::printf(
        "static drop, %.1f cells per diameter, %d smoothing passes: jump %.6f Pa vs "
        "2 sigma/R = %.6f Pa (error %+.4f %%); after %d steps of %.3f s max|u| = %.3e m/s, "
        "max|u| sqrt(rho D / sigma) = %.3e\n",
        2.0 * radius * n, smoothing_passes, drop.jump, drop.laplace,
        100.0 * (drop.jump / drop.laplace - 1.0), steps, dt, drop.max_u, drop.capillary_number);
    return drop;
}

TEST(SurfaceTension, StaticDropThroughTheFluidSolverHasTheLaplaceJump) {
    // Density ratio 1000, no gravity, φ and κ from the coupling; 16.6 and 25 cells per diameter.
    constexpr int STEPS = 5;
    constexpr int SMOOTHING_PASSES = 2;
    for (int n : {32, 48}) {
        const StaticDrop raw = static_drop(n, 0, STEPS);
        const StaticDrop smoothed = static_drop(n, SMOOTHING_PASSES, STEPS);
        EXPECT_NEAR(raw.jump, raw.laplace, 0.02 * raw.laplace);
        EXPECT_NEAR(smoothed.jump, smoothed.laplace, 0.02 * smoothed.laplace);
        // Spurious currents come from the scatter of κ between faces: smoothing reduces them
        // (2 lazy passes: about 5×).
        EXPECT_LT(smoothed.max_u, raw.max_u);
    }
}

TEST(SurfaceTension, FaceCurvatureIsLimitedToWhatTheGridCanHold) {
    // Regression: in bubble_merge at 128 cells, just after the merge, a vertex whose one-ring had
    // degenerated gave a face κ of 2.4e14 1/m (Δx = 7.8e-5 m); its pressure jump set the gas
    // moving at 3e9 m/s. Faces now hold at most max_curvature_cells/Δx. A sphere of 1.5 cells'
    // radius (κ = 1.33/Δx) is below the default limit, and limited to exactly 1/Δx at 1.
    const int n = 16;
    const double dx = 1.0 / n;
    const fluid::MacGrid grid(n, n, n, dx);
    const double radius = 1.5 * dx;
    const tracker::SurfaceMesh mesh = sphere_mesh(Vector3d::Constant(8.5 * dx), radius, 0.3 * dx);
    SurfaceTensionResult result;
    const fluid::InterfaceInput free = interface_from_mesh(mesh, grid, {}, {}, &result);
    ASSERT_GT(result.crossed_faces, 0);
    EXPECT_EQ(result.limited_faces, 0);
    EXPECT_LT(sphere_curvature_error(free, 2.0 / radius).mean, 0.1);
    SurfaceTensionOptions limited_options;
    limited_options.max_curvature_cells = 1.0;
    const fluid::InterfaceInput limited =
        interface_from_mesh(mesh, grid, {}, limited_options, &result);
    EXPECT_EQ(result.limited_faces, result.crossed_faces);
    EXPECT_DOUBLE_EQ(result.max_kappa, 1.0 / dx);
    EXPECT_DOUBLE_EQ(result.min_kappa, 1.0 / dx);
    EXPECT_NEAR(sphere_curvature_error(limited, 1.0 / dx).max, 0.0, 1e-12);
    limited_options.max_curvature_cells = 0.0;
    EXPECT_THROW(limited_options.validate(), std::invalid_argument);
}

TEST(SurfaceTension, InvalidOptionsAndMismatchedRasterAreRejected) {
    SurfaceTensionOptions options;
    options.smoothing_passes = -1;
    EXPECT_THROW(options.validate(), std::invalid_argument);
    options = SurfaceTensionOptions{};
    options.subgrid_rate = -0.1;
    EXPECT_THROW(options.validate(), std::invalid_argument);
    options.subgrid_rate = 1.0;  // above the explicit flow's stability bound
    EXPECT_THROW(options.validate(), std::invalid_argument);
    options = SurfaceTensionOptions{};
    options.subgrid_resolved_passes = 0;
    EXPECT_THROW(options.validate(), std::invalid_argument);
    for (int order : {0, 4}) {
        options = SurfaceTensionOptions{};
        options.subgrid_filter_order = order;
        EXPECT_THROW(options.validate(), std::invalid_argument) << "order " << order;
    }
    const fluid::MacGrid grid(8, 8, 8, 0.125);
    const fluid::MacGrid other(9, 8, 8, 0.125);
    const tracker::SurfaceMesh mesh = sphere_mesh(Vector3d::Constant(0.5), 0.3, 0.1);
    const RasterizeResult raster = rasterize_mesh(mesh, other);
    fluid::InterfaceInput in;
    EXPECT_THROW(face_curvatures(mesh, grid, raster, {}, in), std::invalid_argument);
}

}  // namespace
}  // namespace meniscus::coupling
