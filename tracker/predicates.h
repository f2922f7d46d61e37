#pragma once
/// \file Exact geometric predicates (paper §3.4): orient2d and orient3d.
///
/// Every predicate returns the exact sign of a polynomial in the input coordinates, for all
/// finite double inputs. Evaluation is staged: a floating-point evaluation with a certified
/// forward error bound (semi-static filter) answers the vast majority of queries; when the bound
/// cannot certify the sign, the determinant is recomputed exactly with floating-point expansion
/// arithmetic (error-free two-sum / two-product); inputs whose exponents are too far apart for
/// the expansions to stay clear of underflow and overflow are evaluated with exact big integers.
///
/// Sign convention: -1, 0 or +1, as `int`. Non-finite inputs (NaN, ±inf) are API misuse and
/// throw std::invalid_argument.

#include <Eigen/Core>

namespace meniscus::tracker {

/// Sign of the 2D orientation determinant det[b - a, c - a] = (b-a).x (c-a).y - (b-a).y (c-a).x.
/// Returns +1 when a, b, c turn counter-clockwise (c lies left of the directed line a→b),
/// -1 when clockwise, 0 when exactly collinear. Exact. Throws std::invalid_argument on non-finite
/// input.
int orient2d(const Eigen::Vector2d& a, const Eigen::Vector2d& b, const Eigen::Vector2d& c);

/// orient2d of the projections of 3D points onto the coordinate plane that drops axis
/// `drop_axis` (0 = x, 1 = y, 2 = z). The kept axes are taken in cyclic order after the dropped
/// one — (y, z) for x, (z, x) for y, (x, y) for z — so that the result equals the sign of the
/// `drop_axis` component of (b - a) × (c - a). Exact. Throws std::invalid_argument on
/// non-finite input or drop_axis outside 0..2.
int orient2d_projected(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c,
                       int drop_axis);

/// Sign of the 3D orientation determinant (d - a) · ((b - a) × (c - a)).
/// Returns +1 when d lies on the side of the plane through a, b, c into which the normal
/// (b - a) × (c - a) points (a, b, c counter-clockwise seen from d), -1 on the other side, 0 when
/// the four points are exactly coplanar (this includes every case where a, b, c are collinear).
/// Note: this is the opposite of Shewchuk's `orient3d` sign. Exact. Throws std::invalid_argument
/// on non-finite input.
int orient3d(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c,
             const Eigen::Vector3d& d);

/// True when a, b, c are exactly collinear (including coincident points). Exact.
bool collinear3d(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c);

/// Returned by the `_filtered` predicates when floating point cannot certify the sign.
constexpr int SIGN_UNCERTAIN = 2;

/// The floating-point filter stage of orient3d alone: the exact sign (-1 or +1, same convention
/// as orient3d) when the certified error bound proves it, SIGN_UNCERTAIN otherwise (always for
/// exactly coplanar inputs). Exists so that benchmarks can measure the filter's hit rate.
int orient3d_filtered(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c,
                      const Eigen::Vector3d& d);

/// orient3d forced through the exact path (no filter). Same result and convention as orient3d;
/// exists so that benchmarks and tests can compare the two stages.
int orient3d_exact(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c,
                   const Eigen::Vector3d& d);

}  // namespace meniscus::tracker
