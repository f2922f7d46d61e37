#pragma once
/// \file SurfaceTracker: the thin orchestrator of the paper's algorithm (§3.3) over the free
/// functions of the tracker — mesh improvement, topology changes, and collision-safe
/// integration. It knows nothing about grids or fluids: callers give per-vertex velocities.

#include "tracker/collision_resolution.h"
#include "tracker/mesh.h"
#include "tracker/remesh/improve.h"
#include "tracker/remesh_options.h"
#include "tracker/topology/change_topology.h"

#include <cstdint>
#include <vector>

namespace meniscus::tracker {

/// Options of the tracker. Lengths are fractions of ξ, the mean edge length of the mesh the
/// tracker was created with, so a scene scales without retuning.
struct TrackerOptions {
    bool improve_mesh = true;            ///< §3.3 switch: split, flip, collapse, smooth
    bool allow_topology_changes = true;  ///< §3.3 switch: merging and separation
    bool collision_safety = true;        ///< §3.3 switch: enforce intersection-free motion
    /// ε_p as a fraction of ξ (repulsion distance of collision resolution).
    double proximity_fraction = 1e-3;
    /// Run the exact static self-intersection test after every integrate() and report it.
    bool verify_intersection_free = false;
    /// ξ (metres), the length α, β, γ and ε_p scale with. 0: the initial mesh's mean edge
    /// length (the paper's ξ). Set it to the nominal edge length when the initial mesh is
    /// refined locally (ImplicitMeshOptions::crease), which would otherwise shrink every size.
    double characteristic_length = 0.0;
    /// Collision resolution tuning; its proximity_epsilon is overwritten from
    /// proximity_fraction · ξ.
    CollisionOptions collision;
    RemeshOptions remesh;      ///< α, β, γ as fractions of ξ and the operations' switches
    TopologyOptions topology;  ///< merge distance and separation
    /// Checked inside improve(), change_topology() and integrate(): they throw
    /// meniscus::Cancelled once it is requested, leaving a valid mesh mid-operation (discard it
    /// or keep stepping). Never requested by default.
    CancellationToken cancel;
    void validate() const;     ///< throws std::invalid_argument naming the field
};

/// What one integrate() call did.
struct IntegrateResult {
    CollisionReport collisions;
    double time_advanced = 0.0;   ///< seconds of motion applied (dt × collisions.motion_fraction)
    int intersecting_pairs = -1;  ///< exact check result when verification is on, else −1
    double seconds = 0.0;         ///< wall time spent
};

/// Owns the surface mesh and moves it safely.
class SurfaceTracker {
public:
    /// Takes the initial mesh (must be non-empty; intersection-free for the guarantee) and
    /// options (validated; throws std::invalid_argument naming the field). A periodic mesh
    /// (issue 39) must have every wrapping period at least MeshPeriods::PERIOD_TO_EDGE_RATIO
    /// times its longest edge (else std::invalid_argument naming the axis); integrate() wraps
    /// its positions back into the fundamental box after each motion.
    SurfaceTracker(SurfaceMesh mesh, const TrackerOptions& options);

    SurfaceMesh& mesh() { return m_mesh; }
    const SurfaceMesh& mesh() const { return m_mesh; }
    const TrackerOptions& options() const { return m_options; }
    /// ξ: mean edge length of the initial mesh (metres).
    double characteristic_length() const { return m_xi; }

    /// Mesh improvement of one step (paper §3.5, §3.6.1): an empty report when improve_mesh is
    /// off. Leaves dead slots; call compact() (or change_topology(), which compacts) after.
    /// `pinned` (optional, indexed by vertex; vertices past its end are free): vertices that
    /// smoothing and collapses leave where they are (ImproveContext::pinned).
    ImproveReport improve(const std::vector<std::uint8_t>* pinned = nullptr);
    /// Topology changes of one step (§3.6, §3.7) when allowed, then compact(), and a spatial
    /// renumbering (SurfaceMesh::sort_spatially) when neighbours have drifted apart in memory:
    /// vertex indices may change (observers registered on mesh() are told).
    TopologyReport change_topology();
    /// Removes dead slots (see SurfaceMesh::compact).
    void compact() { m_mesh.compact(); }

    /// Moves every live vertex by velocities[vi] · dt (velocities sized mesh().num_vertices()),
    /// changed as little as needed to keep the mesh intersection-free when collision safety is
    /// on. `pinned` (optional, sized num_vertices()): vertices that do not move at all, whatever
    /// their velocity (collision responses leave them where they are). Throws
    /// std::invalid_argument on size mismatch or dt ≤ 0.
    IntegrateResult integrate(const std::vector<Vec3>& velocities, double dt,
                              const std::vector<std::uint8_t>* pinned = nullptr);

    /// Exact state for checkpoints: ξ and the mesh (SurfaceMesh::save_state). The options are
    /// the caller's (a resumed run builds the tracker from the same scene). load_state() throws
    /// FormatError on truncated or inconsistent data.
    void save_state(BinaryWriter& out) const;
    void load_state(BinaryReader& in);

private:
    SurfaceMesh m_mesh;
    TrackerOptions m_options;
    double m_xi = 0.0;
};

}  // namespace meniscus::tracker
