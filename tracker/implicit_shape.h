#pragma once
/// \file Implicit shapes for initial surfaces: φ(x) < 0 inside, > 0 outside, 0 on the surface.
///
/// Primitives return exact signed distances where a closed form exists (sphere, box, capped
/// cylinder, torus) and a sign-correct, Lipschitz approximation otherwise (ellipsoid, smooth
/// unions). CSG combinations use min/max, which keep the zero set exact but make φ only a
/// bound on the distance away from it. Units: metres.

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <memory>
#include <vector>

namespace meniscus::tracker {

using Box3 = Eigen::AlignedBox3d;

/// A closed region of space given by an implicit function.
class ImplicitShape {
public:
    virtual ~ImplicitShape() = default;
    /// Signed value at x: negative inside, positive outside (a distance or a bound on it).
    virtual double value(const Eigen::Vector3d& x) const = 0;
    /// Gradient of value() at x (central differences at a scale relative to the bounds unless a
    /// shape knows better). Points outward.
    virtual Eigen::Vector3d gradient(const Eigen::Vector3d& x) const;
    /// A box containing the whole region (the zero set and the inside).
    virtual Box3 bounds() const = 0;
    /// An estimate of the area (m²) of the surface φ = 0 inside `within`, for sizing a mesh
    /// before meshing: closed forms for the primitives (whole surface, `within` ignored; an
    /// ellipsoid by Thomsen's formula), an upper bound for combinations (the sum of their parts,
    /// each within the combination's bounds); +∞ for an unbounded surface in an unbounded box.
    virtual double surface_area(const Box3& within) const = 0;
};

using ShapePtr = std::shared_ptr<const ImplicitShape>;

/// Sphere of `radius` > 0 around `center`. Throws std::invalid_argument on radius ≤ 0.
ShapePtr make_sphere(const Eigen::Vector3d& center, double radius);
/// Axis-aligned ellipsoid with semi-axes `radii` (all > 0).
ShapePtr make_ellipsoid(const Eigen::Vector3d& center, const Eigen::Vector3d& radii);
/// Axis-aligned box between `min_corner` and `max_corner` (max > min in every axis).
ShapePtr make_box(const Eigen::Vector3d& min_corner, const Eigen::Vector3d& max_corner);
/// Capped cylinder: axis through `center` along `axis` (normalized inside), `radius`, total
/// `height` (> 0).
ShapePtr make_cylinder(const Eigen::Vector3d& center, const Eigen::Vector3d& axis, double radius,
                       double height);
/// Capped cylinder whose radius varies along the axis as r(s) = radius·(1 + amplitude·cos(2πs /
/// wavelength)), s measured from the centre (Rayleigh–Plateau initial condition). amplitude in
/// [0, 1), wavelength > 0. φ is the radial gap r − r(s) (a distance bound for small amplitude).
ShapePtr make_perturbed_cylinder(const Eigen::Vector3d& center, const Eigen::Vector3d& axis,
                                 double radius, double height, double amplitude, double wavelength);
/// Torus around `axis` through `center`: tube centre circle `major_radius`, tube
/// `minor_radius` (0 < minor < major).
ShapePtr make_torus(const Eigen::Vector3d& center, const Eigen::Vector3d& axis, double major_radius,
                    double minor_radius);
/// Sethian-style dumbbell along x: two balls of `bulb_radius` centred at center ± (separation/2)
/// e_x joined by a cylindrical handle of `handle_radius`, blended over `blend_radius` (≥ 0) by a
/// smooth minimum so the surface is C¹ where the handle meets the bulbs.
ShapePtr make_dumbbell(const Eigen::Vector3d& center, double bulb_radius, double separation,
                       double handle_radius, double blend_radius);
/// Half-space below a cosine-perturbed plane (an unbounded region; intersect it with a box to
/// get a closed slab). With s = (x − origin)·up and t = (x − origin)·direction, the region is
/// s < amplitude·cos(2π t / wavelength): `origin` is a crest of the mean plane, `up` the unit
/// normal pointing out of the region (normalized inside), `direction` the wave direction (its
/// component along `up` is removed, then normalized). Example: up = e_z, direction = e_x,
/// origin = (x0, 0, h) gives z < h + A·cos(2π(x − x0)/λ). φ = (s − A cos(2πt/λ)) / sqrt(1 + (2πA/λ)²),
/// so |∇φ| ≤ 1 and |φ| is a lower bound on the distance to the surface. bounds() is infinite
/// except on the side `up` points to when `up` is a coordinate axis. Throws
/// std::invalid_argument on amplitude < 0, wavelength ≤ 0, zero vectors, or `direction`
/// parallel to `up`.
ShapePtr make_wavy_half_space(const Eigen::Vector3d& origin, const Eigen::Vector3d& up,
                              const Eigen::Vector3d& direction, double amplitude,
                              double wavelength);
/// Union of one or more shapes (min of values).
ShapePtr make_union(std::vector<ShapePtr> shapes);
/// Intersection of one or more shapes (max of values).
ShapePtr make_intersection(std::vector<ShapePtr> shapes);
/// `a` minus `b` (max(φ_a, −φ_b)).
ShapePtr make_difference(ShapePtr a, ShapePtr b);

/// Signed distance (negative inside) from x to the zero set of `shape`, where the shape's value
/// is only a bound on it (blends, CSG): x is projected onto the surface by Newton steps along
/// ∇φ, then moved tangentially towards x and re-projected, until x − p is normal to the surface
/// at p within `tolerance` (m; the first-order condition of the closest point p) or 50 rounds
/// have run. The level-set references' initial conditions (coupling/levelset_reference,
/// tracker/flows/axisymmetric_mcf_reference).
double projected_signed_distance(const ImplicitShape& shape, const Eigen::Vector3d& x,
                                 double tolerance);

}  // namespace meniscus::tracker
