// The surface-viscosity term of semi-implicit surface tension (coupling/implicit_tension.h,
// fluid/surface_viscosity.h): its energy is the surface's Dirichlet energy of the interpolated
// velocity, rigid translations cost nothing, and triangles beyond a wall are left out.

#include "coupling/implicit_tension.h"
#include "fluid/surface_preconditioner.h"
#include "fluid/surface_viscosity.h"
#include "fluid/viscosity.h"
#include "tracker/implicit_mesher.h"
#include "tracker/implicit_shape.h"
#include "tracker/mesh_measures.h"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <random>
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

/// A water drop of radius 0.3 in air at the middle of the unit box of 16³ cells: its mesh and the
/// signed distance φ at the cell centres (negative in the water).
struct DropInAir {
    fluid::MacGrid grid{16, 16, 16, 1.0 / 16};
    tracker::SurfaceMesh mesh = sphere(Vector3d::Constant(0.5), 0.3, 0.05);
    fluid::Array3<double> phi{16, 16, 16, 0.0};
    DropInAir() {
        for (int k = 0; k < 16; ++k)
            for (int j = 0; j < 16; ++j)
                for (int i = 0; i < 16; ++i)
                    phi(i, j, k) =
                        (grid.cell_centre(i, j, k) - Vector3d::Constant(0.5)).norm() - 0.3;
    }
    /// The flat face vector [u | v | w]: 1 on the faces whose both cells are in the air, else 0.
    std::vector<double> gas_faces() const {
        std::vector<double> gas;
        for (int axis = 0; axis < 3; ++axis) {
            const fluid::Array3<double>& faces = grid.velocity(axis);
            for (int k = 0; k < faces.nk(); ++k)
                for (int j = 0; j < faces.nj(); ++j)
                    for (int i = 0; i < faces.ni(); ++i) {
                        std::array<int, 3> lo = {i, j, k}, hi = {i, j, k};
                        --lo[static_cast<std::size_t>(axis)];
                        const bool inside = lo[static_cast<std::size_t>(axis)] >= 0 &&
                                            hi[static_cast<std::size_t>(axis)] < 16;
                        gas.push_back(inside && phi(lo[0], lo[1], lo[2]) > 0.0 &&
                                              phi(hi[0], hi[1], hi[2]) > 0.0
                                          ? 1.0
                                          : 0.0);
                    }
        }
        return gas;
    }
};

TEST(ImplicitTension, EnergyOfTheIdentityFieldIsTwiceTheAreaAndTranslationsAreFree) {
    fluid::MacGrid grid(16, 16, 16, 1.0 / 16);
    const tracker::SurfaceMesh mesh = sphere(Vector3d::Constant(0.5), 0.3, 0.05);
    for (VelocityInterpolation method :
         {VelocityInterpolation::trilinear, VelocityInterpolation::one_sided}) {
        InterpolateOptions options;
        options.method = method;
        const auto term = build_surface_viscosity(mesh, grid, 2.0, options, {}, nullptr, 1.0, 1.0,
                                                  SurfaceTermForm::full);
        EXPECT_EQ(term->points(), mesh.count_live_vertices());
        // u = x: every interpolation is exact for linear fields, and the full form's cotangent
        // energy of the identity on a piecewise-linear surface is ∫ tr(P_Γ) dA = 2 · area exactly.
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

/// A flat square patch (z = 0.5, 0.2 ≤ x, y ≤ 0.8) in a unit box, split into right triangles.
tracker::SurfaceMesh flat_patch(int cells) {
    std::vector<tracker::Vec3> positions;
    std::vector<tracker::Triangle> triangles;
    const double h = 0.6 / cells;
    for (int j = 0; j <= cells; ++j)
        for (int i = 0; i <= cells; ++i)
            positions.emplace_back(0.2 + i * h, 0.2 + j * h, 0.5);
    const auto at = [&](int i, int j) { return j * (cells + 1) + i; };
    for (int j = 0; j < cells; ++j)
        for (int i = 0; i < cells; ++i) {
            triangles.push_back({at(i, j), at(i + 1, j), at(i + 1, j + 1)});
            triangles.push_back({at(i, j), at(i + 1, j + 1), at(i, j + 1)});
        }
    return tracker::SurfaceMesh(positions, triangles);
}

double energy(const fluid::SurfaceViscosity& term, const std::vector<double>& faces) {
    std::vector<double> y(faces.size(), 0.0);
    term.add_stiffness(1.0, faces, y);
    return dot(faces, y);
}

/// The normal form damps only what changes the surface's shape. On a flat patch (area A = 0.36)
/// stretched along itself (u = (x, y, 0), a film draining outwards) its energy is 0 where the
/// full form's is 2A; a normal velocity growing along the patch (u = (0, 0, x)) costs A in both
/// forms. On a sphere, translations and the uniform dilation u = x − c (which changes the
/// curvature only through the |II|² term that Hysing's form leaves out as well) are free. The
/// drop's n = 2 mode u = M(x − c), M = diag(1, 1, −2), costs ∫ |Mn|² − (nᵀMn)² dA = 1.2 A in the
/// normal form (n_T fixed in each triangle) against ∫ tr M² − |Mn|² dA = 4 A in the full one: the
/// normal form sees the mode's normal part and lets its tangential part go.
TEST(ImplicitTension, NormalFormLeavesTheSurfacesStretchingFree) {
    fluid::MacGrid grid(16, 16, 16, 1.0 / 16);
    InterpolateOptions interpolate;
    interpolate.method = VelocityInterpolation::trilinear;
    const auto build = [&](const tracker::SurfaceMesh& mesh, SurfaceTermForm form) {
        return build_surface_viscosity(mesh, grid, 1.0, interpolate, {}, nullptr, 1.0, 1.0, form);
    };
    const tracker::SurfaceMesh patch = flat_patch(12);
    const double area = 0.36;
    const auto normal = build(patch, SurfaceTermForm::normal);
    const auto full = build(patch, SurfaceTermForm::full);
    Eigen::Matrix3d stretch = Eigen::Matrix3d::Zero();
    stretch(0, 0) = stretch(1, 1) = 1.0;
    const std::vector<double> draining = linear_faces(grid, Vector3d(-0.5, -0.5, 0.0), stretch);
    EXPECT_NEAR(energy(*normal, draining), 0.0, 1e-12);
    EXPECT_NEAR(energy(*full, draining), 2.0 * area, 1e-10);
    Eigen::Matrix3d tilt = Eigen::Matrix3d::Zero();
    tilt(2, 0) = 1.0;
    const std::vector<double> tilting = linear_faces(grid, Vector3d::Zero(), tilt);
    EXPECT_NEAR(energy(*normal, tilting), area, 1e-10);
    EXPECT_NEAR(energy(*full, tilting), area, 1e-10);

    const Vector3d centre = Vector3d::Constant(0.5);
    const tracker::SurfaceMesh ball = sphere(centre, 0.3, 0.05);
    const auto on_ball = build(ball, SurfaceTermForm::normal);
    const auto on_ball_full = build(ball, SurfaceTermForm::full);
    const double ball_area = tracker::surface_area(ball);
    EXPECT_NEAR(
        energy(*on_ball, linear_faces(grid, Vector3d(0.3, -0.2, 1.1), Eigen::Matrix3d::Zero())),
        0.0, 1e-12);
    EXPECT_NEAR(energy(*on_ball, linear_faces(grid, -centre, Eigen::Matrix3d::Identity())), 0.0,
                1e-12 * ball_area);
    const Eigen::Matrix3d mode = Eigen::Vector3d(1.0, 1.0, -2.0).asDiagonal();
    const std::vector<double> wobble = linear_faces(grid, -mode * centre, mode);
    const double normal_energy = energy(*on_ball, wobble);
    const double full_energy = energy(*on_ball_full, wobble);
    EXPECT_NEAR(normal_energy / ball_area, 1.2, 0.06);
    EXPECT_NEAR(full_energy / ball_area, 4.0, 0.2);
    std::printf("[ n = 2 mode ] energy: normal form %.4g, full form %.4g\n", normal_energy,
                full_energy);
}

TEST(ImplicitTension, TrianglesBeyondAWallAreLeftOut) {
    // A sphere sticking out of the box's top: only the triangles wholly inside are in L.
    fluid::MacGrid grid(16, 16, 16, 1.0 / 16);
    const tracker::SurfaceMesh mesh = sphere(Vector3d(0.5, 0.5, 0.9), 0.3, 0.05);
    const auto term = build_surface_viscosity(mesh, grid, 1.0, {}, {});
    EXPECT_GT(term->points(), 0);
    EXPECT_LT(term->points(), mesh.count_live_vertices());
    // Each row of K sums to zero (translations are in its null space) and K is symmetric.
    const Eigen::SparseMatrix<double> l = term->stiffness;
    const Eigen::VectorXd row_sums = l * Eigen::VectorXd::Ones(l.cols());
    EXPECT_LT(row_sums.cwiseAbs().maxCoeff(), 1e-12);
    EXPECT_LT((Eigen::SparseMatrix<double>(l.transpose()) - l).norm(), 1e-12);
}

TEST(ImplicitTension, SamplingWeightedByFaceDensityFollowsTheLiquid) {
    // A water drop in air: the points read the faces around them weighted by their density.
    const DropInAir drop;
    const fluid::MacGrid& grid = drop.grid;
    const tracker::SurfaceMesh& mesh = drop.mesh;
    const fluid::Array3<double>& phi = drop.phi;
    InterpolateOptions interpolate;
    interpolate.method = VelocityInterpolation::trilinear;
    const double rho_liquid = 1000.0, rho_gas = 1.2;
    const auto plain = build_surface_viscosity(mesh, grid, 1.0, interpolate, {});
    const auto weighted =
        build_surface_viscosity(mesh, grid, 1.0, interpolate, {}, &phi, rho_liquid, rho_gas);
    ASSERT_EQ(weighted->points(), plain->points());
    // Each point's weights keep their sum (1: a uniform flow is read exactly, and costs no
    // energy).
    const Eigen::VectorXd ones = Eigen::VectorXd::Ones(weighted->sample.cols());
    const Eigen::VectorXd sums = weighted->sample * ones;
    EXPECT_LT((sums - plain->sample * ones).cwiseAbs().maxCoeff(), 1e-12);
    const std::vector<double> shift =
        linear_faces(grid, Vector3d(0.3, -0.2, 1.1), Eigen::Matrix3d::Zero());
    std::vector<double> y(shift.size(), 0.0);
    weighted->add_stiffness(1.0, shift, y);
    for (double value : y)
        EXPECT_LT(std::abs(value), 1e-12);
    // A velocity on the all-gas faces alone (both cells in the air): the plain points read a
    // good part of it, the weighted ones about ρ_g/ρ_l of it.
    const std::vector<double> gas = drop.gas_faces();
    const Eigen::Map<const Eigen::VectorXd> gas_faces(gas.data(),
                                                      static_cast<Eigen::Index>(gas.size()));
    const double plain_read = (plain->sample * gas_faces).maxCoeff();
    const double weighted_read = (weighted->sample * gas_faces).maxCoeff();
    EXPECT_GT(plain_read, 0.3);
    EXPECT_LT(weighted_read, 0.01);
    // φ must have the grid's cells, and the densities make sense.
    fluid::Array3<double> small(8, 8, 8, 0.0);
    EXPECT_THROW(build_surface_viscosity(mesh, grid, 1.0, interpolate, {}, &small, 1.0, 1.0),
                 std::invalid_argument);
    EXPECT_THROW(build_surface_viscosity(mesh, grid, 1.0, interpolate, {}, &phi, 0.0, 1.0),
                 std::invalid_argument);
    EXPECT_THROW(build_surface_viscosity(mesh, grid, 1.0, interpolate, {}, &phi, 1.0, -1.0),
                 std::invalid_argument);
}

/// Regression (issue 36 item 3): the term damped the surface's motion as its density-weighted
/// sampling saw it, while the mesh moved with the plain trilinear vertex velocities, gas faces
/// and all, which the term hardly sees; bubble_merge past the capillary limit then grew spikes of
/// surface velocity at the grid scale (64 cells, frame 4: 0.30 m/s against the explicit run's
/// 0.21) and the CFL limit, not the capillary one, set its step. The mesh now moves with the
/// term's own weights: term_vertex_velocities() is S u for every point, and a velocity on the
/// gas faces alone barely moves the surface.
TEST(ImplicitTension, TheSurfaceMovesWithTheVelocitiesTheTermSees) {
    DropInAir drop;
    fluid::MacGrid& grid = drop.grid;
    const tracker::SurfaceMesh& mesh = drop.mesh;
    const fluid::Array3<double>& phi = drop.phi;
    InterpolateOptions interpolate;
    interpolate.method = VelocityInterpolation::trilinear;
    const double rho_liquid = 1000.0, rho_gas = 1.2;
    const auto term =
        build_surface_viscosity(mesh, grid, 1.0, interpolate, {}, &phi, rho_liquid, rho_gas);
    ASSERT_EQ(term->points(), mesh.num_vertices());  // the whole sphere lies inside the box
    // Any velocity field: S u point by point (the sphere's points are its vertices in order).
    std::mt19937 random(7);
    std::uniform_real_distribution<double> speed(-1.0, 1.0);
    std::vector<double> faces;
    for (int axis = 0; axis < 3; ++axis)
        for (double& u : grid.velocity(axis).storage()) {
            u = speed(random);
            faces.push_back(u);
        }
    const Eigen::VectorXd sampled =
        term->sample *
        Eigen::Map<const Eigen::VectorXd>(faces.data(), static_cast<Eigen::Index>(faces.size()));
    const std::vector<tracker::Vec3> moved =
        term_vertex_velocities(mesh, grid, interpolate, {}, phi, rho_liquid, rho_gas);
    ASSERT_EQ(moved.size(), static_cast<std::size_t>(mesh.num_vertices()));
    for (int v = 0; v < mesh.num_vertices(); ++v)
        EXPECT_LT((moved[static_cast<std::size_t>(v)] - sampled.segment<3>(3 * v)).norm(), 1e-12);
    // A velocity on the all-gas faces alone: the plain vertex velocities carry a good part of
    // it, the term's about ρ_g/ρ_l of it.
    const std::vector<double> gas = drop.gas_faces();
    std::size_t flat = 0;
    for (int axis = 0; axis < 3; ++axis)
        for (double& u : grid.velocity(axis).storage())
            u = gas[flat++];
    double plain_speed = 0.0, term_speed = 0.0;
    for (const tracker::Vec3& v : interpolate_vertex_velocities(grid, mesh, interpolate))
        plain_speed = std::max(plain_speed, v.cwiseAbs().maxCoeff());
    for (const tracker::Vec3& v :
         term_vertex_velocities(mesh, grid, interpolate, {}, phi, rho_liquid, rho_gas))
        term_speed = std::max(term_speed, v.cwiseAbs().maxCoeff());
    EXPECT_GT(plain_speed, 0.3);
    EXPECT_LT(term_speed, 0.01);
    fluid::Array3<double> small(8, 8, 8, 0.0);
    EXPECT_THROW(term_vertex_velocities(mesh, grid, interpolate, {}, small, 1.0, 1.0),
                 std::invalid_argument);
    EXPECT_THROW(term_vertex_velocities(mesh, grid, interpolate, {}, phi, 0.0, 1.0),
                 std::invalid_argument);
}

/// The viscous CG's Jacobi preconditioner with the surface term (fluid/surface_preconditioner.h)
/// is the exact inverse of D + c Sᵀ K S, in either form: on a sphere's term with a stiffness c far
/// above the diagonal (as past the capillary limit, over gas faces) it gives x back from (D + c
/// SᵀLS) x, it is symmetric, and zero on fixed faces.
TEST(ImplicitTension, SurfacePreconditionerInvertsTheDiagonalPlusTheSurfaceTermExactly) {
    fluid::MacGrid grid(12, 12, 12, 1.0 / 12);
    const tracker::SurfaceMesh mesh = sphere(Vector3d::Constant(0.5), 0.3, 0.06);
    InterpolateOptions interpolate;
    interpolate.method = VelocityInterpolation::trilinear;
    for (SurfaceTermForm form : {SurfaceTermForm::normal, SurfaceTermForm::full}) {
        SCOPED_TRACE(form == SurfaceTermForm::normal ? "normal form" : "full form");
        const auto term =
            build_surface_viscosity(mesh, grid, 1.0, interpolate, {}, nullptr, 1.0, 1.0, form);
        const std::size_t faces = static_cast<std::size_t>(term->sample.cols());
        std::mt19937 random(7);
        std::uniform_real_distribution<double> uniform(-1.0, 1.0);
        std::vector<double> diagonal(faces), x(faces);
        std::vector<char> unknown(faces, 1);
        for (std::size_t f = 0; f < faces; ++f) {
            diagonal[f] = 1.0 + 0.5 * uniform(random);  // gas-like faces: ρ ≈ 1
            unknown[f] = f % 17 != 3;                   // some fixed faces among those sampled
            x[f] = unknown[f] ? uniform(random) : 0.0;
        }
        const double c = 1e4;
        fluid::SurfacePreconditioner preconditioner;
        preconditioner.build(*term, c, diagonal, unknown);
        ASSERT_TRUE(preconditioner.built());
        std::vector<double> y(faces, 0.0);
        term->add_stiffness(c, x, y);
        double largest = 0.0;
        for (std::size_t f = 0; f < faces; ++f) {
            y[f] = unknown[f] ? y[f] + diagonal[f] * x[f] : 0.0;
            largest = std::max(largest, std::abs(y[f]));
        }
        EXPECT_GT(largest, 100.0);  // the surface term dominates
        std::vector<double> back;
        preconditioner.apply(y, back);
        double error = 0.0;
        for (std::size_t f = 0; f < faces; ++f)
            error = std::max(error, std::abs(back[f] - x[f]));
        EXPECT_LT(error, 1e-7);  // of |x| ≤ 1, through a system of condition about c (3e-8, 5e-9)
        // Symmetric: r₁ · M⁻¹ r₂ = r₂ · M⁻¹ r₁.
        std::vector<double> r1(faces), r2(faces), z1, z2;
        for (std::size_t f = 0; f < faces; ++f) {
            r1[f] = unknown[f] ? uniform(random) : 0.0;
            r2[f] = unknown[f] ? uniform(random) : 0.0;
        }
        preconditioner.apply(r1, z1);
        preconditioner.apply(r2, z2);
        EXPECT_NEAR(dot(r1, z2), dot(r2, z1), 1e-12 * std::abs(dot(r1, z2)));
        for (std::size_t f = 0; f < faces; ++f) {
            if (!unknown[f]) {
                EXPECT_EQ(z1[f], 0.0);
            }
        }
        // Sizes that do not fit are refused.
        EXPECT_THROW(preconditioner.build(*term, c, std::vector<double>(faces - 1, 1.0), unknown),
                     std::invalid_argument);
    }
}

/// A gas bubble in water at 3.5 times the capillary step limit, the term sampled trilinearly
/// (not weighted by density): the surface viscosity θσΔt is then far stiffer than the gas faces'
/// mass. With the surface term in the preconditioner (jacobi_surface) the viscous CG converges
/// in 19 iterations from a random field, where the plain diagonal and hypre's PFMG V-cycles
/// (which see the term only through its diagonal) take 100 (66 with the full form, whose
/// blocks do not couple the components), to the same answer.
TEST(ImplicitTension, ViscousSolvePastTheCapillaryLimitConvergesInAFewIterations) {
    const int n = 24;
    const double dx = 1e-4;
    fluid::MacGrid grid(n, n, n, dx);
    const Vector3d centre = Vector3d::Constant(0.5 * n * dx);
    const double radius = 0.3 * n * dx;
    const tracker::SurfaceMesh mesh = sphere(centre, radius, dx);
    fluid::InterfaceInput interface(grid);
    for (int k = 0; k < n; ++k)
        for (int j = 0; j < n; ++j)
            for (int i = 0; i < n; ++i)  // gas inside (φ > 0), water outside
                interface.phi(i, j, k) = radius - (grid.cell_centre(i, j, k) - centre).norm();
    fluid::PhaseOptions phases;  // water and air
    phases.rho_liquid = 1000.0;
    phases.rho_gas = 1.2;
    phases.mu_liquid = 1e-3;
    phases.mu_gas = 1.8e-5;
    phases.sigma = 0.072;
    const double rho_mean = 0.5 * (phases.rho_liquid + phases.rho_gas);
    const double dt_capillary = std::sqrt(rho_mean * dx * dx * dx / (2.0 * M_PI * phases.sigma));
    const double dt = 3.5 * dt_capillary;
    InterpolateOptions interpolate;
    interpolate.method = VelocityInterpolation::trilinear;
    interface.surface_viscosity =
        build_surface_viscosity(mesh, grid, phases.sigma * dt, interpolate, {});
    // Random face velocities up to 0.1 m/s: every scale of wobble on the surface.
    std::mt19937 random(3);
    std::uniform_real_distribution<double> uniform(-0.1, 0.1);
    for (int axis = 0; axis < 3; ++axis)
        for (double& value : grid.velocity(axis).storage())
            value = uniform(random);
    const fluid::BoundaryOptions walls =
        fluid::BoundaryOptions::all(fluid::BoundaryType::free_slip);
    fluid::ViscosityOptions options;
    options.iteration.tolerance = 1e-10;
    options.iteration.max_iterations = 5000;
    const auto solve = [&](fluid::ViscousPreconditioner preconditioner, fluid::MacGrid& solved) {
        options.preconditioner = preconditioner;
        solved = grid;
        const fluid::SolveResult result = fluid::apply_viscosity(
            solved, interface, phases, fluid::FluidMode::two_phase, walls, dt, options);
        EXPECT_TRUE(result.converged);
        return result.iterations;
    };
    fluid::MacGrid surface_grid = grid, jacobi_grid = grid, pfmg_grid = grid;
    const int surface = solve(fluid::ViscousPreconditioner::jacobi_surface, surface_grid);
    const int jacobi = solve(fluid::ViscousPreconditioner::jacobi, jacobi_grid);
    const int pfmg = solve(fluid::ViscousPreconditioner::hypre_pfmg, pfmg_grid);
    EXPECT_LE(surface, 20);
    EXPECT_GT(jacobi, 2 * surface);  // 100 against 19
    EXPECT_GT(pfmg, 2 * surface);    // 101
    for (const fluid::MacGrid* other : {&jacobi_grid, &pfmg_grid}) {
        double difference = 0.0;
        for (int axis = 0; axis < 3; ++axis)
            for (std::size_t f = 0; f < grid.velocity(axis).size(); ++f)
                difference =
                    std::max(difference, std::abs(surface_grid.velocity(axis).storage()[f] -
                                                  other->velocity(axis).storage()[f]));
        EXPECT_LT(difference, 1e-6);  // m/s, of speeds up to 0.1
    }
    std::printf("[ viscous CG ] jacobi_surface %d iterations, jacobi %d, hypre PFMG %d\n", surface,
                jacobi, pfmg);
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
