#pragma once
/// \file Quadric metric tensor of a vertex and its eigen-decomposition (Jiao 2007; paper §3.5.3,
/// §3.6.1): A = Σ wᵢ nᵢ nᵢᵀ / Σ wᵢ over the incident triangles (unit normals nᵢ, area weights
/// wᵢ). Its dominant eigenvectors span the "primary space" (normal directions); the rest is the
/// "null space" in which a vertex may slide without changing the shape to first order: the
/// tangent plane on a smooth patch, the ridge line on a ridge, nothing at a corner.

#include "tracker/mesh.h"

#include <Eigen/Core>

namespace meniscus::tracker {

/// What kind of surface point a vertex sits on, by the rank of its primary space.
enum class VertexFeature {
    smooth = 1,  ///< one dominant normal direction: null space is the tangent plane
    ridge = 2,   ///< two: null space is the ridge line
    corner = 3,  ///< three: null space is empty
};

/// Eigen-decomposition of a vertex's quadric metric tensor.
struct VertexQuadric {
    /// Eigenvalues λ₁ ≥ λ₂ ≥ λ₃ ≥ 0 (they sum to 1 for a vertex with triangles).
    Eigen::Vector3d eigenvalues = Eigen::Vector3d::Zero();
    /// Unit eigenvectors as columns, matching `eigenvalues`.
    Eigen::Matrix3d eigenvectors = Eigen::Matrix3d::Identity();
    VertexFeature feature = VertexFeature::corner;
    /// Projector onto the null space (I − e₁e₁ᵀ, e₃e₃ᵀ or 0).
    Eigen::Matrix3d null_space_projector() const;
};

/// Thresholds of the feature classification (RemeshOptions carries the defaults).
struct FeatureThresholds {
    double ridge_eigenvalue_ratio = 0.1;   ///< ridge when λ₂ ≥ this · λ₁
    double corner_eigenvalue_ratio = 0.1;  ///< corner when λ₃ ≥ this · λ₁
};

/// Quadric of live vertex `vi` at the mesh's positions. A vertex without triangles of non-zero
/// area is classified as a corner (it must not move).
VertexQuadric vertex_quadric(const SurfaceMesh& mesh, int vi, const FeatureThresholds& thresholds);

}  // namespace meniscus::tracker
