#include "tracker/surface_tracker.h"

#include "tracker/mesh_intersections.h"
#include "tracker/mesh_measures.h"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <sstream>
#include <stdexcept>
#include <string>

namespace meniscus::tracker {

namespace {

/// change_topology() renumbers the mesh spatially (SurfaceMesh::sort_spatially) when more than
/// this fraction of its edges join far-apart indices (SurfaceMesh::far_edge_fraction): about
/// 0.07–0.14 right after a renumbering, 0.6–0.8 for a mesher's order or a long run's.
constexpr double REORDER_FAR_EDGE_FRACTION = 0.2;

/// Throws std::invalid_argument when a wrapping period of `mesh` is shorter than
/// MeshPeriods::PERIOD_TO_EDGE_RATIO times its longest live edge (read by the minimum image):
/// the minimum image of an element, and of the pairs collision handling reads, would be
/// ambiguous.
void check_periods(const SurfaceMesh& mesh) {
    double longest = 0.0;
    for (int ei = 0; ei < mesh.num_edges(); ++ei)
        if (mesh.edge_alive(ei)) {
            const std::array<Vec3, 2> ends = mesh.edge_positions(ei);
            longest = std::max(longest, (ends[1] - ends[0]).norm());
        }
    static const char* names[3] = {"x", "y", "z"};
    const MeshPeriods& periods = mesh.periods();
    for (int a = 0; a < 3; ++a)
        if (periods.wraps(a) && periods.length[a] < MeshPeriods::PERIOD_TO_EDGE_RATIO * longest) {
            std::ostringstream message;
            message << "SurfaceTracker: the period along " << names[a] << " (" << periods.length[a]
                    << " m) is shorter than " << MeshPeriods::PERIOD_TO_EDGE_RATIO
                    << " times the longest edge (" << longest
                    << " m): refine the mesh or lengthen the period";
            throw std::invalid_argument(message.str());
        }
}

}  // namespace

void TrackerOptions::validate() const {
    if (!(proximity_fraction > 0.0) || !std::isfinite(proximity_fraction))
        throw std::invalid_argument("proximity_fraction: expected a number > 0");
    if (!(characteristic_length >= 0.0) || !std::isfinite(characteristic_length))
        throw std::invalid_argument("characteristic_length: expected a number >= 0");
    try {
        remesh.validate();
    } catch (const std::invalid_argument& e) {
        throw std::invalid_argument(std::string("remesh/") + e.what());
    }
    try {
        topology.validate();
    } catch (const std::invalid_argument& e) {
        throw std::invalid_argument(std::string("topology/") + e.what());
    }
    if (allow_topology_changes && topology.allow_merging &&
        !(topology.merge_distance_fraction > proximity_fraction))
        throw std::invalid_argument(
            "topology/merge_distance_fraction: must exceed proximity_fraction, or approaching "
            "surfaces are held apart by repulsion before they come close enough to merge");
    CollisionOptions c = collision;
    c.proximity_epsilon = 1.0;  // overwritten from proximity_fraction; validate the rest
    try {
        c.validate();
    } catch (const std::invalid_argument& e) {
        throw std::invalid_argument(std::string("collision/") + e.what());
    }
}

SurfaceTracker::SurfaceTracker(SurfaceMesh mesh, const TrackerOptions& options)
    : m_mesh(std::move(mesh)), m_options(options) {
    m_options.validate();
    m_xi = m_options.characteristic_length > 0.0 ? m_options.characteristic_length
                                                 : edge_length_stats(m_mesh).mean;
    if (!(m_xi > 0.0))
        throw std::invalid_argument("SurfaceTracker: the mesh has no edges");
    m_options.collision.proximity_epsilon = m_options.proximity_fraction * m_xi;
    m_options.collision.cancel = m_options.cancel;
    if (m_mesh.periodic())
        check_periods(m_mesh);
}

ImproveReport SurfaceTracker::improve(const std::vector<std::uint8_t>* pinned) {
    if (!m_options.improve_mesh)
        return {};
    ImproveContext context;
    context.pinned = pinned;
    context.xi = m_xi;
    context.collision_safety = m_options.collision_safety;
    context.allow_topology_changes = m_options.allow_topology_changes;
    context.collision = m_options.collision;
    context.separation = m_options.topology.separation;
    context.cancel = m_options.cancel;
    return improve_mesh(m_mesh, m_options.remesh, context);
}

TopologyReport SurfaceTracker::change_topology() {
    TopologyReport report;
    if (m_options.allow_topology_changes) {
        TopologyContext context;
        context.xi = m_xi;
        context.collision_safety = m_options.collision_safety;
        context.cancel = m_options.cancel;
        report = meniscus::tracker::change_topology(m_mesh, m_options.topology, context);
    }
    if (m_mesh.has_dead_elements())
        m_mesh.compact();
    // compact() fills dead slots with the last elements, which scatters neighbours over memory
    // step by step; renumbering along a space-filling curve once they are scattered enough keeps
    // every pass over the mesh cache-friendly (profile_a1 at xi = 0.02: 14 renumberings in 400
    // steps, the whole tracker step 13 % faster than with order-preserving compaction).
    if (m_mesh.far_edge_fraction() > REORDER_FAR_EDGE_FRACTION)
        m_mesh.sort_spatially();
    return report;
}

IntegrateResult SurfaceTracker::integrate(const std::vector<Vec3>& velocities, double dt,
                                          const std::vector<std::uint8_t>* pinned) {
    const auto start = std::chrono::steady_clock::now();
    if (velocities.size() != static_cast<size_t>(m_mesh.num_vertices()))
        throw std::invalid_argument(
            "SurfaceTracker::integrate: " + std::to_string(velocities.size()) + " velocities for " +
            std::to_string(m_mesh.num_vertices()) + " vertex slots");
    if (!(dt > 0.0) || !std::isfinite(dt))
        throw std::invalid_argument("SurfaceTracker::integrate: dt must be a finite number > 0");
    if (pinned && pinned->size() != velocities.size())
        throw std::invalid_argument(
            "SurfaceTracker::integrate: pinned must be sized num_vertices()");
    const std::vector<Vec3>& x0 = m_mesh.positions();
    std::vector<Vec3> x1(x0.size());
    for (size_t i = 0; i < x0.size(); ++i) {
        const bool moves = m_mesh.vertex_alive(static_cast<int>(i)) && !(pinned && (*pinned)[i]);
        x1[i] = moves ? Vec3(x0[i] + dt * velocities[i]) : x0[i];
    }

    IntegrateResult result;
    if (m_options.collision_safety)
        result.collisions =
            resolve_collisions(m_mesh, x0, x1, dt, m_options.collision, nullptr, pinned);
    result.time_advanced = dt * result.collisions.motion_fraction;
    m_mesh.set_positions(x1);
    m_mesh.wrap_positions();  // periodic meshes: back into the fundamental box (else no-op)
    if (m_options.verify_intersection_free)
        result.intersecting_pairs =
            static_cast<int>(find_self_intersections(m_mesh).triangle_pairs.size());
    result.seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return result;
}

void SurfaceTracker::save_state(BinaryWriter& out) const {
    out.put(m_xi);
    m_mesh.save_state(out);
}

void SurfaceTracker::load_state(BinaryReader& in) {
    const double xi = in.get<double>();
    if (!(xi > 0.0) || !std::isfinite(xi))
        throw FormatError("tracker state: the characteristic length is not a positive number");
    m_mesh.load_state(in);
    m_xi = xi;
    m_options.collision.proximity_epsilon = m_options.proximity_fraction * m_xi;  // as built
}

}  // namespace meniscus::tracker
