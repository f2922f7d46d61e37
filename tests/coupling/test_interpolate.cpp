// Grid → mesh velocity: every method reproduces linear velocity fields exactly (each component
// from its own staggered faces), dead vertices get zero, the B-spline is smoother than trilinear,
// the one-sided method is exact across a kink at a planar interface.
#include "coupling/interpolate.h"

#include "tracker/implicit_mesher.h"
#include "tracker/mesh_measures.h"
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

/// u(x) = value + slope·|n·(x − x0)| on every face of `grid` (every component alike): linear on
/// each side of the plane through x0 with normal n, with a kink on it — how an inviscid mode
/// ∝ e^{−k|z|} looks at the grid scale across an interface.
void set_kinked_velocity(fluid::MacGrid& grid, const Vector3d& x0, const Vector3d& n,
                         const Vector3d& value, double slope) {
    for (int axis = 0; axis < 3; ++axis) {
        fluid::Array3<double>& field = grid.velocity(axis);
        for (int k = 0; k < field.nk(); ++k)
            for (int j = 0; j < field.nj(); ++j)
                for (int i = 0; i < field.ni(); ++i)
                    field(i, j, k) =
                        value[axis] + slope * std::abs(n.dot(grid.face_centre(axis, i, j, k) - x0));
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

TEST(Interpolate, OneSidedReproducesLinearFieldsForAnyNormal) {
    fluid::MacGrid grid(13, 11, 9, 0.07, Vector3d(-0.3, 0.2, 0.5));
    const Vector3d offset(0.3, -1.2, 0.7);
    Matrix3d gradient;
    gradient << 1.5, -0.4, 2.0, 0.3, -2.5, 0.9, -1.1, 0.6, 1.0;
    set_linear_velocity(grid, offset, gradient);
    const Vector3d extent(13 * 0.07, 11 * 0.07, 9 * 0.07);
    const double scale = offset.norm() + gradient.norm() * (grid.origin().norm() + extent.norm());
    std::mt19937 random(11);
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    std::normal_distribution<double> gauss;
    double max_error = 0.0;
    for (int sample = 0; sample < 2000; ++sample) {
        Vector3d x;
        for (int d = 0; d < 3; ++d)
            x[d] = grid.origin()[d] + 0.5 * grid.dx() + unit(random) * (extent[d] - grid.dx());
        const Vector3d normal(gauss(random), gauss(random), gauss(random));
        const Vector3d expected = offset + gradient * x;
        max_error = std::max(
            max_error,
            (sample_grid_velocity(grid, x, VelocityInterpolation::one_sided, normal) - expected)
                .cwiseAbs()
                .maxCoeff());
    }
    EXPECT_LT(max_error, LINEAR_TOLERANCE * scale);
}

TEST(Interpolate, OneSidedIsExactAcrossAKinkAtAPlanarInterfaceWhereTrilinearIsNot) {
    // Points on a tilted plane at least 3 cells from the walls; the velocity is linear on each
    // side of the plane with a kink on it. Trilinear interpolation mixes faces from both sides
    // and comes out high by up to about slope·dx/2; the one-sided columns are exact.
    const double dx = 0.1;
    fluid::MacGrid grid(20, 20, 20, dx);
    const Vector3d x0(1.03, 0.97, 1.011);
    const Vector3d n = Vector3d(0.3, -0.5, 1.0).normalized();
    const Vector3d value(0.2, -0.1, 0.4);
    const double slope = 3.0;
    set_kinked_velocity(grid, x0, n, value, slope);
    const Vector3d t1 = n.unitOrthogonal();
    const Vector3d t2 = n.cross(t1);
    std::mt19937 random(5);
    std::uniform_real_distribution<double> offset(-0.6, 0.6);
    double one_sided_error = 0.0, trilinear_error = 0.0;
    for (int sample = 0; sample < 500; ++sample) {
        const Vector3d x = x0 + offset(random) * t1 + offset(random) * t2;
        one_sided_error =
            std::max(one_sided_error,
                     (sample_grid_velocity(grid, x, VelocityInterpolation::one_sided, -2.0 * n) -
                      value)
                         .cwiseAbs()
                         .maxCoeff());
        trilinear_error = std::max(
            trilinear_error,
            (sample_grid_velocity(grid, x, VelocityInterpolation::trilinear) - value)
                .cwiseAbs()
                .maxCoeff());
    }
    EXPECT_LT(one_sided_error, 1e-12);
    EXPECT_GT(trilinear_error, 0.2 * slope * dx);
}

TEST(Interpolate, OneSidedClampsPointsOutsideTheDomainLikeTrilinear) {
    // Regression: the one-sided columns once extrapolated linearly to wherever a vertex was, so
    // the cut ends of a wall-crossing jet (6 cells outside the domain) moved with velocities
    // extrapolated over 6 cells and the quick jet pinch-off's liquid volume drifted 0.86 %
    // (ScenePhysics.JetPinchQuickPinchesIntoDrops). Outside the lattice both methods clamp.
    fluid::MacGrid grid(10, 8, 9, 0.1);
    Matrix3d gradient;
    gradient << 1.5, -0.4, 2.0, 0.3, -2.5, 0.9, -1.1, 0.6, 1.0;
    set_linear_velocity(grid, Vector3d(0.3, -1.2, 0.7), gradient);
    const Vector3d normal = Vector3d(0.2, 0.1, 1.0);
    for (const Vector3d& x : {Vector3d(-0.6, 0.4, 0.45), Vector3d(0.5, 1.4, 0.45),
                              Vector3d(0.5, 0.4, -0.7), Vector3d(1.7, -0.5, 1.6)}) {
        const Vector3d one_sided =
            sample_grid_velocity(grid, x, VelocityInterpolation::one_sided, normal);
        const Vector3d trilinear = sample_grid_velocity(grid, x, VelocityInterpolation::trilinear);
        EXPECT_LT((one_sided - trilinear).cwiseAbs().maxCoeff(), 1e-12) << x.transpose();
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
         {VelocityInterpolation::trilinear, VelocityInterpolation::quadratic_bspline,
          VelocityInterpolation::one_sided}) {
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

TEST(Interpolate, MirrorReflectsTheFlowAcrossFreeSlipWallsAndClampsAtNoSlipOnes) {
    // A mesh crossing walls (B4's slab past its side walls): with OutsideVelocity::mirror a
    // vertex beyond a free-slip wall takes the velocity at its mirror point with the wall-normal
    // component negated (the even/odd continuation a symmetry plane implies); beyond a no-slip
    // wall it keeps the clamped sample; with `clamp` every vertex keeps the clamped sample.
    fluid::MacGrid grid(10, 8, 9, 0.1);  // [0, 1] × [0, 0.8] × [0, 0.9]
    Matrix3d gradient;
    gradient << 1.5, -0.4, 2.0, 0.3, -2.5, 0.9, -1.1, 0.6, 1.0;
    set_linear_velocity(grid, Vector3d(0.3, -1.2, 0.7), gradient);
    fluid::BoundaryOptions walls;  // free-slip but x_max
    walls.x_max.type = fluid::BoundaryType::no_slip;
    const std::vector<Vector3d> x = {{-0.2, 0.4, 0.45}, {0.5, 0.4, 1.1}, {1.25, 0.9, 0.45}};
    // Where mirroring samples each vertex, and the sign of each component there.
    const std::vector<Vector3d> image = {{0.2, 0.4, 0.45}, {0.5, 0.4, 0.7}, {1.25, 0.7, 0.45}};
    const std::vector<Vector3d> sign = {{-1, 1, 1}, {1, 1, -1}, {1, -1, 1}};
    const tracker::SurfaceMesh mesh({x[0], x[1], x[2]}, {{0, 1, 2}});
    const std::vector<tracker::Vec3> normals = tracker::area_weighted_vertex_normals(mesh);
    for (VelocityInterpolation method :
         {VelocityInterpolation::trilinear, VelocityInterpolation::one_sided}) {
        InterpolateOptions options;
        options.method = method;
        options.outside = OutsideVelocity::mirror;
        const std::vector<tracker::Vec3> mirrored =
            interpolate_vertex_velocities(grid, mesh, options, walls);
        options.outside = OutsideVelocity::clamp;
        const std::vector<tracker::Vec3> clamped =
            interpolate_vertex_velocities(grid, mesh, options, walls);
        for (size_t v = 0; v < 3; ++v) {
            const Vector3d n = normals[v];
            const Vector3d expected =
                sample_grid_velocity(grid, image[v], method, n.cwiseProduct(sign[v]))
                    .cwiseProduct(sign[v]);
            EXPECT_LT((mirrored[v] - expected).cwiseAbs().maxCoeff(), 1e-12) << "vertex " << v;
            EXPECT_LT((clamped[v] - sample_grid_velocity(grid, x[v], method, n)).cwiseAbs().maxCoeff(),
                      1e-12)
                << "vertex " << v;
        }
        // The two differ wherever a vertex is beyond a free-slip wall.
        EXPECT_GT((mirrored[0] - clamped[0]).norm(), 0.1);
    }
    InterpolateOptions bad;
    bad.outside = static_cast<OutsideVelocity>(5);
    EXPECT_THROW(bad.validate(), std::invalid_argument);
}

/// The weights (semi-implicit tension's S) reproduce the vertex velocities of any grid velocity
/// for every method, with vertices inside the box and beyond free-slip and no-slip walls.
TEST(Interpolate, VertexVelocityWeightsReproduceTheInterpolatedVelocities) {
    fluid::MacGrid grid(10, 8, 9, 0.1);  // [0, 1] × [0, 0.8] × [0, 0.9]
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> value(-1.0, 1.0);
    for (int axis = 0; axis < 3; ++axis)
        for (double& u : grid.velocity(axis).storage())
            u = value(rng);
    fluid::BoundaryOptions walls;
    walls.x_max.type = fluid::BoundaryType::no_slip;
    tracker::ImplicitMeshOptions mesher;
    mesher.edge_length = 0.08;
    tracker::SurfaceMesh mesh = tracker::mesh_implicit_shape(
        *tracker::make_sphere(Vector3d(0.5, 0.4, 0.45), 0.3), mesher);
    // Three more vertices beyond the walls (x_min free-slip, z_max free-slip, x_max no-slip).
    const int a = mesh.add_vertex(Vector3d(-0.2, 0.4, 0.45));
    const int b = mesh.add_vertex(Vector3d(0.5, 0.4, 1.1));
    const int c = mesh.add_vertex(Vector3d(1.25, 0.9, 0.45));
    mesh.add_triangle({a, b, c});
    std::vector<int> vertices;
    for (int v = 0; v < mesh.num_vertices(); ++v)
        if (mesh.vertex_alive(v))
            vertices.push_back(v);
    std::vector<double> faces;
    for (int axis = 0; axis < 3; ++axis)
        faces.insert(faces.end(), grid.velocity(axis).storage().begin(),
                     grid.velocity(axis).storage().end());
    const Eigen::Map<const Eigen::VectorXd> u(faces.data(), static_cast<Eigen::Index>(faces.size()));
    for (VelocityInterpolation method :
         {VelocityInterpolation::trilinear, VelocityInterpolation::quadratic_bspline,
          VelocityInterpolation::one_sided}) {
        for (OutsideVelocity outside : {OutsideVelocity::clamp, OutsideVelocity::mirror}) {
            InterpolateOptions options;
            options.method = method;
            options.outside = outside;
            const std::vector<tracker::Vec3> velocity =
                interpolate_vertex_velocities(grid, mesh, options, walls);
            const Eigen::SparseMatrix<double, Eigen::RowMajor> weights =
                vertex_velocity_weights(grid, mesh, vertices, options, walls);
            ASSERT_EQ(weights.rows(), static_cast<Eigen::Index>(3 * vertices.size()));
            ASSERT_EQ(weights.cols(), static_cast<Eigen::Index>(faces.size()));
            const Eigen::VectorXd sampled = weights * u;
            double max_error = 0.0;
            for (size_t p = 0; p < vertices.size(); ++p)
                for (int d = 0; d < 3; ++d)
                    max_error = std::max(
                        max_error,
                        std::abs(sampled[static_cast<Eigen::Index>(3 * p + d)] -
                                 velocity[static_cast<size_t>(vertices[p])][d]));
            EXPECT_LT(max_error, 1e-12) << "method " << static_cast<int>(method) << ", outside "
                                        << static_cast<int>(outside);
        }
    }
    const int dead = mesh.add_vertex(Vector3d::Constant(0.5));
    mesh.remove_vertex(dead);
    EXPECT_THROW(vertex_velocity_weights(grid, mesh, {dead}), std::invalid_argument);
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
