#pragma once
/// \file Isotropic remeshing onto a known surface (Botsch & Kobbelt 2004 style): split long
/// edges, collapse short ones, Delaunay flips, tangential relaxation, projection back onto the
/// surface. Used to build well-shaped initial meshes from implicit shapes; it is NOT
/// collision-safe (the tracker's remeshing is) and assumes the target edge length resolves the
/// surface's features.

#include "common/cancellation.h"
#include "tracker/mesh.h"

#include <functional>

namespace meniscus::tracker {

/// Options of isotropic_remesh(). Defaults are the usual 4/3 and 4/5 thresholds.
struct IsotropicRemeshOptions {
    double target_edge_length = 0.0;    ///< metres, > 0
    int iterations = 8;                 ///< outer iterations (split, collapse, flip, smooth)
    int smoothing_steps = 3;            ///< tangential relaxation steps per iteration
    double split_ratio = 4.0 / 3.0;     ///< split edges longer than ratio · target
    double collapse_ratio = 4.0 / 5.0;  ///< collapse edges shorter than ratio · target
    /// Refuse collapses/flips that turn a triangle normal by more than this (degrees).
    double max_normal_change_degrees = 45.0;
    CancellationToken cancel;  ///< checked every iteration (throws meniscus::Cancelled)
    void validate() const;  ///< throws std::invalid_argument naming the field
};

/// What isotropic_remesh() did.
struct IsotropicRemeshReport {
    int splits = 0;
    int collapses = 0;
    int flips = 0;
};

/// Moves a point onto the surface (closest point or a good approximation of it).
using SurfaceProjection = std::function<Vec3(const Vec3&)>;

/// Remeshes a closed, consistently oriented manifold mesh in place; the result is compacted.
IsotropicRemeshReport isotropic_remesh(SurfaceMesh& mesh, const IsotropicRemeshOptions& options,
                                       const SurfaceProjection& project);

}  // namespace meniscus::tracker
