#pragma once
/// \file An independent level-set solution of motion by mean curvature, the reference of
/// docs/validation.md A2 (the paper's Table 4.3 compares the mesh against a high-resolution
/// level-set run).
///
/// The surface moves with normal velocity V = −(κ₁ + κ₂) (the sum of the principal curvatures,
/// positive on a sphere, so a sphere follows R(t) = sqrt(R₀² − 4t)). In level-set form, with φ
/// negative inside,
///
///     φ_t = (κ₁ + κ₂) |∇φ|,   κ₁ + κ₂ = ∇·(∇φ / |∇φ|).
///
/// Discretization: OpenVDB's narrow-band level set (FloatGrid, half width `half_width_voxels`).
/// Each step is forward Euler, φ += Δt (κ₁ + κ₂)|∇φ|, with κ₁ + κ₂ = 2 × OpenVDB's
/// CurvatureStencil::meanCurvatureNormGrad() (which returns the MEAN curvature (κ₁ + κ₂)/2 times
/// the central-difference |∇φ|; second-order central differences, 19-point stencil), on every
/// band voxel, with Δt = cfl · Δx²/6 shortened so that a whole number of steps ends at end_time.
/// Where the central-difference |∇φ| is below 0.5 (a voxel-sized blob left by a pinch-off, whose
/// gradient vanishes, would otherwise never move) the step uses Δφ, which equals κ₁ + κ₂ for a
/// signed distance. A step moves no value by more than Δx/2 (the band follows the surface by
/// one voxel per step; only curvatures beyond 3/Δx, at under-resolved pinch-offs, reach the cap).
/// After every step the band is rebuilt around the moved surface WITHOUT moving it: dilate by
/// one voxel, `renormalization_iterations` Euler steps of the Eikonal equation (OpenVDB's
/// LevelSetTracker::normalize, HJWENO5 gradients) on every band voxel except the interface
/// voxels (a face neighbour of the other sign), which keep their values, then trim. An interface
/// voxel whose |φ| exceeds Δx is stale (the surface swept past it, as a tip does right after a
/// pinch-off) and first gets the crossing-distance estimate of OpenVDB's fast sweeping.
///
/// Why not `openvdb::tools::LevelSetFilter::meanCurvature()`: it takes the same Euler step with
/// the mean curvature and a fixed Δt = Δx²/3 (OpenVDB 10 LevelSetFilter.h), i.e. Δx²/6 of the
/// flow above, and then LevelSetTracker::track(), whose smoothed-sign Eikonal iterations also
/// renormalize the interface voxels and so shift the zero set a little on every step. On a
/// sphere R₀ = 0.3 run to half its extinction time the filter's error (max |φ| on the exact
/// sphere) was 3.4e-4 at Δx = 0.02 and still 2.7e-4 at Δx = 0.01 (one Eikonal iteration per
/// step; 8.7e-4 at Δx = 0.02 with its default three): it does not converge. Rebuilding the band
/// less often instead lets the stale band edge (inactive neighbours at ±half width) pollute the
/// curvature stencils near the surface (errors grew under refinement too). Freezing the
/// interface voxels during renormalization converges: max error 1.6e-3, 5.7e-4, 8.9e-5 at
/// Δx = 0.04, 0.02, 0.01 on that sphere (tests/coupling/test_levelset_reference.cpp).
///
/// Initial condition: every voxel centre within the band gets the exact signed distance to the
/// zero set of the implicit shape, found by projecting the centre onto the surface (Newton steps
/// along ∇φ alternated with tangential moves until x − p is normal to the surface at p) — not the
/// shape's value, which for blends and CSG is only a bound on the distance.
///
/// OpenVDB stays in levelset_reference.cpp: this header exposes none of its types.

#include "tracker/implicit_shape.h"

#include <Eigen/Core>

#include <memory>

namespace meniscus::coupling {

/// Options of LevelSetReference.
struct LevelSetReferenceOptions {
    double voxel_size = 0.01;  ///< Δx (m, > 0)
    double end_time = 0.0;     ///< s (≥ 0), time of the returned surface
    /// Δt ≤ cfl · Δx²/6 (in (0, 1]: 1 is the explicit stability limit of the 3-D Laplacian and
    /// OpenVDB's own choice in LevelSetFilter::meanCurvature).
    double cfl = 1.0;
    int half_width_voxels = 3;  ///< narrow-band half width in voxels (≥ 3: HJWENO5 stencils)
    /// Eikonal iterations per band rebuild, i.e. per step (≥ 1; OpenVDB's LevelSetTracker
    /// default). On the sphere test one iteration costs 40 % less but converges only at first
    /// order (max error 3.3e-4 at Δx = 0.02, 1.8e-4 at 0.01; three: 5.7e-4, 8.9e-5).
    int renormalization_iterations = 3;
    void validate() const;  ///< throws std::invalid_argument naming the field
};

/// What a LevelSetReference run did.
struct LevelSetReferenceStats {
    double time_step = 0.0;        ///< Δt (s)
    long steps = 0;                ///< curvature steps taken
    long long initial_voxels = 0;  ///< active (band) voxels at t = 0
    long long final_voxels = 0;    ///< active voxels at end_time
    double seconds = 0.0;          ///< wall time of initialization and flow
};

/// Level-set mean-curvature flow of an implicit shape to a given time; afterwards a read-only
/// signed-distance field (see the file comment). Not copyable; movable.
class LevelSetReference {
public:
    /// Runs the flow. Throws std::invalid_argument on invalid options or a shape with unbounded
    /// bounds, std::runtime_error if the shape spans more than 2³¹ voxels on an axis.
    LevelSetReference(const tracker::ImplicitShape& shape, const LevelSetReferenceOptions& options);
    ~LevelSetReference();
    LevelSetReference(LevelSetReference&&) noexcept;
    LevelSetReference& operator=(LevelSetReference&&) noexcept;
    LevelSetReference(const LevelSetReference&) = delete;
    LevelSetReference& operator=(const LevelSetReference&) = delete;

    /// Signed distance (m, negative inside) of x (m) to the surface at end_time: tri-quadratic
    /// interpolation of the band values. Outside the band the magnitude saturates at
    /// band_half_width() (the sign stays right); values are distances within about
    /// band_half_width() − 1.5 Δx of the surface. Thread-safe.
    double distance(const Eigen::Vector3d& x) const;
    /// Half width of the band (m): |distance()| values this large are not distances.
    double band_half_width() const;
    const LevelSetReferenceStats& stats() const;

private:
    struct Impl;
    std::unique_ptr<Impl> m_impl;
};

}  // namespace meniscus::coupling
