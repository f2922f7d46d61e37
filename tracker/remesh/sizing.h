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
/// at any resolution).

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

/// Edge-length limits for one pass over the mesh. The curvature is measured when the object is
/// built; vertices created afterwards get the nominal limits (s = 1) until the next pass.
class EdgeSizing {
public:
    /// Throws std::invalid_argument on invalid options or ξ ≤ 0.
    EdgeSizing(const SurfaceMesh& mesh, const RemeshOptions& options, double xi);
    /// s ∈ [s_min, 1] for the edge between vertices a and b (1 when adaptivity is off).
    double scale(int a, int b) const;
    double max_length(int a, int b) const { return m_limits.max_edge_length * scale(a, b); }
    double min_length(int a, int b) const { return m_limits.min_edge_length * scale(a, b); }
    /// Nominal limits (s = 1).
    const RemeshLimits& limits() const { return m_limits; }
    bool adaptive() const { return !m_scale.empty(); }

private:
    RemeshLimits m_limits;
    std::vector<double> m_scale;  ///< per vertex; empty when adaptivity is off
};

}  // namespace meniscus::tracker
