#pragma once
/// \file A level-set solution of motion by mean curvature for surfaces of revolution, solved on
/// a 2-D meridian grid: an accurate, independent reference for docs/validation.md A2 (the dumbbell
/// of the paper's Table 4.3), much finer than a 3-D level set can afford.
///
/// The surface moves with normal velocity V = −(κ₁ + κ₂) (sum of the principal curvatures,
/// positive on a sphere, so a sphere follows R(t) = sqrt(R₀² − 4t) and a cylinder
/// R(t) = sqrt(R₀² − 2t)). With φ negative inside, φ_t = |∇φ| ∇·(∇φ/|∇φ|). For a surface of
/// revolution about an axis, φ depends on the axial coordinate a and the distance r ≥ 0 from the
/// axis only, and
///
///     |∇φ|(κ₁ + κ₂) = [φ_aa φ_r² − 2 φ_a φ_r φ_ar + φ_rr φ_a²] / (φ_a² + φ_r²) + φ_r / r.
///
/// Grid: cell centres a_i = a₀ + (i + ½)Δx, r_j = (j + ½)Δx, so no unknown sits on the axis;
/// φ is even in r (ghost row j = −1 mirrors j = 0, j = −2 mirrors j = 1), so φ_r/r at
/// r₀ = Δx/2 is the second-order estimate of φ_rr there. The outer edges mirror too (Neumann),
/// far from the surface.
///
/// Step: forward Euler with second-order central differences (the mixed derivative from the
/// four diagonal neighbours) on the cells of a narrow band around the surface, Δt = cfl·Δx²/4
/// shortened so a whole number of steps ends exactly at end_time. Stability: the meridian term
/// is tᵀ(D²φ)t with t the unit tangent, whose central-difference symbol is at most
/// (4t_a² + 4t_r² + 2|t_a t_r|)/Δx² ≤ 5/Δx²; the azimuthal term φ_r/r adds at most 2/Δx² (at the
/// axis row, where it is (φ₁ − φ₀)/Δx²) and is a small skew part elsewhere. Forward Euler needs
/// Δt·7/Δx² ≤ 2, i.e. Δt ≤ 0.286 Δx²; cfl = 1 (Δt = 0.25 Δx²) keeps a 12 % margin
/// (tests/tracker/test_axisymmetric_mcf_reference.cpp runs cfl = 1 and 0.5 and compares).
/// Where the central gradient vanishes (a blob about to vanish, the pinch point) the meridian
/// term is 0/0; there it is the average ½(φ_aa + φ_rr) over tangent directions, which keeps a
/// vanishing component moving instead of freezing it (the form above, with |∇φ| cancelled, is
/// bounded by |D²φ| for any non-zero gradient, so nothing else blows up).
///
/// Reinitialization (every `reinit_interval` steps) must renormalize φ without moving the zero
/// set AND leave the values that the curvature stencils read smooth: the stencils divide by
/// Δx², so grid-scale noise ε in the values becomes ε/Δx² in κ. Russo–Smereka (interface cells
/// set to φ/|∇φ|, the others by ENO2 Godunov Eikonal iterations, every step) leaves O(Δx³)
/// noise per reinitialization, and O(1/Δx²) of them gave errors that did not converge: on a
/// sphere R₀ = 0.3 at half its extinction time, max radius error 5.0e-4, 4.0e-4, 3.7e-4 at
/// Δx = 0.01, 0.005, 0.0025. So: Chopp's closest-point reinitialization (J. Comput. Phys. 2001). φ is
/// interpolated by the C¹ bicubic Hermite interpolant whose corner derivatives φ_a, φ_r, φ_ar
/// are fourth-order central differences (so its zero set is within O(Δx⁴) of the discrete
/// surface), and every cell within `projection_width_voxels` of the surface gets its distance to
/// that zero set, found by Newton iteration (each step moves onto the zero set along ∇φ and
/// removes the tangential part of x − p) warm-started from the cell's previous closest point,
/// else from its own gradient, else from a neighbour's closest point. The zero set moves by
/// O(Δx⁴) per reinitialization and the values are samples of a distance to a smooth curve. Cells
/// farther out take `reinit_iterations` Eikonal iterations (Godunov, second-order ENO, Δτ = Δx/2)
/// with the projected cells fixed; they only serve as stencil support far from the surface. A
/// cell's update after k steps depends on values up to k + 1 cells away, so the projected
/// width must exceed the stencil reach over `reinit_interval` steps plus the Hermite
/// derivatives' reach: with the defaults (every 4 steps, 6 voxels) the sphere error converges at
/// second order; every 8 steps it degrades. The band (|φ| < band half width, values beyond it
/// saturate) is rebuilt from the cells within one ring of the old one, so it follows the surface
/// through a pinch-off.
///
/// Initial φ: the exact signed distance to the shape's zero set, by projecting each band cell's
/// 3-D point onto the surface (Newton steps along ∇φ alternated with tangential moves until x − p
/// is normal to the surface at p), not the shape's value (only a bound for blends and CSG).
///
/// Output: distance(x) interpolates the final field bicubically (Catmull–Rom, C¹, exact for
/// quadratics: O(Δx³) interpolation error; at t = 0 on a sphere of radius 0.3 the interpolated
/// distance is within 6e-9 of the exact one at Δx = 0.0025) after a final reinitialization with
/// `final_reinit_iterations` Eikonal iterations, which makes the whole band a signed distance.

#include "tracker/implicit_shape.h"
#include "tracker/mesh.h"

#include <vector>

namespace meniscus::tracker {

/// Options of AxisymmetricMcfReference.
struct AxisymmetricMcfOptions {
    double voxel_size = 0.0025;  ///< Δx (m, > 0), in a and r
    double end_time = 0.0;       ///< s (≥ 0), time of the returned surface
    /// Δt ≤ cfl · Δx²/4, in (0, 1] (1 is 88 % of the forward-Euler limit; see the file comment).
    double cfl = 1.0;
    int reinit_interval = 4;    ///< curvature steps between reinitializations (≥ 1)
    int reinit_iterations = 2;  ///< Eikonal iterations per reinitialization (≥ 1)
    /// Cells nearer the surface than this (voxels, in [2, band_half_width_voxels]) get their
    /// distance by closest-point projection at each reinitialization, the others by Eikonal
    /// iterations.
    double projection_width_voxels = 6.0;
    int band_half_width_voxels = 10;  ///< narrow band |φ| < this · Δx (≥ 4: ENO and curvature stencils)
    int padding_voxels = 4;  ///< grid cells beyond the band around the shape's bounds (≥ 2)
    /// Eikonal iterations of the final reinitialization (≥ 0; enough to cross the band).
    int final_reinit_iterations = 30;
    void validate() const;  ///< throws std::invalid_argument naming the field
};

/// What an AxisymmetricMcfReference run did.
struct AxisymmetricMcfStats {
    double time_step = 0.0;          ///< Δt (s)
    long steps = 0;                  ///< curvature steps
    long reinitializations = 0;      ///< reinitializations, the final one included
    int axial_cells = 0;             ///< grid cells along the axis
    int radial_cells = 0;            ///< grid cells from the axis outwards
    long long initial_band_cells = 0;
    long long final_band_cells = 0;
    double seconds = 0.0;  ///< wall time of initialization, flow and final reinitialization
};

/// Mean-curvature flow of an axisymmetric implicit shape to a given time on a meridian grid;
/// afterwards a read-only signed-distance field (see the file comment). Copyable.
class AxisymmetricMcfReference {
public:
    /// Runs the flow. `axis_point` and `axis_direction` (normalized inside) give the axis of
    /// symmetry; the shape is assumed symmetric about it (only the half-plane through the
    /// axis and axis_point + any perpendicular is sampled). Throws std::invalid_argument on
    /// invalid options, a zero or non-finite axis direction, or a shape with unbounded bounds.
    AxisymmetricMcfReference(const ImplicitShape& shape, const Vec3& axis_point,
                             const Vec3& axis_direction, const AxisymmetricMcfOptions& options);

    /// Signed distance (m, negative inside) from x (m) to the surface at end_time; bicubic
    /// interpolation in (a, r). Saturates at ±band_half_width() away from the surface (the sign
    /// stays right); a distance within about band_half_width() − 2Δx. Thread-safe.
    double distance(const Vec3& x) const;
    /// The same in meridian coordinates: axial a (m, from axis_point along the axis) and r ≥ 0.
    double meridian_distance(double a, double r) const;
    /// Half width of the band (m).
    double band_half_width() const { return m_band_half_width; }
    const AxisymmetricMcfStats& stats() const { return m_stats; }

private:
    double value(int i, int j) const;  ///< φ at a cell, mirrored indices allowed

    Vec3 m_axis_point;
    Vec3 m_axis;
    double m_dx = 0.0;
    double m_a0 = 0.0;  ///< axial coordinate of the grid's lower face
    int m_na = 0, m_nr = 0;
    double m_band_half_width = 0.0;
    std::vector<double> m_phi;  ///< m_na × m_nr, index i·m_nr + j
    AxisymmetricMcfStats m_stats;
};

}  // namespace meniscus::tracker
