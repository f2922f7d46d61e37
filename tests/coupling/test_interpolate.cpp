// Grid → mesh velocity: both methods reproduce linear velocity fields exactly (each component
// from its own staggered faces), dead vertices get zero, the B-spline is smoother than trilinear.
#include "coupling/interpolate.h"

#include "tracker/implicit_mesher.h"
#include "tracker/implicit_shape.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

namespace meniscus::coupling {
namespace {

using Eigen::Matrix3d;
using Eigen::Vector3d;

/// u(x) = offset + gradient · x on every face of `grid`, each component at its own faces.
void set_linear_velocity(fluid::MacGrid& grid, const Vector3d& offset, const Matrix3d& gradient) {
    for (int axis = 0; axis < 3; ++axis) {
        fluid::Array3<double>& field = grid.velocity(axis);
        for (int k = 0; k < field.nk(); ++k)
            for (int j = 0; j < field.nj(); ++j)
                for (int i = 0; i < field.ni(); ++i) {
                    const Vector3d x = grid.face_centre(axis, i, j, k);
                    field(i, j, k) = offset[axis] + gradient.row(axis).dot(x);
                }
    }
}

constexpr double LINEAR_TOLERANCE = 1e-12;  // relative to the largest velocity

TEST(Interpolate, BothMethodsReproduceLinearFieldsExactly) {
    fluid::MacGrid grid(13, 11, 9, 0.07, Vector3d(-0.3, 0.2, 0.5));
    const Vector3d offset(0.3, -1.2, 0.7);
    Matrix3d gradient;
    gradient << 1.5, -0.4, 2.0, 0.3, -2.5, 0.9, -1.1, 0.6, 1.0;
    set_linear_velocity(grid, offset, gradient);
    const Vector3d extent(13 * 0.07, 11 * 0.07, 9 * 0.07);
    const double scale = offset.norm() + gradient.norm() * (grid.origin().norm() + extent.norm());

    // Everywhere in the lattice of every component, i.e. half a cell from the walls (where the
    // B-spline falls back to trilinear near the walls and uses its 3³ stencil elsewhere).
    std::mt19937 random(7);
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    for (VelocityInterpolation method :
         {VelocityInterpolation::trilinear, VelocityInterpolation::quadratic_bspline}) {
        double max_error = 0.0;
        for (int sample = 0; sample < 2000; ++sample) {
            Vector3d x;
            for (int d = 0; d < 3; ++d)
                x[d] = grid.origin()[d] + 0.5 * grid.dx() + unit(random) * (extent[d] - grid.dx());
            const Vector3d expected = offset + gradient * x;
            max_error =
                std::max(max_error,
                         (sample_grid_velocity(grid, x, method) - expected).cwiseAbs().maxCoeff());
        }
        EXPECT_LT(max_error, LINEAR_TOLERANCE * scale) << "method " << static_cast<int>(method);
    }
}

TEST(Interpolate, VertexVelocitiesOfAMeshAreExactForALinearFieldAndZeroWhenDead) {
    fluid::MacGrid grid(16, 16, 16, 1.0 / 16);
    const Vector3d offset(0.1, 0.2, -0.3);
    Matrix3d gradient;
    gradient << 0.0, -1.0, 0.0, 1.0, 0.0, 0.0, 0.2, 0.3, -0.5;
    set_linear_velocity(grid, offset, gradient);
    tracker::ImplicitMeshOptions mesher;
    mesher.edge_length = 0.05;
    tracker::SurfaceMesh mesh =
        tracker::mesh_implicit_shape(*tracker::make_sphere(Vector3d::Constant(0.5), 0.3), mesher);
    const int dead = mesh.add_vertex(Vector3d::Constant(0.5));
    mesh.remove_vertex(dead);
    for (VelocityInterpolation method :
         {VelocityInterpolation::trilinear, VelocityInterpolation::quadratic_bspline}) {
        InterpolateOptions options;
        options.method = method;
        const std::vector<tracker::Vec3> velocity =
            interpolate_vertex_velocities(grid, mesh, options);
        ASSERT_EQ(velocity.size(), static_cast<size_t>(mesh.num_vertices()));
        double max_error = 0.0;
        for (int vi = 0; vi < mesh.num_vertices(); ++vi) {
            if (!mesh.vertex_alive(vi))
                continue;
            const Vector3d expected = offset + gradient * mesh.position(vi);
            max_error = std::max(max_error, (velocity[static_cast<size_t>(vi)] - expected).norm());
        }
        EXPECT_LT(max_error, LINEAR_TOLERANCE);
        EXPECT_EQ(velocity[static_cast<size_t>(dead)], tracker::Vec3::Zero());
    }
}

TEST(Interpolate, QuadraticBSplineIsSmootherThanTrilinear) {
    // A velocity that alternates sign face by face (the grid's highest frequency): trilinear
    // passes it on at full amplitude at the faces, the B-spline damps it (to ½ at a face).
    fluid::MacGrid grid(12, 12, 12, 1.0);
    fluid::Array3<double>& u = grid.u();
    for (int k = 0; k < u.nk(); ++k)
        for (int j = 0; j < u.nj(); ++j)
            for (int i = 0; i < u.ni(); ++i)
                u(i, j, k) = (i % 2 == 0) ? 1.0 : -1.0;
    const Vector3d at_face = grid.face_centre(0, 6, 6, 6);
    EXPECT_NEAR(sample_grid_velocity(grid, at_face, VelocityInterpolation::trilinear).x(), 1.0,
                1e-14);
    EXPECT_NEAR(sample_grid_velocity(grid, at_face, VelocityInterpolation::quadratic_bspline).x(),
                0.5, 1e-14);
}

TEST(Interpolate, InvalidMethodIsRejected) {
    InterpolateOptions options;
    options.method = static_cast<VelocityInterpolation>(7);
    EXPECT_THROW(options.validate(), std::invalid_argument);
}

}  // namespace
}  // namespace meniscus::coupling
