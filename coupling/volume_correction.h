#pragma once
/// \file Volume per connected component of the interface, followed through merges and
/// pinch-offs, and the correction that restores each component's target volume.
///
/// Targets follow topology changes: before a step every vertex remembers its component; after
/// the step each new component collects the old components of its surviving vertices (vertex
/// indices are followed through compaction by a MeshObserver). A new component fed by several
/// old ones (a merge) gets the sum of their targets; old components feeding several new ones
/// (a pinch-off) share their target in proportion to the new components' current volumes. A
/// component with no surviving vertex of any old one keeps its current volume as target.
///
/// Correction: component c with volume V and target V* gets a uniform normal speed w_c added to
/// the velocities u of its vertices, chosen so that the volume at the end of the step is V* to
/// first order: dt·(Σ_v u_v·∇V_v + w_c Σ_v |∇V_v|) = V* − V, with ∇V_v the volume gradient
/// of vertex v (a third of its triangles' area vectors). So the correction both restores the
/// target and removes the volume rate of the motion itself (the interpolation error of the
/// grid velocity; parts of a surface outside the domain, which move with the clamped wall
/// velocity and would otherwise add the rate of a whole step every step). It goes through the
/// tracker's collision-safe integration like any motion.

#include "tracker/mesh.h"

#include <cstdint>
#include <vector>

namespace meniscus::coupling {

/// Volume bookkeeping of one step (volumes in m³).
struct VolumeReport {
    std::vector<double> volumes;      ///< per current component, after the step
    std::vector<double> targets;      ///< per current component
    int merges = 0;                   ///< components formed from several old ones this step
    int splits = 0;                   ///< old components that became several this step
    double max_relative_error = 0.0;  ///< max |V − V*| / V* over components
};

/// Follows component volumes across steps. Registers itself as an observer of the mesh it is
/// given (which must outlive it).
class VolumeTracker final : public tracker::MeshObserver {
public:
    /// Starts with the mesh's current component volumes as targets.
    explicit VolumeTracker(tracker::SurfaceMesh& mesh);
    ~VolumeTracker() override;
    VolumeTracker(const VolumeTracker&) = delete;
    VolumeTracker& operator=(const VolumeTracker&) = delete;

    /// Call at the start of a step (before remeshing and topology changes).
    void begin_step();
    /// Call after the mesh changes of the step (topology, compaction) and before computing the
    /// correction: matches components and updates targets.
    VolumeReport match_components();
    /// Between begin_step() and match_components(): the target of the component vertex `vi`
    /// belonged to at begin_step() changes by `delta` (m³, with the sign of its enclosed volume):
    /// volume that entered through an inflow face or was clipped off at an outflow face. A vertex
    /// created since begin_step() stands for the first vertex it is connected to that existed
    /// then. Returns false (and changes nothing) when no such vertex is found.
    bool add_to_target(int vi, double delta);
    /// Adds the correction velocity (see file comment) to `velocities` (sized num_vertices()),
    /// which must already hold the step's motion. `dt` > 0 (s). `held` (optional, sized
    /// num_vertices()): vertices that do not move (integrate()'s pinned ones) take no
    /// correction, the others of their component make up for them. Returns the largest
    /// correction displacement applied (m).
    double add_correction(std::vector<tracker::Vec3>& velocities, double dt,
                          const std::vector<std::uint8_t>* held = nullptr) const;

    /// Targets of the current components (after match_components()).
    const std::vector<double>& targets() const { return m_targets; }

    void on_compact(const std::vector<int>& old_to_new_vertex) override;

    /// Exact state for checkpoints (targets and component maps); load_state() throws
    /// FormatError on truncated data.
    void save_state(BinaryWriter& out) const;
    void load_state(BinaryReader& in);

private:
    tracker::SurfaceMesh& m_mesh;
    std::vector<int> m_vertex_component;  ///< old component per vertex (−1 unknown)
    std::vector<double> m_old_targets;
    std::vector<double> m_targets;          ///< per current component
    std::vector<int> m_triangle_component;  ///< current components of triangles
};

}  // namespace meniscus::coupling
