#include "fluid/interface_input.h"

#include "fluid/surface_viscosity.h"

#include <cmath>
#include <stdexcept>
#include <string>

namespace meniscus::fluid {

namespace {

void check_size(const Array3<double>& field, int ni, int nj, int nk, const char* name) {
    if (field.ni() != ni || field.nj() != nj || field.nk() != nk) {
        throw std::invalid_argument(std::string("InterfaceInput.") + name + " must be " +
                                    std::to_string(ni) + " x " + std::to_string(nj) + " x " +
                                    std::to_string(nk) + " for this grid");
    }
}

}  // namespace

InterfaceInput::InterfaceInput(const MacGrid& grid)
    : phi(grid.nx(), grid.ny(), grid.nz(), -grid.dx()),
      kappa_u(grid.nx() + 1, grid.ny(), grid.nz(), 0.0),
      kappa_v(grid.nx(), grid.ny() + 1, grid.nz(), 0.0),
      kappa_w(grid.nx(), grid.ny(), grid.nz() + 1, 0.0) {}

const Array3<double>& InterfaceInput::kappa(int axis) const {
    return axis == 0 ? kappa_u : (axis == 1 ? kappa_v : kappa_w);
}

Array3<double>& InterfaceInput::kappa(int axis) {
    return axis == 0 ? kappa_u : (axis == 1 ? kappa_v : kappa_w);
}

void InterfaceInput::check_sizes(const MacGrid& grid) const {
    const int nx = grid.nx(), ny = grid.ny(), nz = grid.nz();
    check_size(phi, nx, ny, nz, "phi");
    check_size(kappa_u, nx + 1, ny, nz, "kappa_u");
    check_size(kappa_v, nx, ny + 1, nz, "kappa_v");
    check_size(kappa_w, nx, ny, nz + 1, "kappa_w");
}

void InterfaceInput::validate(const MacGrid& grid) const {
    check_sizes(grid);
    for (double value : phi.storage()) {
        if (!std::isfinite(value)) {
            throw std::invalid_argument("InterfaceInput.phi holds a non-finite value");
        }
    }
    if (surface_viscosity)
        surface_viscosity->validate(grid);
}

double liquid_fraction(double phi_a, double phi_b) {
    const bool liquid_a = is_liquid(phi_a);
    const bool liquid_b = is_liquid(phi_b);
    if (liquid_a && liquid_b) {
        return 1.0;
    }
    if (!liquid_a && !liquid_b) {
        return 0.0;
    }
    const double phi_l = liquid_a ? phi_a : phi_b;
    const double phi_g = liquid_a ? phi_b : phi_a;
    return phi_l / (phi_l - phi_g);
}

double face_pressure_jump(double phi_lo, double phi_hi, double sigma, double kappa) {
    const bool liquid_lo = is_liquid(phi_lo);
    const bool liquid_hi = is_liquid(phi_hi);
    if (liquid_lo == liquid_hi) {
        return 0.0;
    }
    const double liquid_minus_gas = sigma * kappa;
    return liquid_hi ? liquid_minus_gas : -liquid_minus_gas;
}

}  // namespace meniscus::fluid
