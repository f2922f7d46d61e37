#pragma once
/// \file Material properties of the two phases and how the gas is modelled.

namespace meniscus::fluid {

/// How the gas phase enters the flow solve.
enum class FluidMode {
    /// Liquid and gas are both solved (variable density and viscosity, ghost-fluid jump
    /// p_liquid − p_gas = σκ across the interface).
    two_phase,
    /// The gas is a void at zero pressure: only liquid cells are unknowns, the interface carries
    /// the Dirichlet condition p_liquid = σκ placed at the θ-weighted interface position.
    free_surface
};

/// Densities, viscosities and surface tension (SI units). Defaults: water and air at 20 °C.
struct PhaseOptions {
    double rho_liquid = 1000.0;  ///< liquid density, kg/m³ (> 0)
    double rho_gas = 1.2;        ///< gas density, kg/m³ (> 0; ignored in free_surface mode)
    double mu_liquid = 1.0e-3;   ///< liquid dynamic viscosity, Pa·s (≥ 0)
    double mu_gas = 1.8e-5;      ///< gas dynamic viscosity, Pa·s (≥ 0; ignored in free_surface)
    double sigma = 0.0728;       ///< surface tension coefficient, N/m (≥ 0)

    /// Throws std::invalid_argument naming the first field that is out of range or not finite.
    void validate() const;
};

/// Default lower clamp of a face's liquid fraction θ where the free surface crosses it (the
/// ghost-fluid Dirichlet coefficient β/θ and the viscous face inertia ρθ).
constexpr double DEFAULT_MIN_LIQUID_FRACTION = 1.0e-3;

/// Density (kg/m³) of a face whose segment between the two adjacent cell centres is a fraction
/// `liquid_fraction` ∈ [0, 1] in the liquid: θ ρ_l + (1 − θ) ρ_g (Liu–Fedkiw–Kang: the
/// harmonic mean of the face coefficients 1/ρ weighted by θ). In free_surface mode: ρ_l.
double face_density(double liquid_fraction, const PhaseOptions& phases, FluidMode mode);

}  // namespace meniscus::fluid
