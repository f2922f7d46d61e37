#pragma once
/// \file Curvature-adaptive edge-length limits. The paper (§3.5) splits edges longer than α and
/// collapses edges shorter than β everywhere. Where the surface turns sharply — a thinning neck,
/// a tight fold — edges of length ξ cut a chord that sags L²κ/8 off the surface, and a neck only
/// a few edges around moves too slowly under mean curvature and pinches late (A2 at ξ = 0.04).
/// With RemeshOptions::curvature_edge_fraction = c > 0, an edge whose endpoints see curvature κ
/// is split above α·s and collapsed below β·s, with s = clamp(c / (κ α), s_min, 1): edges turn
/// by at most about c radians, and β/α keeps its ratio so splits and collapses never undo each
/// other. κ at a vertex is the larger principal curvature, in magnitude, of a least-squares fit
/// of the vertex normals' variation over its one-ring (1/r on a sphere or a tube of radius r,
/// at any resolution); with RemeshOptions::curvature_sizing_convex_only the larger positive
/// one (concave creases keep α and β).
///
/// With RemeshOptions::thin_sheet_sag_fraction = f > 0, s is also at most sqrt(8 f h / κ) / α
/// (floored at s_min) where the vertex faces another part of the surface at distance h
/// (vertex_facing_distance): the chord sag κ(sα)²/8 stays below f·h, so the two discretized
/// sides of a thin, curved sheet do not meet before the sheet itself closes.

#include "tracker/mesh.h"
#include "tracker/remesh_options.h"

#include <vector>

namespace meniscus::tracker {

/// Per-vertex curvature estimate (1/m): with area-weighted normals n, the symmetric 2×2 S in
/// the tangent plane of n_v fitting n_w − n_v ≈ S (x_w − x_v) over the neighbours w (each
/// weighted by 1/|x_w − x_v|²), and max |eigenvalue of S|; where the neighbours do not span
/// the plane, the largest angle(n_v, n_w) / |x_v − x_w|. 0 for dead or isolated vertices.
/// Sized num_vertices().
std::vector<double> vertex_turning_curvature(const SurfaceMesh& mesh);
/// The same from given unit (or zero) vertex normals, sized num_vertices(). With
/// `convex_only`, the largest eigenvalue of S floored at 0 (positive where the surface bends
/// away from its outward normal, as on a sphere), and in the fallback only neighbours with
/// (n_w − n_v)·(x_w − x_v) > 0 count: 0 on a concave surface.
std::vector<double> vertex_turning_curvature(const SurfaceMesh& mesh,
                                             const std::vector<Vec3>& normals,
                                             bool convex_only = false);

/// Per-vertex distance (m) to the nearest live triangle that does not contain the vertex and
/// faces it: the triangle's normal opposes the vertex normal (n_t · n_v < −1/2), as the other
/// side of a thin sheet or of a thin gap does. Only triangles within radius[v] are searched
/// (radius ≤ 0 skips the vertex); +∞ where none is found. Sized num_vertices().
std::vector<double> vertex_facing_distance(const SurfaceMesh& mesh,
                                           const std::vector<Vec3>& normals,
                                           const std::vector<double>& radius);

/// Largest growth of the adaptive target edge length per unit distance along the mesh: after
/// the curvature and thin-sheet terms, s α is graded so that it rises by at most this much per
/// metre away from a refined vertex. Without it a lone refined vertex gets a fan of split edges
/// whose outer triangles are slivers (A4 with thin-sheet sizing: minimum angles of 0.1°).
constexpr double SIZE_GRADING = 0.5;

/// Edge-length limits for one split or collapse call. On a periodic mesh α is at most the
/// smallest period over MeshPeriods::PERIOD_TO_EDGE_RATIO (β scaled with it, keeping β/α), so
/// that remeshing never grows an edge to where the minimum image could be ambiguous; options
/// and ξ are not changed (remesh_limits() still reports the unclamped values). Curvature and facing
/// distances are measured when the object is built; vertices created afterwards get the nominal
/// limits (s = 1) unless inherit() grades them from their split edge's endpoints.
class EdgeSizing {
public:
    /// Throws std::invalid_argument on invalid options or ξ ≤ 0.
    EdgeSizing(const SurfaceMesh& mesh, const RemeshOptions& options, double xi);
    /// Gives vertex vi, created by splitting the edge (a, b) after the measurement, the graded
    /// bound of its endpoints' target lengths, so that refinement continues within the call.
    void inherit(const SurfaceMesh& mesh, int vi, int a, int b);
    /// s ∈ [s_min, 1] for the edge between vertices a and b (1 when adaptivity is off).
    double scale(int a, int b) const;
    double max_length(int a, int b) const { return m_limits.max_edge_length * scale(a, b); }
    double min_length(int a, int b) const { return m_limits.min_edge_length * scale(a, b); }
    /// Nominal limits (s = 1).
    const RemeshLimits& limits() const { return m_limits; }
    bool adaptive() const { return !m_scale.empty(); }

private:
    void grade(const SurfaceMesh& mesh);
    RemeshLimits m_limits;
    std::vector<double> m_scale;  ///< per vertex; empty when adaptivity is off
};

}  // namespace meniscus::tracker
