// The surface-viscosity term of semi-implicit surface tension (coupling/implicit_tension.h,
// fluid/surface_viscosity.h): its energy is the surface's Dirichlet energy of the interpolated
// velocity, rigid translations cost nothing, and triangles beyond a wall are left out.

#include "coupling/implicit_tension.h"
#include "fluid/surface_viscosity.h"
#include "tracker/implicit_mesher.h"
#include "tracker/implicit_shape.h"
#include "tracker/mesh_measures.h"

#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>
#include <vector>

namespace meniscus::coupling {
namespace {

using Eigen::Vector3d;

/// The flat face vector [u | v | w] of u(x) = offset + gradient·x.
std::vector<double> linear_faces(const fluid::MacGrid& grid, const Vector3d& offset,
                                 const Eigen::Matrix3d& gradient) {
    std::vector<double> faces;
    for (int axis = 0; axis < 3; ++axis) {
        const fluid::Array3<double>& field = grid.velocity(axis);
        for (int k = 0; k < field.nk(); ++k)
            for (int j = 0; j < field.nj(); ++j)
                for (int i = 0; i < field.ni(); ++i)
                    faces.push_back(offset[axis] +
                                    gradient.row(axis).dot(grid.face_centre(axis, i, j, k)));
    }
    return faces;
}

double dot(const std::vector<double>& a, const std::vector<double>& b) {
    double s = 0.0;
    for (size_t i = 0; i < a.size(); ++i)
        s += a[i] * b[i];
    return s;
}

tracker::SurfaceMesh sphere(const Vector3d& centre, double radius, double edge) {
    tracker::ImplicitMeshOptions mesher;
    mesher.edge_length = edge;
    return tracker::mesh_implicit_shape(*tracker::make_sphere(centre, radius), mesher);
}

TEST(ImplicitTension, EnergyOfTheIdentityFieldIsTwiceTheAreaAndTranslationsAreFree) {
    fluid::MacGrid grid(16, 16, 16, 1.0 / 16);
    const tracker::SurfaceMesh mesh = sphere(Vector3d::Constant(0.5), 0.3, 0.05);
    for (VelocityInterpolation method :
         {VelocityInterpolation::trilinear, VelocityInterpolation::one_sided}) {
        InterpolateOptions options;
        options.method = method;
        const auto term = build_surface_viscosity(mesh, grid, 2.0, options, {});
        EXPECT_EQ(term->points(), mesh.count_live_vertices());
        // u = x: every interpolation is exact for linear fields, and the cotangent energy of
        // the identity on a piecewise-linear surface is ∫ tr(P_Γ) dA = 2 · area exactly.
        const std::vector<double> identity =
            linear_faces(grid, Vector3d::Zero(), Eigen::Matrix3d::Identity());
        std::vector<double> y(identity.size(), 0.0);
        term->add_stiffness(1.0, identity, y);
        EXPECT_NEAR(dot(identity, y), 2.0 * tracker::surface_area(mesh),
                    1e-10 * tracker::surface_area(mesh));
        // A rigid translation: no surface gradient, no force.
        const std::vector<double> shift =
            linear_faces(grid, Vector3d(0.3, -0.2, 1.1), Eigen::Matrix3d::Zero());
        std::fill(y.begin(), y.end(), 0.0);
        term->add_stiffness(1.0, shift, y);
        double largest = 0.0;
        for (double value : y)
            largest = std::max(largest, std::abs(value));
        EXPECT_LT(largest, 1e-12);
        // The Jacobi estimate is positive wherever the term reaches.
        std::vector<double> d(identity.size(), 0.0);
        term->add_diagonal_bound(1.0, d);
        EXPECT_GT(*std::max_element(d.begin(), d.end()), 0.0);
        EXPECT_GE(*std::min_element(d.begin(), d.end()), 0.0);
        EXPECT_NO_THROW(term->validate(grid));
    }
}

TEST(ImplicitTension, TrianglesBeyondAWallAreLeftOut) {
    // A sphere sticking out of the box's top: only the triangles wholly inside are in L.
    fluid::MacGrid grid(16, 16, 16, 1.0 / 16);
    const tracker::SurfaceMesh mesh = sphere(Vector3d(0.5, 0.5, 0.9), 0.3, 0.05);
    const auto term = build_surface_viscosity(mesh, grid, 1.0, {}, {});
    EXPECT_GT(term->points(), 0);
    EXPECT_LT(term->points(), mesh.count_live_vertices());
    // Each row of L sums to zero (constants are in its null space) and L is symmetric.
    const Eigen::SparseMatrix<double> l = term->laplacian;
    const Eigen::VectorXd row_sums = l * Eigen::VectorXd::Ones(l.cols());
    EXPECT_LT(row_sums.cwiseAbs().maxCoeff(), 1e-12);
    EXPECT_LT((Eigen::SparseMatrix<double>(l.transpose()) - l).norm(), 1e-12);
}

TEST(ImplicitTension, RefusesBadInputNamingIt) {
    fluid::MacGrid grid(4, 4, 4, 0.25);
    const tracker::SurfaceMesh mesh = sphere(Vector3d::Constant(0.5), 0.3, 0.1);
    EXPECT_THROW(build_surface_viscosity(mesh, grid, -1.0, {}, {}), std::invalid_argument);
    auto term = std::make_shared<fluid::SurfaceViscosity>(
        *build_surface_viscosity(mesh, grid, 1.0, {}, {}));
    fluid::MacGrid other(5, 4, 4, 0.25);
    try {
        term->validate(other);
        FAIL() << "a term built for another grid was accepted";
    } catch (const std::invalid_argument& e) {
        EXPECT_NE(std::string(e.what()).find("SurfaceViscosity.sample"), std::string::npos);
    }
}

}  // namespace
}  // namespace meniscus::coupling
