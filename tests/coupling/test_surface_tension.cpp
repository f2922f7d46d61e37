// Curvature at face crossings from the mesh: a sphere gives 2/R (converging with refinement),
// a bubble −2/R, and an end-to-end static drop through FluidSolver has the Laplace jump 2σ/R.
#include "coupling/surface_tension.h"

#include "fluid/fluid_solver.h"
#include "tracker/implicit_mesher.h"
#include "tracker/implicit_shape.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
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

TEST(SurfaceTension, SphereCurvatureAtCrossingsConvergesToTwoOverR) {
    const double radius = 0.3;
    const Vector3d centre(0.503, 0.497, 0.511);
    std::vector<CurvatureError> errors;
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
            "|kappa R/2 - 1| mean %.4f max %.4f (faces %.4f s)\n",
            2.0 * radius * n, error.faces, error.mean, error.max, result.face_seconds);
        errors.push_back(error);
    }
    EXPECT_LT(errors[0].mean, 0.03);
    for (size_t r = 1; r < errors.size(); ++r) {
        EXPECT_LT(errors[r].mean, errors[r - 1].mean);
        EXPECT_LT(errors[r].max, 0.05);
    }
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

TEST(SurfaceTension, StaticDropThroughTheFluidSolverHasTheLaplaceJump) {
    // 16.6 cells per diameter, density ratio 1000, no gravity.
    const int n = 32;
    const double dx = 1.0 / n;
    const double radius = 0.26;
    fluid::FluidOptions options;
    options.phases.rho_liquid = 1000.0;
    options.phases.rho_gas = 1.0;
    options.phases.sigma = 0.07;
    options.gravity = Vector3d::Zero();
    fluid::FluidSolver solver(n, n, n, dx, Vector3d::Zero(), options);
    const tracker::SurfaceMesh mesh = sphere_mesh(Vector3d(0.5, 0.49, 0.51), radius, dx);
    const fluid::InterfaceInput in = interface_from_mesh(mesh, solver.grid());

    const int steps = 5;
    const double dt = solver.time_step_limits().dt;
    for (int step = 0; step < steps; ++step) {
        const fluid::StepResult result = solver.step(dt, in);
        ASSERT_TRUE(result.pressure.converged);
    }
    const double well = 3.0 * dx;
    double inside = 0.0, outside = 0.0;
    long long n_inside = 0, n_outside = 0;
    for (int k = 0; k < n; ++k)
        for (int j = 0; j < n; ++j)
            for (int i = 0; i < n; ++i) {
                const double phi = in.phi(i, j, k);
                if (phi < -well) {
                    inside += solver.pressure()(i, j, k);
                    ++n_inside;
                } else if (phi > well) {
                    outside += solver.pressure()(i, j, k);
                    ++n_outside;
                }
            }
    ASSERT_GT(n_inside, 0);
    ASSERT_GT(n_outside, 0);
    const double jump = inside / n_inside - outside / n_outside;
    const double laplace = 2.0 * options.phases.sigma / radius;
    const double max_u = solver.grid().max_abs_velocity().maxCoeff();
    const double diameter = 2.0 * radius;
    std::printf(
        "static drop, %.1f cells per diameter: jump %.5f Pa vs 2 sigma/R = %.5f Pa "
        "(error %.3f %%); after %d steps of %.2e s max|u| = %.3e m/s, "
        "max|u| sqrt(rho D / sigma) = %.3e\n",
        diameter / dx, jump, laplace, 100.0 * (jump / laplace - 1.0), steps, dt, max_u,
        max_u * std::sqrt(options.phases.rho_liquid * diameter / options.phases.sigma));
    EXPECT_NEAR(jump, laplace, 0.02 * laplace);
}

TEST(SurfaceTension, InvalidOptionsAndMismatchedRasterAreRejected) {
    SurfaceTensionOptions options;
    options.smoothing_passes = -1;
    EXPECT_THROW(options.validate(), std::invalid_argument);
    const fluid::MacGrid grid(8, 8, 8, 0.125);
    const fluid::MacGrid other(9, 8, 8, 0.125);
    const tracker::SurfaceMesh mesh = sphere_mesh(Vector3d::Constant(0.5), 0.3, 0.1);
    const RasterizeResult raster = rasterize_mesh(mesh, other);
    fluid::InterfaceInput in;
    EXPECT_THROW(face_curvatures(mesh, grid, raster, {}, in), std::invalid_argument);
}

}  // namespace
}  // namespace meniscus::coupling
