// Advection: constants and linear fields are reproduced exactly; the corrections reduce
// numerical diffusion.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <stdexcept>

#include "fluid/advection.h"
#include "fluid/clamped_trilinear.h"

namespace meniscus::fluid {
namespace {

constexpr AdvectionScheme ALL_SCHEMES[] = {AdvectionScheme::semi_lagrangian, AdvectionScheme::bfecc,
                                           AdvectionScheme::maccormack};

void set_uniform_velocity(MacGrid& grid, const Eigen::Vector3d& velocity) {
    for (int axis = 0; axis < 3; ++axis) {
        grid.velocity(axis).fill(velocity[axis]);
    }
}

/// Trilinear interpolation written out plainly (clamp, floor, the lower index at most n − 2, the
/// same order of blends as ClampedTrilinear::blend): the reference of the samplers' bit-for-bit
/// results. Also the smallest and largest of the 8 samples.
TrilinearSample reference_trilinear(const Array3<double>& field, const Eigen::Vector3d& offset,
                                    const Eigen::Vector3d& g) {
    const int n[3] = {field.ni(), field.nj(), field.nk()};
    int lo[3], up[3];
    double t[3];
    for (int a = 0; a < 3; ++a) {
        if (n[a] == 1) {
            lo[a] = up[a] = 0;
            t[a] = 0.0;
            continue;
        }
        const double s = std::clamp(g[a] - offset[a], 0.0, n[a] - 1.0);
        lo[a] = std::min(static_cast<int>(std::floor(s)), n[a] - 2);
        up[a] = lo[a] + 1;
        t[a] = s - lo[a];
    }
    double c[8];
    for (int corner = 0; corner < 8; ++corner)
        c[corner] = field((corner & 1) ? up[0] : lo[0], (corner & 2) ? up[1] : lo[1],
                          (corner & 4) ? up[2] : lo[2]);
    const auto lerp = [](double a, double b, double f) { return a + f * (b - a); };
    const double c0 = lerp(lerp(c[0], c[1], t[0]), lerp(c[2], c[3], t[0]), t[1]);
    const double c1 = lerp(lerp(c[4], c[5], t[0]), lerp(c[6], c[7], t[0]), t[1]);
    return {lerp(c0, c1, t[2]), *std::min_element(c, c + 8), *std::max_element(c, c + 8)};
}

TEST(FluidAdvection, ClampedSamplersMatchAPlainTrilinearInterpolationBitForBit) {
    // One cell thick along y: u and w have a single sample along it there. Points up to two
    // cells outside the box on every side (clamped), and repeated sample values (ties in the
    // bounds).
    MacGrid grid(5, 1, 4, 0.1);
    std::mt19937 random(7);
    std::uniform_real_distribution<double> value(-1.0, 1.0);
    for (int axis = 0; axis < 3; ++axis)
        for (double& v : grid.velocity(axis).storage())
            v = std::round(4.0 * value(random)) / 4.0;
    const ClampedVelocity velocity(grid.u(), grid.v(), grid.w());
    std::uniform_real_distribution<double> x(-2.0, 7.0), y(-2.0, 3.0), z(-2.0, 6.0);
    for (int point = 0; point < 2000; ++point) {
        const Eigen::Vector3d g(x(random), y(random), z(random));
        const Eigen::Vector3d sampled = velocity.value(g);
        for (int axis = 0; axis < 3; ++axis) {
            const FieldLocation location = face_location(axis);
            const Array3<double>& faces = grid.velocity(axis);
            const TrilinearSample expected = reference_trilinear(faces, field_offset(location), g);
            const TrilinearSample one = ClampedTrilinear(faces, field_offset(location)).sample(g);
            ASSERT_EQ(sampled[axis], expected.value) << "axis " << axis << " at " << g.transpose();
            ASSERT_EQ(one.value, expected.value);
            ASSERT_EQ(one.min, expected.min);
            ASSERT_EQ(one.max, expected.max);
            ASSERT_EQ(interpolate_trilinear(faces, location, g), expected.value);
        }
    }
}

TEST(FluidAdvection, ConstantFieldIsExactForEveryScheme) {
    MacGrid grid(12, 10, 8, 0.1);
    // A swirling, non-uniform velocity field.
    for (int axis = 0; axis < 3; ++axis) {
        Array3<double>& faces = grid.velocity(axis);
        for (int k = 0; k < faces.nk(); ++k) {
            for (int j = 0; j < faces.nj(); ++j) {
                for (int i = 0; i < faces.ni(); ++i) {
                    const Eigen::Vector3d x = grid.face_centre(axis, i, j, k);
                    faces(i, j, k) = std::sin(3.0 * x.x() + axis) * std::cos(2.0 * x.y() - x.z());
                }
            }
        }
    }
    for (AdvectionScheme scheme : ALL_SCHEMES) {
        Array3<double> field(12, 10, 8, 3.25);
        advect_field(grid, 0.05, FieldLocation::cell_centre, {scheme}, field);
        for (double value : field.storage()) {
            EXPECT_DOUBLE_EQ(value, 3.25);
        }
    }
}

TEST(FluidAdvection, LinearFieldInUniformFlowIsExactAwayFromInflow) {
    const int n = 16;
    const double dx = 1.0 / n;
    MacGrid grid(n, n, n, dx);
    const Eigen::Vector3d velocity(0.7, -0.4, 0.25);
    set_uniform_velocity(grid, velocity);
    const Eigen::Vector3d gradient(2.0, -1.0, 0.5);
    const double dt = 1.3 * dx;  // about one cell per step
    for (AdvectionScheme scheme : ALL_SCHEMES) {
        Array3<double> field(n, n, n);
        for (int k = 0; k < n; ++k) {
            for (int j = 0; j < n; ++j) {
                for (int i = 0; i < n; ++i) {
                    field(i, j, k) = gradient.dot(grid.cell_centre(i, j, k));
                }
            }
        }
        advect_field(grid, dt, FieldLocation::cell_centre, {scheme}, field);
        // Cells whose back-traced (and, for the corrections, forward-traced) points stay at
        // least one sample inside the lattice.
        const int margin = 3;
        double max_error = 0.0;
        for (int k = margin; k < n - margin; ++k) {
            for (int j = margin; j < n - margin; ++j) {
                for (int i = margin; i < n - margin; ++i) {
                    const Eigen::Vector3d x = grid.cell_centre(i, j, k);
                    max_error = std::max(
                        max_error, std::abs(field(i, j, k) - gradient.dot(x - dt * velocity)));
                }
            }
        }
        EXPECT_LT(max_error, 1e-12) << "scheme " << static_cast<int>(scheme);
    }
}

TEST(FluidAdvection, LinearShearVelocityIsASteadyExactSolution) {
    // u = a + b·y, v = w = 0 is a steady solution of u_t + (u·∇)u = 0 and is linear, so every
    // scheme must keep it exactly (everywhere: the back-trace only moves along x).
    const int n = 12;
    MacGrid grid(n, n, n, 0.25);
    for (int k = 0; k < n; ++k) {
        for (int j = 0; j < n; ++j) {
            for (int i = 0; i <= n; ++i) {
                grid.u()(i, j, k) = 0.3 + 0.8 * grid.face_centre(0, i, j, k).y();
            }
        }
    }
    const MacGrid initial = grid;
    for (AdvectionScheme scheme : ALL_SCHEMES) {
        grid = initial;
        advect_velocity(grid, 0.2, {scheme});
        double max_error = 0.0;
        for (int axis = 0; axis < 3; ++axis) {
            for (std::size_t f = 0; f < grid.velocity(axis).size(); ++f) {
                max_error = std::max(max_error,
                                     std::abs(grid.velocity(axis)[f] - initial.velocity(axis)[f]));
            }
        }
        EXPECT_LT(max_error, 1e-13) << "scheme " << static_cast<int>(scheme);
    }
}

TEST(FluidAdvection, CorrectionsAreLessDiffusiveThanPlainSemiLagrangian) {
    // Translate a smooth bump by a quarter of the box in 20 steps; compare with the exact shift.
    const int n = 48;
    const double dx = 1.0 / n;
    MacGrid grid(n, n, 1, dx);
    set_uniform_velocity(grid, Eigen::Vector3d(1.0, 0.5, 0.0));
    const Eigen::Vector3d centre(0.3, 0.35, 0.0);
    const double width = 0.08;
    const auto bump = [&](const Eigen::Vector3d& x) {
        const Eigen::Vector2d d(x.x() - centre.x(), x.y() - centre.y());
        return std::exp(-d.squaredNorm() / (width * width));
    };
    const int steps = 20;
    const double dt = 0.25 / steps;
    double error[3] = {0.0, 0.0, 0.0};
    int s = 0;
    for (AdvectionScheme scheme : ALL_SCHEMES) {
        Array3<double> field(n, n, 1);
        for (int j = 0; j < n; ++j) {
            for (int i = 0; i < n; ++i) {
                field(i, j, 0) = bump(grid.cell_centre(i, j, 0));
            }
        }
        for (int step = 0; step < steps; ++step) {
            advect_field(grid, dt, FieldLocation::cell_centre, {scheme}, field);
        }
        const Eigen::Vector3d shift = steps * dt * Eigen::Vector3d(1.0, 0.5, 0.0);
        for (int j = 0; j < n; ++j) {
            for (int i = 0; i < n; ++i) {
                error[s] = std::max(
                    error[s], std::abs(field(i, j, 0) - bump(grid.cell_centre(i, j, 0) - shift)));
            }
        }
        ++s;
    }
    std::printf("bump max error: semi-Lagrangian %.4f, BFECC %.4f, MacCormack %.4f\n", error[0],
                error[1], error[2]);
    EXPECT_LT(error[1], 0.5 * error[0]);
    EXPECT_LT(error[2], 0.5 * error[0]);
}

TEST(FluidAdvection, AdvectingTheGridsOwnVelocityArrayIsRefused) {
    // The corrected schemes overwrite the field while they sample the grid's velocities: a
    // velocity array passed as the field would be read half-updated.
    MacGrid grid(6, 5, 4, 0.1);
    set_uniform_velocity(grid, Eigen::Vector3d(0.3, -0.2, 0.1));
    for (int axis = 0; axis < 3; ++axis)
        EXPECT_THROW(advect_field(grid, 0.05, face_location(axis), {AdvectionScheme::maccormack},
                                  grid.velocity(axis)),
                     std::invalid_argument);
    Array3<double> copy = grid.u();
    EXPECT_NO_THROW(
        advect_field(grid, 0.05, FieldLocation::x_face, {AdvectionScheme::maccormack}, copy));
}

}  // namespace
}  // namespace meniscus::fluid
