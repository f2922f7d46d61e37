#include "tracker/collision_resolution.h"

#include "tracker/collision_candidates.h"
#include "tracker/ccd.h"
#include "tracker/distance.h"
#include "tracker/impact_zone.h"
#include "tracker/ordered_collect.h"
#include "tracker/volume_constraint.h"

#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>
#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <numeric>
#include <stdexcept>
#include <string>
#include <tuple>
#include <utility>

namespace meniscus::tracker {

namespace {

/// Grain of the parallel CCD loops.
constexpr size_t PARALLEL_GRAIN = 64;
/// CCD impulses aim for this fraction of ε_p of separating normal displacement, so that a
/// resolved pair does not end the step exactly touching.
constexpr double IMPULSE_SEPARATION_FRACTION = 0.1;

/// A closed component's volume error below this fraction of its volume is round-off of the
/// volume sums, not something collision handling changed: the volume correction leaves it.
constexpr double VOLUME_ERROR_TOLERANCE = 1e-13;
/// Newton steps of one volume correction attempt at most (each a linearised solve and a volume
/// sum; the CCD check follows the last).
constexpr int VOLUME_NEWTON_ITERATIONS = 3;

/// Inverse masses (0 for pinned vertices).
std::vector<double> inverse_masses(const SurfaceMesh& mesh, const std::vector<double>* masses,
                                   const std::vector<std::uint8_t>* pinned) {
    const size_t n = static_cast<size_t>(mesh.num_vertices());
    if (masses && masses->size() != n)
        throw std::invalid_argument("resolve_collisions: masses has " +
                                    std::to_string(masses->size()) + " entries for " +
                                    std::to_string(n) + " vertices");
    if (pinned && pinned->size() != n)
        throw std::invalid_argument("resolve_collisions: pinned has " +
                                    std::to_string(pinned->size()) + " entries for " +
                                    std::to_string(n) + " vertices");
    std::vector<double> w(n, 1.0);
    for (size_t i = 0; i < n; ++i) {
        if (masses) {
            if (!((*masses)[i] > 0.0))
                throw std::invalid_argument("resolve_collisions: masses must be > 0");
            w[i] = 1.0 / (*masses)[i];
        }
        if (pinned && (*pinned)[i])
            w[i] = 0.0;
    }
    return w;
}

/// Applies the impulse that raises the contact's relative normal displacement to its target
/// (no-op when already there). Returns true if it changed anything.
bool apply_impulse(const Contact& c, const std::vector<double>& inv_mass, std::vector<Vec3>& d) {
    const double delta = c.target - relative_normal_displacement(c, d);
    if (!(delta > 0.0))
        return false;
    double denom = 0.0;
    for (int k = 0; k < 4; ++k)
        denom += c.weights[k] * c.weights[k] * inv_mass[static_cast<size_t>(c.vertices[k])];
    if (!(denom > 0.0))
        return false;  // every vertex pinned: nothing can move
    const double j = delta / denom;
    for (int k = 0; k < 4; ++k) {
        const auto v = static_cast<size_t>(c.vertices[k]);
        d[v] += (j * c.weights[k] * inv_mass[v]) * c.normal;
    }
    return true;
}

class Resolver {
public:
    Resolver(const SurfaceMesh& mesh, const std::vector<Vec3>& x_t0, const CollisionOptions& o,
             std::vector<double> inv_mass, CollisionReport* report = nullptr)
        : m_mesh(mesh),
          m_x0(x_t0),
          m_o(o),
          m_inv_mass(std::move(inv_mass)),
          m_candidates(mesh, x_t0, o.proximity_epsilon),
          m_report(report) {}

    /// Phase 1: proximity repulsion at t0 (paper: push apart to ε_p over the step). Builds the
    /// broad phase that the first CCD sweep reuses: swept boxes of the requested motion padded
    /// by ε_p/2 plus a slack contain the static boxes repulsion needs; candidates are filtered
    /// by the exact static box test, so the contacts are the ones a static broad phase gives.
    int repel(std::vector<Vec3>& d) {
        const double padding = 0.5 * m_o.proximity_epsilon;
        m_candidates.build(d, padding);
        count_broad_phase();
        m_detected_d.clear();
        const size_t count =
            m_candidates.vertex_triangle().size() + m_candidates.edge_edge().size();
        const std::vector<Contact> contacts =
            ordered_parallel_collect<Contact>(count, [&](size_t i, std::vector<Contact>& out) {
                size_t split = 1;
                const std::array<int, 4> v = m_candidates.vertices(i, &split);
                std::array<Vec3, 4> q;
                if (!m_candidates.static_boxes_overlap(v, split, padding, q))
                    return;
                const auto add = [&](const auto& prox) {
                    if (prox.distance < m_o.proximity_epsilon)
                        out.push_back(
                            {v, prox.weights, prox.normal, m_o.proximity_epsilon - prox.distance});
                };
                if (split == 1)
                    add(point_triangle_proximity(q[0], q[1], q[2], q[3]));
                else
                    add(edge_edge_proximity(q[0], q[1], q[2], q[3]));
            });
        for (const Contact& c : contacts)
            apply_impulse(c, m_inv_mass, d);
        return static_cast<int>(contacts.size());
    }

    /// Every possible collision of the motion x0 → x0 + d (exact broad phase + CCD). Reuses the
    /// last candidates when they still cover d, else builds new ones (with slack, for the next
    /// call); either way only pairs whose swept boxes overlap exactly are tested.
    std::vector<Contact> detect(const std::vector<Vec3>& d) {
        m_o.cancel.throw_if_requested("collision resolution");
        std::vector<Vec3> x1(m_x0.size());
        for (size_t i = 0; i < x1.size(); ++i)
            x1[i] = m_x0[i] + d[i];
        if (m_candidates.cover(d)) {
            count_broad_phase();
            m_detected_d.clear();
        }
        // Only pairs with a vertex whose displacement changed since the last call are tested;
        // the others keep their last answer (a CCD answer depends on x0 and x1 alone).
        std::vector<std::uint8_t> changed;  // empty: every pair is tested
        if (m_detected_d.size() == d.size()) {
            changed.resize(d.size());
            for (size_t i = 0; i < d.size(); ++i)
                changed[i] = d[i] != m_detected_d[i] ? 1 : 0;
        }
        const std::vector<VertexTrianglePair> vt = m_candidates.moving_vertex_triangle(x1, changed);
        const std::vector<EdgeEdgePair> ee = m_candidates.moving_edge_edge(x1, changed);
        tbb::enumerable_thread_specific<std::vector<Contact>> local;
        const double target = IMPULSE_SEPARATION_FRACTION * m_o.proximity_epsilon;
        tbb::parallel_for(tbb::blocked_range<size_t>(0, vt.size() + ee.size(), PARALLEL_GRAIN),
                          [&](const tbb::blocked_range<size_t>& r) {
                              auto& out = local.local();
                              for (size_t i = r.begin(); i < r.end(); ++i) {
                                  if (i < vt.size()) {
                                      const VertexTrianglePair& p = vt[i];
                                      const Triangle& t = m_mesh.triangle(p.ti);
                                      const std::array<int, 4> v = {p.vi, t[0], t[1], t[2]};
                                      test(v, x1, false, target, out);
                                  } else {
                                      const EdgeEdgePair& p = ee[i - vt.size()];
                                      const Edge& a = m_mesh.edge(p.ei);
                                      const Edge& b = m_mesh.edge(p.ej);
                                      const std::array<int, 4> v = {a[0], a[1], b[0], b[1]};
                                      test(v, x1, true, target, out);
                                  }
                              }
                          });
        std::vector<Contact> all;
        for (auto& part : local)
            all.insert(all.end(), part.begin(), part.end());
        if (!changed.empty())
            for (const Contact& c : m_detected)
                if (!any_changed(changed, c.vertices))
                    all.push_back(c);
        // Deterministic order regardless of threading and of which answers were kept.
        std::sort(all.begin(), all.end(), [](const Contact& a, const Contact& b) {
            return std::tie(a.vertices, a.edge_edge) < std::tie(b.vertices, b.edge_edge);
        });
        m_detected_d = d;
        m_detected = all;
        return all;
    }

    /// Phase 3: impact zones (Harmon et al. 2008 inelastic projection, paper §3.8).
    /// Returns true when the motion is collision-free at the end.
    ///
    /// A pair detected again (the same four vertices, the same kind) replaces its row: the old
    /// row holds the normal and weights of a contact that the last solve has moved.
    bool impact_zones(std::vector<Vec3>& d, CollisionReport& report) {
        std::vector<Contact> constraints;
        std::map<std::pair<std::array<int, 4>, bool>, size_t> row_of;  // a pair → its row
        for (int it = 0; it < m_o.max_impact_zone_iterations; ++it) {
            std::vector<Contact> fresh = detect(d);
            if (fresh.empty())
                return true;
            ++report.impact_zone_iterations;
            for (Contact& c : fresh) {
                const auto [slot, added] =
                    row_of.emplace(std::make_pair(c.vertices, c.edge_edge), constraints.size());
                if (added)
                    constraints.push_back(std::move(c));
                else
                    constraints[slot->second] = std::move(c);
            }
            solve_zones(constraints, d, report);
        }
        return detect(d).empty();
    }

    /// Phase 4a: rigid impact zones (Bridson et al. 2002): every zone moves with the mean
    /// linear and angular momentum of its vertices; zones merge as new collisions appear.
    /// The linear interpolation of a rigid velocity field is an affine map with determinant
    /// 1 + t²|ω|² > 0, so a zone never collides with itself.
    bool rigid_zones(std::vector<Vec3>& d, CollisionReport& report) {
        std::vector<int> parent(m_x0.size());
        std::iota(parent.begin(), parent.end(), 0);
        std::vector<std::uint8_t> in_zone(m_x0.size(), 0);
        for (int it = 0; it < m_o.max_rigid_zone_iterations; ++it) {
            const std::vector<Contact> fresh = detect(d);
            if (fresh.empty())
                return true;
            ++report.rigid_zone_iterations;
            for (const Contact& c : fresh)
                for (int k = 0; k < 4; ++k) {
                    in_zone[static_cast<size_t>(c.vertices[k])] = 1;
                    unite(parent, c.vertices[0], c.vertices[k]);
                }
            make_rigid(parent, in_zone, d);
        }
        return detect(d).empty();
    }

    /// CollisionOptions::preserve_volume on the collision-free motion x0 → x0 + d whose
    /// requested displacements were `reference`: each closed component gets back the volume
    /// the response changed, through the vertices the response left at their requested
    /// displacement; a corrected motion is kept only when detect() finds it free, and each
    /// rejected attempt takes the vertices of the collisions it found out of the next one.
    void restore_volume(const std::vector<Vec3>& reference, std::vector<Vec3>& d,
                        CollisionReport& report) {
        const size_t n = m_x0.size();
        std::vector<std::uint8_t> movable(n, 0);
        bool responded = false;
        for (size_t i = 0; i < n; ++i) {
            movable[i] = d[i] == reference[i] ? 1 : 0;
            responded = responded || !movable[i];
        }
        if (!responded)
            return;  // the response changed nothing
        const VolumeComponents components = volume_components(m_mesh);
        const std::vector<double> requested =
            component_volumes_at(m_mesh, components, ends(reference));
        const std::vector<double> responded_volume =
            component_volumes_at(m_mesh, components, ends(d));
        std::vector<double> error(static_cast<size_t>(components.count), 0.0);
        double volume_scale = 0.0;  // Σ |V| of the components corrected
        bool any = false;
        for (size_t c = 0; c < error.size(); ++c) {
            const double e = requested[c] - responded_volume[c];
            if (!components.closed[c] ||
                !(std::abs(e) > VOLUME_ERROR_TOLERANCE * std::abs(requested[c])))
                continue;
            error[c] = e;
            volume_scale += std::abs(requested[c]);
            report.volume_error_before += std::abs(e);
            any = true;
        }
        report.volume_error_after = report.volume_error_before;
        if (!any)
            return;
        for (int round = 0; round < m_o.max_volume_rounds; ++round) {
            // Newton on the volume constraints (each step the linearised solve at the current
            // positions): the volume is cubic in the positions, and one linear step leaves an
            // error of second order in the correction.
            std::vector<Vec3> trial = d;
            for (int it = 0; it < VOLUME_NEWTON_ITERATIONS; ++it) {
                const std::vector<Vec3> x = ends(trial);
                std::vector<double> residual = component_volumes_at(m_mesh, components, x);
                double remaining = 0.0;
                for (size_t c = 0; c < error.size(); ++c) {
                    residual[c] = error[c] != 0.0 ? requested[c] - residual[c] : 0.0;
                    remaining += std::abs(residual[c]);
                }
                if (!(remaining > VOLUME_ERROR_TOLERANCE * volume_scale))
                    break;
                const std::vector<Vec3> delta = volume_restoring_displacements(
                    m_mesh, components, x, residual, movable, m_inv_mass);
                for (size_t i = 0; i < n; ++i)
                    trial[i] += delta[i];
            }
            ++report.volume_rounds;
            const std::vector<Contact> hits = detect(trial);
            if (hits.empty()) {
                d = std::move(trial);
                report.volume_restored = true;
                const std::vector<double> corrected =
                    component_volumes_at(m_mesh, components, ends(d));
                report.volume_error_after = 0.0;
                for (size_t c = 0; c < error.size(); ++c)
                    if (error[c] != 0.0)
                        report.volume_error_after += std::abs(requested[c] - corrected[c]);
                return;
            }
            for (const Contact& c : hits)
                for (int k = 0; k < 4; ++k)
                    movable[static_cast<size_t>(c.vertices[k])] = 0;
        }
    }

private:
    const Vec3& x0(int vi) const { return m_x0[static_cast<size_t>(vi)]; }

    /// x0 + d.
    std::vector<Vec3> ends(const std::vector<Vec3>& d) const {
        std::vector<Vec3> x(m_x0.size());
        for (size_t i = 0; i < x.size(); ++i)
            x[i] = m_x0[i] + d[i];
        return x;
    }

    void count_broad_phase() const {
        if (m_report)
            ++m_report->broad_phases;
    }

    void test(const std::array<int, 4>& v, const std::vector<Vec3>& x1, bool edge_edge,
              double target, std::vector<Contact>& out) const {
        std::array<Vec3, 4> q0, q1;
        pair_positions(m_mesh, m_x0, x1, v, q0, q1);
        // One detailed query: its may_collide is the boolean query's answer (ccd.h), and a hit
        // is not searched twice (true contacts are the expensive CCD queries).
        const CcdResult r =
            edge_edge
                ? edge_edge_ccd_detailed(q0[0], q0[1], q0[2], q0[3], q1[0], q1[1], q1[2], q1[3])
                : point_triangle_ccd_detailed(q0[0], q0[1], q0[2], q0[3], q1[0], q1[1], q1[2],
                                              q1[3]);
        if (r.may_collide)
            out.push_back({v, r.weights, r.normal, target, edge_edge});
    }

    static int find(std::vector<int>& parent, int v) {
        while (parent[static_cast<size_t>(v)] != v) {
            parent[static_cast<size_t>(v)] =
                parent[static_cast<size_t>(parent[static_cast<size_t>(v)])];
            v = parent[static_cast<size_t>(v)];
        }
        return v;
    }
    static void unite(std::vector<int>& parent, int a, int b) {
        a = find(parent, a);
        b = find(parent, b);
        if (a != b)
            parent[static_cast<size_t>(std::max(a, b))] = std::min(a, b);
    }

    /// Groups constraints into zones of vertex-connected contacts and solves each zone:
    /// d ← d + M⁻¹ Cᵀ λ with (C M⁻¹ Cᵀ) λ = b − C d.
    void solve_zones(const std::vector<Contact>& constraints, std::vector<Vec3>& d,
                     CollisionReport& report) const {
        std::vector<int> parent(m_x0.size());
        std::iota(parent.begin(), parent.end(), 0);
        for (const Contact& c : constraints)
            for (int k = 1; k < 4; ++k)
                unite(parent, c.vertices[0], c.vertices[k]);
        std::vector<std::vector<int>> zone_rows;
        std::vector<int> zone_of_root(m_x0.size(), -1);
        for (size_t i = 0; i < constraints.size(); ++i) {
            const int root = find(parent, constraints[i].vertices[0]);
            int& z = zone_of_root[static_cast<size_t>(root)];
            if (z < 0) {
                z = static_cast<int>(zone_rows.size());
                zone_rows.emplace_back();
            }
            zone_rows[static_cast<size_t>(z)].push_back(static_cast<int>(i));
        }
        report.impact_zones = static_cast<int>(zone_rows.size());
        for (const std::vector<int>& rows : zone_rows)
            project_impact_zone(constraints, rows, m_inv_mass, m_o.max_zone_matrix_entries, d,
                                report);
    }

    void make_rigid(std::vector<int>& parent, const std::vector<std::uint8_t>& in_zone,
                    std::vector<Vec3>& d) const {
        std::vector<std::vector<int>> zones;
        std::vector<int> zone_of_root(m_x0.size(), -1);
        for (size_t v = 0; v < m_x0.size(); ++v) {
            if (!in_zone[v])
                continue;
            const int root = find(parent, static_cast<int>(v));
            int& z = zone_of_root[static_cast<size_t>(root)];
            if (z < 0) {
                z = static_cast<int>(zones.size());
                zones.emplace_back();
            }
            zones[static_cast<size_t>(z)].push_back(static_cast<int>(v));
        }
        for (const std::vector<int>& zone : zones) {
            bool any_pinned = false;
            for (int v : zone)
                any_pinned = any_pinned || m_inv_mass[static_cast<size_t>(v)] == 0.0;
            if (any_pinned) {
                // A pinned vertex pins its whole zone.
                for (int v : zone)
                    d[static_cast<size_t>(v)].setZero();
                continue;
            }
            // Periodic meshes: the zone's vertices at their images nearest its first vertex
            // (a zone is a cluster of contacts, far smaller than half a period).
            const auto at = [&](int v) -> Vec3 {
                return m_mesh.periodic() ? m_mesh.periods().nearest_image(x0(v), x0(zone.front()))
                                         : x0(v);
            };
            double mass = 0.0;
            Vec3 com = Vec3::Zero(), momentum = Vec3::Zero();
            for (int v : zone) {
                const double mv = 1.0 / m_inv_mass[static_cast<size_t>(v)];
                mass += mv;
                com += mv * at(v);
                momentum += mv * d[static_cast<size_t>(v)];
            }
            com /= mass;
            const Vec3 linear = momentum / mass;
            Vec3 angular = Vec3::Zero();
            Eigen::Matrix3d inertia = Eigen::Matrix3d::Zero();
            for (int v : zone) {
                const double mv = 1.0 / m_inv_mass[static_cast<size_t>(v)];
                const Vec3 r = at(v) - com;
                angular += mv * r.cross(d[static_cast<size_t>(v)] - linear);
                inertia += mv * (r.squaredNorm() * Eigen::Matrix3d::Identity() - r * r.transpose());
            }
            const Vec3 omega = inertia.completeOrthogonalDecomposition().solve(angular);
            for (int v : zone)
                d[static_cast<size_t>(v)] = linear + omega.cross(at(v) - com);
        }
    }

    const SurfaceMesh& m_mesh;
    const std::vector<Vec3>& m_x0;
    const CollisionOptions& m_o;
    std::vector<double> m_inv_mass;
    CollisionCandidates m_candidates;
    CollisionReport* m_report = nullptr;  ///< counts broad phases when set
    /// detect()'s last displacements and contacts, on the current candidates (empty: none).
    std::vector<Vec3> m_detected_d;
    std::vector<Contact> m_detected;
};

}  // namespace

void CollisionOptions::validate() const {
    if (!(proximity_epsilon > 0.0) || !std::isfinite(proximity_epsilon))
        throw std::invalid_argument("proximity_epsilon: expected a number > 0");
    if (impulse_sweeps < 0)
        throw std::invalid_argument("impulse_sweeps: expected an integer >= 0");
    if (max_impact_zone_iterations < 1)
        throw std::invalid_argument("max_impact_zone_iterations: expected an integer >= 1");
    if (max_rigid_zone_iterations < 0)
        throw std::invalid_argument("max_rigid_zone_iterations: expected an integer >= 0");
    if (max_step_shortenings < 0)
        throw std::invalid_argument("max_step_shortenings: expected an integer >= 0");
    if (max_zone_matrix_entries < 1)
        throw std::invalid_argument("max_zone_matrix_entries: expected an integer >= 1");
    if (max_volume_rounds < 1)
        throw std::invalid_argument("max_volume_rounds: expected an integer >= 1");
}

CollisionReport resolve_collisions(const SurfaceMesh& mesh, const std::vector<Vec3>& x_t0,
                                   std::vector<Vec3>& x_t1, double dt,
                                   const CollisionOptions& options,
                                   const std::vector<double>* masses,
                                   const std::vector<std::uint8_t>* pinned) {
    options.validate();
    const size_t n = static_cast<size_t>(mesh.num_vertices());
    if (x_t0.size() != n || x_t1.size() != n)
        throw std::invalid_argument("resolve_collisions: " + std::to_string(x_t0.size()) + " and " +
                                    std::to_string(x_t1.size()) + " positions for " +
                                    std::to_string(n) + " vertices");
    if (!(dt > 0.0) || !std::isfinite(dt))
        throw std::invalid_argument("resolve_collisions: dt must be a finite number > 0");
    const std::vector<double> inv = inverse_masses(mesh, masses, pinned);
    CollisionReport report;
    Resolver resolver(mesh, x_t0, options, inv, &report);

    // Work with displacements d = x_t1 − x_t0 (velocities times dt).
    std::vector<Vec3> d(n);
    for (size_t i = 0; i < n; ++i)
        d[i] = x_t1[i] - x_t0[i];
    const std::vector<Vec3> requested = d;

    if (options.repulsion)
        report.proximities = resolver.repel(d);

    // The verified motion x_t0 → x_t0 + free, requested as x_t0 + reference (the requested
    // displacements, shortened with the step), made volume-aware when asked.
    const auto finish = [&](std::vector<Vec3>& free, const std::vector<Vec3>& reference) {
        if (options.preserve_volume)
            resolver.restore_volume(reference, free, report);
        for (size_t i = 0; i < n; ++i)
            x_t1[i] = x_t0[i] + free[i];
        return report;
    };

    // Phase 2: sweeps of individual impulses.
    for (int sweep = 0; sweep < options.impulse_sweeps; ++sweep) {
        const std::vector<Contact> contacts = resolver.detect(d);
        if (sweep == 0)
            report.collisions_first_sweep = static_cast<int>(contacts.size());
        if (contacts.empty())
            return finish(d, requested);  // verified collision-free without impact zones
        for (const Contact& c : contacts)
            report.impulses += apply_impulse(c, inv, d) ? 1 : 0;
    }

    // Phases 3 and 4, on shorter and shorter motions if needed.
    double fraction = 1.0;
    for (int attempt = 0; attempt <= options.max_step_shortenings; ++attempt) {
        std::vector<Vec3> trial = d;
        if (resolver.impact_zones(trial, report) || resolver.rigid_zones(trial, report)) {
            report.motion_fraction = fraction;
            std::vector<Vec3> reference = requested;
            if (fraction != 1.0)
                for (size_t i = 0; i < n; ++i)
                    reference[i] = fraction * requested[i];
            return finish(trial, reference);
        }
        // Fallback: shorten the whole motion and try again from the requested one.
        ++report.step_shortenings;
        fraction *= 0.5;
        for (size_t i = 0; i < n; ++i)
            d[i] = fraction * requested[i];
    }
    // Nothing could be verified: do not move (always collision-free from a free state).
    x_t1 = x_t0;
    report.motion_fraction = 0.0;
    report.collision_free = true;
    return report;
}

bool motion_is_collision_free(const SurfaceMesh& mesh, const std::vector<Vec3>& x_t0,
                              const std::vector<Vec3>& x_t1) {
    CollisionOptions o;
    Resolver resolver(mesh, x_t0, o, std::vector<double>(x_t0.size(), 1.0));
    std::vector<Vec3> d(x_t0.size());
    if (x_t1.size() != x_t0.size())
        throw std::invalid_argument("motion_is_collision_free: position counts differ");
    for (size_t i = 0; i < d.size(); ++i)
        d[i] = x_t1[i] - x_t0[i];
    return resolver.detect(d).empty();
}

}  // namespace meniscus::tracker
