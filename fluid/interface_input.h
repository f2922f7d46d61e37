#pragma once
/// \file The interface as the fluid solver sees it: a level set at cell centres and the mean
/// curvature at the faces the interface crosses. Filled by coupling/, never by the mesh itself.

#include "fluid/array3.h"
#include "fluid/mac_grid.h"

#include <memory>

namespace meniscus::fluid {

struct SurfaceViscosity;

/// Interface description for one fluid step.
///
/// - `phi`: signed distance (m) at cell centres, nx × ny × nz, NEGATIVE IN THE LIQUID. A cell is
///   liquid iff φ < 0 (φ = 0 counts as gas).
/// - `kappa_u`, `kappa_v`, `kappa_w`: mean curvature κ (1/m) on x-, y- and z-faces, sized like
///   MacGrid::u(), v(), w(). κ is the sum of the principal curvatures (2/R on a sphere of radius
///   R), POSITIVE FOR A CONVEX LIQUID BLOB (a drop) and negative around a gas bubble. Only read on
///   faces whose two adjacent cells have φ of opposite sign; other entries are ignored.
/// - The pressure jump imposed on such a face is p_liquid − p_gas = σκ (higher inside a drop).
/// - `surface_viscosity` (optional): the implicit part of semi-implicit surface tension, which
///   the viscous solve adds (surface_viscosity.h); null for explicit surface tension.
struct InterfaceInput {
    Array3<double> phi;      ///< level set at cell centres, m, negative in the liquid
    Array3<double> kappa_u;  ///< κ on x-faces, 1/m, (nx+1) × ny × nz
    Array3<double> kappa_v;  ///< κ on y-faces, 1/m, nx × (ny+1) × nz
    Array3<double> kappa_w;  ///< κ on z-faces, 1/m, nx × ny × (nz+1)
    std::shared_ptr<const SurfaceViscosity> surface_viscosity;  ///< null: none

    InterfaceInput() = default;
    /// Arrays sized for `grid`: φ = −dx everywhere (all liquid), κ = 0.
    explicit InterfaceInput(const MacGrid& grid);

    /// κ on the faces of velocity component `axis` (0 = x, 1 = y, 2 = z).
    const Array3<double>& kappa(int axis) const;
    Array3<double>& kappa(int axis);

    /// Throws std::invalid_argument naming the field if an array is not sized for `grid` or φ
    /// holds a non-finite value.
    void validate(const MacGrid& grid) const;
    /// validate()'s size checks alone (no pass over φ), for the grid loops that index the arrays
    /// by the grid's flat indices.
    void check_sizes(const MacGrid& grid) const;
};

/// True when a cell with level set value `phi` is liquid (φ < 0).
inline bool is_liquid(double phi) {
    return phi < 0.0;
}

/// Fraction θ ∈ [0, 1] of the segment between two neighbouring cell centres that lies in the
/// liquid, from the level set at its ends assuming φ linear along it: 1 if both are liquid, 0 if
/// both are gas, otherwise φ_l / (φ_l − φ_g) with φ_l the liquid end's value.
double liquid_fraction(double phi_a, double phi_b);

/// Pressure jump (Pa) seen when stepping across a face from cell `lo` (level set phi_lo) to cell
/// `hi` (phi_hi): p(hi side) − p(lo side) at the interface. −σκ from liquid to gas, +σκ from gas
/// to liquid, 0 when the face is not crossed.
double face_pressure_jump(double phi_lo, double phi_hi, double sigma, double kappa);

}  // namespace meniscus::fluid
