#pragma once
/// \file The matrix-free operator of the implicit viscosity step (viscosity.h): A = ρ_f + K on
/// every face velocity, its diagonal, and the 7-point blocks of each velocity component that
/// the multigrid and hypre preconditioners of the viscous CG are built on.

#include <array>
#include <cstddef>
#include <vector>

#include "fluid/array3.h"
#include "fluid/boundary.h"
#include "fluid/mac_grid.h"
#include "fluid/phases.h"
#include "fluid/poisson_matrix.h"
#include "fluid/viscosity.h"

namespace meniscus::fluid {

struct SurfaceViscosity;

/// Matrix-free operator of the backward-Euler viscous step on all face velocities, stored as one
/// flat vector [u | v | w] (each block in its Array3 layout). With the energy of viscosity.h,
///   A x = ρ_f x + K x,  K x = Dᵀ (2Δt W) D x,
/// where D maps face velocities to strain rates (cell centres and edges) and W holds μ_c or
/// ½ μ_e (× the dual-cell fraction inside the box). K x is evaluated in three TBB-parallel
/// passes: diagonal stresses at cells, shear stresses on edges, their divergence on faces.
class ViscousOperator {
public:
    using Index3 = std::array<int, 3>;

    /// (Re)builds the operator for a grid, interface and time step, reusing the arrays' memory.
    void build(const MacGrid& grid, const Array3<double>& phi, const PhaseOptions& phases,
               FluidMode mode, const BoundaryOptions& walls, double dt, double min_liquid_fraction,
               ViscosityWeights weights, const SurfaceViscosity* surface);

    std::size_t size() const { return m_size; }
    const std::vector<char>& unknown() const { return m_unknown; }
    const std::vector<double>& density() const { return m_density; }

    /// Flat vector [u | v | w] of the grid's face velocities.
    void gather(const MacGrid& grid, std::vector<double>& x) const;

    void scatter(const std::vector<double>& x, MacGrid& grid) const;

    /// y = K x on every interior face (entries on wall-normal faces are left unspecified). With
    /// `moving` walls the shear strain next to a no-slip wall is taken relative to the wall's
    /// velocity, which makes the map affine: use it only for the right-hand side.
    void stiffness(const std::vector<double>& x, std::vector<double>& y,
                   const BoundaryOptions* moving = nullptr) const;

    /// y = (ρ + K) x restricted to the unknowns (x must vanish on fixed faces; y does too).
    void apply(const std::vector<double>& x, std::vector<double>& y) const;
    /// apply(), returning x·y from its last pass: summed per face layer (each layer along its
    /// rows, then the layers in order; without a surface term), so the same for any number of
    /// threads, equal to dot() to round-off.
    double apply_dot(const std::vector<double>& x, std::vector<double>& y) const;

    /// Diagonal of ρ + K on the unknowns (1 on fixed faces), for Jacobi preconditioning; with
    /// `with_surface` false, that of the grid part alone (the surface term's left out, for
    /// SurfacePreconditioner, which takes that term whole).
    void diagonal(std::vector<double>& d, bool with_surface = true) const;

    /// The scale Δt μ_s / Δx³ of the implicit tension's term in K (0 when there is none).
    double surface_scale() const { return m_surface_scale; }

    /// The diagonal blocks of ρ + K, each velocity component coupled with itself alone (the
    /// normal-stress couplings through cells, the shear couplings through edges), as 7-point
    /// matrices on that component's face lattice: same diagonal `d` (diagonal()) as the whole
    /// operator, fixed faces inactive (zero rows and columns).
    void component_blocks(const std::vector<double>& d, std::array<PoissonMatrix, 3>& blocks) const;

private:
    /// Calls visit(face index, flat index in [u|v|w]) for every face of component a that can be
    /// an unknown: the interior ones and those on an outflow face of the box.
    template <class Visit>
    void for_each_face(int a, Visit&& visit) const;

    /// Is face f of component a inside the box or on one of its outflow faces?
    bool solvable(int a, const Index3& f) const {
        if (f[a] == 0)  // across a periodic axis the face at 0 is the seam; the one at n its copy
            return m_open[a][0] || periodic(a);
        return f[a] != m_n[a] || m_open[a][1];
    }

    /// Index of face f of component a in the stacked [u|v|w] vector.
    std::size_t face_flat(int a, const Index3& f) const {
        const Index3& d = m_face_dims[a];
        return m_offset[a] + static_cast<std::size_t>(f[0]) +
               static_cast<std::size_t>(d[0]) *
                   (static_cast<std::size_t>(f[1]) + static_cast<std::size_t>(d[1]) * f[2]);
    }

    /// What a face of component a reaches: the flat step to the cell below it (along a) and,
    /// for its two edge arrays (3 − a − b, the other axes b in increasing order), b and the flat
    /// step along b.
    struct FaceReach {
        std::size_t cell_step = 0;
        std::array<int, 2> other{};
        std::array<std::size_t, 2> edge_step{};
    };
    FaceReach face_reach(int a) const;
    /// Do the faces of component a in row (·, j, k) have their cells and edges inside the box
    /// along axes 1 and 2 (no wall, seam or outflow to treat there)?
    bool row_inside(int a, int j, int k) const;
    /// Liquid fraction of a cube of edge dx centred where the level set is `phi`: exact for a
    /// plane parallel to a face, 1 and 0 a half cell inside and outside (free_surface weights).
    double control_volume_fraction(double phi) const;

    /// μ of a control volume whose liquid fraction is `fraction`.
    double blended_mu(double mu_liquid, double fraction) const;

    /// Calls visit(cell) for each of the (up to 4) grid cells around edge e of axis c, whose
    /// other two axes are a and b.
    template <typename Visit>
    void for_each_edge_cell(const Index3& e, int a, int b, Visit&& visit) const;

    void set_edge_weights(const BoundaryOptions& walls, const Array3<double>& phi,
                          const PhaseOptions& phases);

    void set_faces(const Array3<double>& phi, const PhaseOptions& phases, FluidMode mode,
                   double min_liquid_fraction);

    /// σ_a(cell) = 2Δt μ_c ∂_a x_a.
    void normal_stresses(const std::vector<double>& x) const;

    /// Flat-index step of axis `axis` in the face array of component a.
    std::size_t face_stride(int a, int axis) const;

    /// τ(edge) = 2Δt W_e (∂_b x_a + ∂_a x_b) on edges parallel to c, (a, b) the other axes; ∂
    /// one-sided at walls, where a no-slip wall mirrors the tangential velocity relative to the
    /// wall's own (`moving`, else at rest), with the face indices stepped along each row instead
    /// of recomputed.
    void shear_stresses(const std::vector<double>& x, const BoundaryOptions* moving) const;

    /// y_f = Σ over the strain terms containing face f of stress × coefficient. With `x`, the
    /// whole operator instead: y_f = ρ_f x_f + that sum on the unknowns and 0 on every other face
    /// (apply()), returning x·y summed per face layer; without, 0.
    double stress_divergence(std::vector<double>& y, const std::vector<double>* x = nullptr) const;

    Index3 m_n{};
    bool m_open[3][2] = {};  ///< outflow faces of the box: their normal velocity is solved for
    /// periodic axes: the face at 0 is the seam (cells n−1 and 0), the one at n its copy, and
    /// the edges at 0 are the seam's (those at n copies, weight 0)
    Periodicity m_periodic = {false, false, false};
    bool periodic(int axis) const { return m_periodic[static_cast<std::size_t>(axis)]; }
    double m_dx = 0.0;
    double m_dt = 0.0;
    std::array<Index3, 3> m_face_dims{};
    std::array<std::size_t, 3> m_offset{};
    std::size_t m_size = 0;
    Array3<double> m_mu;                          ///< μ per cell
    bool m_fraction_weights = false;              ///< μ blended by control-volume fractions
    bool m_pointwise_edges = false;               ///< μ_e of the phase at the edge's midpoint
    const SurfaceViscosity* m_surface = nullptr;  ///< the implicit tension term, if any
    double m_surface_scale = 0.0;                 ///< Δt μ_s / Δx³
    double m_mu_gas = 0.0;                        ///< 0 in free_surface mode
    std::array<Array3<double>, 3> m_edge_weight;  ///< W_e per edge, by the axis it is parallel to
    std::vector<char> m_unknown;                  ///< 1 on faces that are solved for
    std::vector<double> m_density;                ///< ρ_f on unknown faces
    mutable std::array<Array3<double>, 3> m_normal_stress;  ///< scratch: σ_aa at cells
    mutable std::array<Array3<double>, 3> m_shear_stress;   ///< scratch: τ on edges
    mutable std::vector<double> m_layer_dots;  ///< scratch: apply_dot()'s sum per face layer
};

}  // namespace meniscus::fluid
