// Periodic faces in the pressure projection (issue 39): the seam between cell n−1 and cell 0 in
// the matrix, its three solvers and the multigrid hierarchy, on even and odd cell counts.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "fluid/fluid_solver.h"
#include "fluid/forces.h"
#include "fluid/multigrid.h"
#include "fluid/pressure.h"

namespace meniscus::fluid {
namespace {

constexpr double DX = 1e-3;   // m
constexpr double DT = 1e-3;   // s
constexpr double RHO = 1000;  // kg/m³, the liquid
constexpr double TIGHT_TOL = 1e-11;

PressureOptions tight(PressureSolver solver) {
    PressureOptions options;
    options.solver = solver;
    options.iteration.tolerance = TIGHT_TOL;
    options.iteration.max_iterations = 3000;
    return options;
}

/// Free-slip walls, with the axes flagged in `periodic` periodic instead.
BoundaryOptions boundaries_with(std::array<bool, 3> periodic) {
    BoundaryOptions boundaries = BoundaryOptions::all(BoundaryType::free_slip);
    for (int axis = 0; axis < 3; ++axis)
        if (periodic[static_cast<std::size_t>(axis)]) {
            boundaries.face(axis, 0).type = BoundaryType::periodic;
            boundaries.face(axis, 1).type = BoundaryType::periodic;
        }
    return boundaries;
}

int wrap(int i, int n) {
    return ((i % n) + n) % n;
}

/// A random field on the n0 × n1 × n2 cells, indexed periodically.
struct PeriodicField {
    std::array<int, 3> n;
    std::vector<double> values;
    double operator()(int i, int j, int k) const {
        return values[static_cast<std::size_t>(wrap(i, n[0]) +
                                               n[0] * (wrap(j, n[1]) + n[1] * wrap(k, n[2])))];
    }
};

PeriodicField random_field(std::array<int, 3> n, unsigned seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> uniform(-1.0, 1.0);
    PeriodicField field{n, std::vector<double>(static_cast<std::size_t>(n[0] * n[1] * n[2]))};
    for (double& v : field.values)
        v = uniform(rng);
    return field;
}

/// Sets the faces of `grid` to curl ψ + ∇q of periodic fields (ψ on the cell edges, its
/// component c on the edges parallel to axis c at the cells' min corners, q at the cell centres):
/// the curl part is exactly divergence-free on the periodic MAC grid and the gradient part is
/// what a periodic projection removes. `curl` false leaves the curl part out. The faces on the
/// box's max sides repeat those on its min sides.
void set_curl_plus_gradient(MacGrid& grid, const std::array<PeriodicField, 3>& psi,
                            const PeriodicField& q, bool curl, double scale) {
    for (int a = 0; a < 3; ++a) {
        const int b = (a + 1) % 3, c = (a + 2) % 3;
        Array3<double>& faces = grid.velocity(a);
        for (int k = 0; k < faces.nk(); ++k)
            for (int j = 0; j < faces.nj(); ++j)
                for (int i = 0; i < faces.ni(); ++i) {
                    const std::array<int, 3> f = {i, j, k};
                    std::array<int, 3> lo = f;
                    --lo[static_cast<std::size_t>(a)];
                    double value = (q(f[0], f[1], f[2]) - q(lo[0], lo[1], lo[2])) / DX;
                    if (curl) {
                        // (curl ψ)_a = ∂ψ_c/∂x_b − ∂ψ_b/∂x_c on the a-face.
                        std::array<int, 3> up_b = f, up_c = f;
                        ++up_b[static_cast<std::size_t>(b)];
                        ++up_c[static_cast<std::size_t>(c)];
                        const PeriodicField& pc = psi[static_cast<std::size_t>(c)];
                        const PeriodicField& pb = psi[static_cast<std::size_t>(b)];
                        value += (pc(up_b[0], up_b[1], up_b[2]) - pc(f[0], f[1], f[2])) / DX -
                                 (pb(up_c[0], up_c[1], up_c[2]) - pb(f[0], f[1], f[2])) / DX;
                    }
                    faces(i, j, k) = scale * value;
                }
    }
}

double max_difference(const MacGrid& a, const MacGrid& b) {
    double largest = 0.0;
    for (int axis = 0; axis < 3; ++axis)
        for (std::size_t f = 0; f < a.velocity(axis).size(); ++f)
            largest = std::max(largest, std::abs(a.velocity(axis)[f] - b.velocity(axis)[f]));
    return largest;
}

double max_divergence(const MacGrid& grid) {
    double largest = 0.0;
    for (int k = 0; k < grid.nz(); ++k)
        for (int j = 0; j < grid.ny(); ++j)
            for (int i = 0; i < grid.nx(); ++i)
                largest = std::max(largest, std::abs(grid.divergence(i, j, k)));
    return largest;
}

/// A gas bubble of radius `radius` (m) centred at `centre`, in the liquid, with the periodic
/// images of the axes flagged in `periodic` (φ the distance to the nearest image).
InterfaceInput bubble(const MacGrid& grid, const Eigen::Vector3d& centre, double radius,
                      std::array<bool, 3> periodic) {
    InterfaceInput interface(grid);
    const Eigen::Vector3d size = DX * Eigen::Vector3d(grid.nx(), grid.ny(), grid.nz());
    for (int k = 0; k < grid.nz(); ++k)
        for (int j = 0; j < grid.ny(); ++j)
            for (int i = 0; i < grid.nx(); ++i) {
                Eigen::Vector3d d = grid.cell_centre(i, j, k) - centre;
                for (int a = 0; a < 3; ++a)
                    if (periodic[static_cast<std::size_t>(a)])
                        d[a] -= size[a] * std::round(d[a] / size[a]);
                interface.phi(i, j, k) = radius - d.norm();  // negative (liquid) outside
            }
    for (int axis = 0; axis < 3; ++axis)
        interface.kappa(axis).fill(-2.0 / radius);
    return interface;
}

PhaseOptions water_and_air() {
    PhaseOptions phases;
    phases.rho_liquid = RHO;
    phases.rho_gas = 1.0;
    phases.sigma = 0.072;
    return phases;
}

struct Case {
    PressureSolver solver;
    std::array<int, 3> cells;
};

class PeriodicProjection : public ::testing::TestWithParam<Case> {};

// In a box periodic along every axis, u* = curl ψ + ∇q of random periodic fields projects to
// curl ψ exactly (to the solver's tolerance): the seam faces are interior faces of the operator,
// nothing leaks through them, and every cell, the seam's included, ends divergence-free. Even
// and odd cell counts, every solver.
TEST_P(PeriodicProjection, RemovesTheGradientAndKeepsTheCurlOfPeriodicFields) {
    const Case param = GetParam();
    const std::array<int, 3> n = param.cells;
    const std::array<PeriodicField, 3> psi = {random_field(n, 1), random_field(n, 2),
                                              random_field(n, 3)};
    const PeriodicField q = random_field(n, 4);
    const double scale = 1e-6;  // m²/s: velocities of a few mm/s
    MacGrid grid(n[0], n[1], n[2], DX);
    MacGrid curl_only(n[0], n[1], n[2], DX);
    set_curl_plus_gradient(grid, psi, q, true, scale);
    set_curl_plus_gradient(curl_only, psi, PeriodicField{n, std::vector<double>(q.values.size())},
                           true, scale);
    ASSERT_GT(max_difference(grid, curl_only), 1e-3);  // the gradient part is there to remove
    ASSERT_LT(max_divergence(curl_only), 1e-9);
    const BoundaryOptions periodic = boundaries_with({true, true, true});
    const InterfaceInput all_liquid(grid);
    Array3<double> pressure;
    const ProjectionResult result = project(grid, all_liquid, water_and_air(), FluidMode::two_phase,
                                            DT, tight(param.solver), pressure, periodic);
    ASSERT_TRUE(result.solve.converged);
    EXPECT_TRUE(result.singular);  // no Dirichlet face: p only up to a constant
    EXPECT_LT(max_difference(grid, curl_only), 1e-9);
    EXPECT_LT(max_divergence(grid), 1e-8);
    // The max faces still repeat the min faces.
    for (int j = 0; j < n[1]; ++j)
        EXPECT_EQ(grid.u()(0, j, 1), grid.u()(n[0], j, 1));
}

// Periodic along x only, free-slip walls across y and z: u* = ∇q on the faces inside the box
// (the walls' faces hold 0) projects to rest.
TEST_P(PeriodicProjection, RemovesAGradientWithOnePeriodicAxisBetweenWalls) {
    const Case param = GetParam();
    const std::array<int, 3> n = param.cells;
    const PeriodicField q = random_field(n, 5);
    MacGrid grid(n[0], n[1], n[2], DX);
    set_curl_plus_gradient(grid, {}, q, false, 1e-6);
    const BoundaryOptions boundaries = boundaries_with({true, false, false});
    apply_boundary_velocity(grid, boundaries);  // walls 0, x_max the copy of x_min
    const InterfaceInput all_liquid(grid);
    Array3<double> pressure;
    const ProjectionResult result = project(grid, all_liquid, water_and_air(), FluidMode::two_phase,
                                            DT, tight(param.solver), pressure, boundaries);
    ASSERT_TRUE(result.solve.converged);
    const Eigen::Vector3d largest = grid.max_abs_velocity();
    EXPECT_LT(largest.maxCoeff(), 1e-9) << largest.transpose();
}

INSTANTIATE_TEST_SUITE_P(Solvers, PeriodicProjection,
                         ::testing::Values(Case{PressureSolver::multigrid_pcg, {16, 16, 16}},
                                           Case{PressureSolver::multigrid_pcg, {15, 13, 17}},
                                           Case{PressureSolver::mic0_pcg, {16, 16, 16}},
                                           Case{PressureSolver::mic0_pcg, {15, 13, 17}},
                                           Case{PressureSolver::eigen_ic_cg, {15, 13, 17}}),
                         [](const ::testing::TestParamInfo<Case>& param_info) {
                             const std::string solver =
                                 param_info.param.solver == PressureSolver::multigrid_pcg
                                     ? "Multigrid"
                                 : param_info.param.solver == PressureSolver::mic0_pcg
                                     ? "Mic0"
                                     : "EigenIcCg";
                             return solver + (param_info.param.cells[0] % 2 == 0 ? "Even" : "Odd");
                         });

/// The pressure system of a bubble crossing every seam of a periodic box of `n` cells (density
/// ratio 1000, its surface-tension jump on the right-hand side), and a free-slip box's with the
/// bubble in its middle.
PressureSystem bubble_system(std::array<int, 3> n, bool periodic, MacGrid& grid) {
    grid = MacGrid(n[0], n[1], n[2], DX);
    const std::array<bool, 3> axes = {periodic, periodic, periodic};
    const Eigen::Vector3d size = DX * Eigen::Vector3d(n[0], n[1], n[2]);
    const Eigen::Vector3d centre = periodic ? Eigen::Vector3d(Eigen::Vector3d(0.1, 0.2, 0.3) * DX)
                                            : Eigen::Vector3d(0.5 * size);
    const InterfaceInput interface = bubble(grid, centre, 0.2 * size.minCoeff(), axes);
    apply_gravity(grid, Eigen::Vector3d(0, 0, -9.81), DT, boundaries_with(axes));
    return build_pressure_system(grid, interface, water_and_air(), FluidMode::two_phase, DT,
                                 tight(PressureSolver::multigrid_pcg), boundaries_with(axes));
}

std::vector<double> random_vector(std::size_t size, unsigned seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> uniform(-1.0, 1.0);
    std::vector<double> v(size);
    for (double& x : v)
        x = uniform(rng);
    return v;
}

double dot_product(const std::vector<double>& a, const std::vector<double>& b) {
    double sum = 0.0;
    for (std::size_t i = 0; i < a.size(); ++i)
        sum += a[i] * b[i];
    return sum;
}

// PCG needs a symmetric preconditioner. With odd cell counts the two cells beside a periodic
// seam have the same red–black colour; the smoother reads its neighbours across the seam from a
// copy taken before each half sweep, which keeps the V-cycle symmetric (and MIC(0), which leaves
// the seam out, is symmetric by construction). Also checked: the matrix itself is symmetric
// with its seam entries, and the constant is its null space.
TEST(PeriodicPreconditioners, AreSymmetricOnOddPeriodicGrids) {
    MacGrid grid(1, 1, 1, DX);
    const PressureSystem system = bubble_system({15, 13, 17}, true, grid);
    const PoissonMatrix& a = system.matrix;
    ASSERT_TRUE(a.periodic[0] && a.periodic[1] && a.periodic[2]);
    const std::vector<double> x = random_vector(a.size(), 7), y = random_vector(a.size(), 8);
    std::vector<double> ax, ay;
    a.apply(x, ax);
    a.apply(y, ay);
    EXPECT_NEAR(dot_product(x, ay), dot_product(y, ax), 1e-12 * std::abs(dot_product(x, ay)));
    std::vector<double> ones(a.size(), 1.0), a_ones;
    a.apply(ones, a_ones);
    double largest_row = 0.0;
    for (double v : a_ones)
        largest_row = std::max(largest_row, std::abs(v));
    EXPECT_LT(largest_row, 1e-12 * a.diag.storage()[0]);

    MultigridOptions deep;  // down to 1 × 1 × 2 cells: odd seams on every level, and the folds
    deep.coarsest_max_cells = 1;
    deep.single_precision = false;  // symmetric to double's rounding
    const MultigridPreconditioner multigrid(a, deep);
    EXPECT_EQ(multigrid.levels(), 5);
    deep.single_precision = true;  // the default: symmetric to float's rounding
    const MultigridPreconditioner in_float(a, deep);
    const Mic0Preconditioner mic0(a);
    const std::pair<const Preconditioner*, double> checks[] = {
        {&multigrid, 1e-10}, {&in_float, 1e-5}, {&mic0, 1e-10}};
    for (const auto& [m, tolerance] : checks) {
        std::vector<double> mx, my;
        m->apply(x, mx);
        m->apply(y, my);
        const double xmy = dot_product(x, my), ymx = dot_product(y, mx);
        EXPECT_NEAR(xmy, ymx, tolerance * std::abs(xmy));
        EXPECT_GT(dot_product(x, mx), 0.0);
    }
}

// The multigrid keeps its rate with periodic faces: a bubble at density ratio 1000 across every
// seam of a periodic box takes about as many PCG iterations as the same bubble in the middle of
// a free-slip box, at two resolutions and with even and odd counts; the three solvers agree.
TEST(PeriodicPreconditioners, MultigridKeepsItsIterationCountAcrossSeams) {
    for (const std::array<int, 3> n :
         {std::array<int, 3>{32, 32, 32}, std::array<int, 3>{31, 33, 30},
          std::array<int, 3>{64, 64, 64}}) {
        int iterations[2] = {0, 0};
        for (int periodic = 0; periodic < 2; ++periodic) {
            MacGrid grid(1, 1, 1, DX);
            const PressureSystem system = bubble_system(n, periodic == 1, grid);
            PressureOptions options = tight(PressureSolver::multigrid_pcg);
            options.iteration.tolerance = 1e-8;
            Array3<double> pressure;
            const SolveResult result = solve_pressure_system(system, options, pressure);
            ASSERT_TRUE(result.converged);
            iterations[periodic] = result.iterations;
            if (periodic == 1 && n[0] == 31) {
                for (PressureSolver other :
                     {PressureSolver::mic0_pcg, PressureSolver::eigen_ic_cg}) {
                    options.solver = other;
                    Array3<double> reference;
                    ASSERT_TRUE(solve_pressure_system(system, options, reference).converged);
                    double largest = 0.0, scale = 0.0;
                    for (std::size_t c = 0; c < pressure.size(); ++c) {
                        largest = std::max(largest, std::abs(pressure[c] - reference[c]));
                        scale = std::max(scale, std::abs(reference[c]));
                    }
                    EXPECT_LT(largest, 1e-5 * scale);
                }
            }
        }
        std::printf("%d x %d x %d: multigrid PCG %d iterations in the free-slip box, %d periodic\n",
                    n[0], n[1], n[2], iterations[0], iterations[1]);
        EXPECT_LE(iterations[1], iterations[0] + 3);
    }
}

// A periodic face is paired with its opposite, and the errors say which and with what.
TEST(PeriodicBoundaries, ErrorsNameTheFaceAndTheConflict) {
    BoundaryOptions boundaries = BoundaryOptions::all(BoundaryType::no_slip);
    boundaries.y_min.type = BoundaryType::periodic;
    try {
        boundaries.validate();
        FAIL() << "a periodic face paired with a wall";
    } catch (const std::invalid_argument& e) {
        EXPECT_EQ(std::string(e.what()),
                  "y_max: y_min is periodic and y_max no_slip: a periodic face is paired with the "
                  "opposite face, which must be periodic too");
    }
    boundaries.y_max.type = BoundaryType::periodic;
    EXPECT_NO_THROW(boundaries.validate());
    FluidOptions options;  // the fluid step takes them
    options.boundaries = boundaries;
    EXPECT_NO_THROW(options.validate());
}

// The max face of a periodic pair repeats the min face after apply_boundary_velocity(), and
// gravity accelerates both copies like interior faces.
TEST(PeriodicBoundaries, MaxFaceRepeatsTheMinFace) {
    MacGrid grid(4, 3, 5, DX);
    const BoundaryOptions boundaries = boundaries_with({false, false, true});
    for (int j = 0; j < 3; ++j)
        for (int i = 0; i < 4; ++i) {
            grid.w()(i, j, 0) = 0.1 * i + 0.01 * j;
            grid.w()(i, j, 5) = -1.0;
        }
    apply_boundary_velocity(grid, boundaries);
    apply_gravity(grid, Eigen::Vector3d(0, 0, -10), 0.01, boundaries);
    for (int j = 0; j < 3; ++j)
        for (int i = 0; i < 4; ++i) {
            EXPECT_DOUBLE_EQ(grid.w()(i, j, 0), 0.1 * i + 0.01 * j - 0.1);
            EXPECT_EQ(grid.w()(i, j, 5), grid.w()(i, j, 0));
        }
    EXPECT_EQ(grid.u()(0, 1, 1), 0.0);  // the x faces are walls
}

}  // namespace
}  // namespace meniscus::fluid
