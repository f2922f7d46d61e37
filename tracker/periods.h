#pragma once
/// \file The box a periodic surface wraps around (issue 39).
///
/// Along an axis with a period L > 0 the points x and x + k·L·e_axis (k an integer) are the same
/// point: a liquid column along that axis is a closed tube joined to itself across the box's
/// faces. A periodic mesh keeps its vertices in the fundamental box [origin, origin + L) and
/// reads every element by the minimum-image convention: a corner is taken at its image nearest
/// the element's first corner. That is exact while every element (and every pair of elements
/// the collision handling looks at together) spans less than half a period, which the tracker
/// checks (SurfaceTracker refuses a period under PERIOD_TO_EDGE_RATIO mesh edges).
///
/// Geometry code reads positions through `nearest_image()` (or `SurfaceMesh::position_near()`),
/// which for an axis without a period returns its argument unchanged: non-periodic meshes pay one
/// branch.

#include <Eigen/Core>

#include <array>

namespace meniscus::tracker {

struct MeshPeriods {
    /// Smallest period in units of the longest edge that the tracker accepts: the minimum image
    /// of an element and of each pair the broad phase hands on must be unambiguous.
    static constexpr double PERIOD_TO_EDGE_RATIO = 8.0;

    Eigen::Vector3d origin = Eigen::Vector3d::Zero();  ///< the fundamental box's low corner
    Eigen::Vector3d length = Eigen::Vector3d::Zero();  ///< period per axis; 0 = does not wrap

    bool wraps(int axis) const { return length[axis] > 0.0; }
    bool any() const { return wraps(0) || wraps(1) || wraps(2); }

    /// The whole-period shift s such that p + s is the image of p nearest `reference`
    /// (0 along axes that do not wrap).
    Eigen::Vector3d shift_towards(const Eigen::Vector3d& p, const Eigen::Vector3d& reference) const;
    /// p moved by whole periods to its image nearest `reference`.
    Eigen::Vector3d nearest_image(const Eigen::Vector3d& p,
                                  const Eigen::Vector3d& reference) const {
        return any() ? Eigen::Vector3d(p + shift_towards(p, reference)) : p;
    }
    /// p moved by whole periods into [origin, origin + length) along each wrapping axis.
    Eigen::Vector3d wrap(const Eigen::Vector3d& p) const;
    /// p − q between their nearest images (the shortest periodic displacement).
    Eigen::Vector3d difference(const Eigen::Vector3d& p, const Eigen::Vector3d& q) const {
        return nearest_image(p, q) - q;
    }

    /// Throws std::invalid_argument naming the field: lengths finite and ≥ 0, origin finite.
    void validate() const;

    friend bool operator==(const MeshPeriods& a, const MeshPeriods& b) {
        return a.origin == b.origin && a.length == b.length;
    }
    friend bool operator!=(const MeshPeriods& a, const MeshPeriods& b) { return !(a == b); }
};

}  // namespace meniscus::tracker
