#pragma once
// What the pressure tests share: tight solver options and the body force of a still pool.
#include "fluid/mac_grid.h"
#include "fluid/pressure.h"

namespace meniscus::fluid::pressure_test {

constexpr double GRAVITY = 9.81;     // m/s², acting along −z
constexpr double TIGHT_TOL = 1e-10;  // relative residual for the exactness tests

inline PressureOptions tight_options(PressureSolver solver) {
    PressureOptions options;
    options.solver = solver;
    options.iteration.tolerance = TIGHT_TOL;
    options.iteration.max_iterations = 2000;
    return options;
}

/// Sets the interior w faces to the velocity gravity adds in dt (u* = g dt).
inline void add_gravity(MacGrid& grid, double dt) {
    for (int k = 1; k < grid.nz(); ++k) {
        for (int j = 0; j < grid.ny(); ++j) {
            for (int i = 0; i < grid.nx(); ++i) {
                grid.w()(i, j, k) -= GRAVITY * dt;
            }
        }
    }
}

}  // namespace meniscus::fluid::pressure_test
