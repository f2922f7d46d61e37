#include "fluid/phases.h"

#include <cmath>
#include <stdexcept>
#include <string>

namespace meniscus::fluid {

namespace {

void require(bool condition, const char* field, const char* what) {
    if (!condition) {
        throw std::invalid_argument(std::string("phases/") + field + ": must be " + what);
    }
}

}  // namespace

void PhaseOptions::validate() const {
    require(std::isfinite(rho_liquid) && rho_liquid > 0.0, "rho_liquid", "positive (kg/m^3)");
    require(std::isfinite(rho_gas) && rho_gas > 0.0, "rho_gas", "positive (kg/m^3)");
    require(std::isfinite(mu_liquid) && mu_liquid >= 0.0, "mu_liquid", "non-negative (Pa s)");
    require(std::isfinite(mu_gas) && mu_gas >= 0.0, "mu_gas", "non-negative (Pa s)");
    require(std::isfinite(sigma) && sigma >= 0.0, "sigma", "non-negative (N/m)");
}

double face_density(double liquid_fraction, const PhaseOptions& phases, FluidMode mode) {
    if (mode == FluidMode::free_surface) {
        return phases.rho_liquid;
    }
    return liquid_fraction * phases.rho_liquid + (1.0 - liquid_fraction) * phases.rho_gas;
}

}  // namespace meniscus::fluid
