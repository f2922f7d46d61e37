#pragma once
/// \file Volume-aware collision response (not in the paper; issue 34): collision impulses and
/// impact zones move vertices along contact normals and so change the volume each closed
/// component encloses — on the A4 curl-noise flow, where a sheet gets thinner than the chord
/// sag of its sides, by more than the flow's own motion. This file gives that volume back by
/// the smallest mass-weighted displacement of the vertices collision handling left alone:
/// for a closed component c with volume error e_c (the volume the requested motion gives minus
/// the volume after collision handling) and free vertices F_c,
///
///     δ_v = e_c m_v⁻¹ g_v / Σ_{w ∈ F_c} m_w⁻¹ ‖g_w‖²,    g_v = ∂V_c/∂x_v = ⅓ Σ_{t ∋ v} A_t,
///
/// A_t the area vector ½ (x_b − x_a) × (x_c − x_a) of triangle t (the linearised volume
/// constraint gᵀδ = e_c, solved exactly). The displacements are only proposed here: the caller
/// (resolve_collisions) keeps them only when CCD verifies the corrected motion.

#include "tracker/mesh.h"

#include <cstdint>
#include <vector>

namespace meniscus::tracker {

/// The closed components of a mesh, per vertex: those whose every live edge has at least two
/// live triangles (an open surface encloses no volume and is never corrected).
struct VolumeComponents {
    int count = 0;  ///< components (closed or not)
    /// Component of each vertex slot; INVALID_INDEX for dead vertices, vertices without live
    /// triangles, vertices of open components and vertices shared by two components (whose
    /// gradient would mix two volumes).
    std::vector<int> vertex_component;
    /// Component of each triangle slot (INVALID_INDEX for dead triangles).
    std::vector<int> triangle_component;
    std::vector<std::uint8_t> closed;  ///< per component: 1 when it has no boundary edge
};

/// Components of the live triangles of `mesh` (edge-connected, as triangle_components()).
VolumeComponents volume_components(const SurfaceMesh& mesh);

/// Signed enclosed volume of each component (m³, indexed by component id) with the vertices at
/// `positions` (sized mesh.num_vertices()). A periodic mesh (issue 39) is read by the minimum
/// image and its volumes come from the divergence theorem along its first axis that does not
/// wrap, V = ∮ (x_a − origin_a) n_a dA: exact for a column closed through the box's faces; a
/// layer periodic along the other two axes gets its volume above origin_a. When all three axes
/// wrap, along z: defined up to a constant per component (volume changes are exact).
std::vector<double> component_volumes_at(const SurfaceMesh& mesh,
                                         const VolumeComponents& components,
                                         const std::vector<Vec3>& positions);

/// The displacements δ (one per vertex slot, metres; zero outside `movable`) that change each
/// closed component's volume at `positions` by `volume_errors[c]` (m³) to first order, with
/// the smallest Σ m_v ‖δ_v‖² over the vertices with movable[v] ≠ 0 and inv_mass[v] > 0
/// (inverse masses, 1/kg; 0: pinned). A component with no such vertex, or a zero error, gets
/// no displacement. Throws std::invalid_argument on size mismatches.
std::vector<Vec3> volume_restoring_displacements(const SurfaceMesh& mesh,
                                                 const VolumeComponents& components,
                                                 const std::vector<Vec3>& positions,
                                                 const std::vector<double>& volume_errors,
                                                 const std::vector<std::uint8_t>& movable,
                                                 const std::vector<double>& inv_mass);

}  // namespace meniscus::tracker
