#pragma once
/// \file Meshing an implicit shape into a closed, consistently oriented triangle mesh.
///
/// Marching tetrahedra on a regular grid (each cube cut into six tetrahedra around its main
/// diagonal, so neighbouring cubes agree and the surface is watertight), crossings located by
/// root finding on φ, then isotropic remeshing with projection onto φ = 0 to reach the
/// requested mean edge length without slivers. Normals point outward (towards φ > 0).

#include "common/cancellation.h"
#include "tracker/implicit_shape.h"
#include "tracker/mesh.h"

namespace meniscus::tracker {

/// Refinement around the creases of a shape (where its gradient jumps, e.g. the dumbbell's
/// handle meeting its bulbs), after remeshing: `levels` passes, each splitting at its midpoint,
/// moved onto φ = 0, every edge longer than edge_length·2^−(pass+1) whose midpoint lies within
/// `band` of a crease point, the midpoint of an edge whose end normals ∇φ/|∇φ| turn by more
/// than `angle`. Under mean-curvature flow a crease rounds off at once over a width growing as
/// √t; sampled at edge_length that rounding starts wrong, and a concave crease lags by a dent
/// that diffuses into the neighbouring surface. Refined once, the A2 dumbbell's vertex L1 up to
/// its pinch is 2–3× smaller (app/validate_parameters.h). Give a tracker of the refined mesh the
/// unrefined ξ (ImplicitMeshReport::nominal_characteristic_length(),
/// TrackerOptions::characteristic_length), or every size it derives from ξ shrinks too.
///
/// `snap` (before any refinement): vertices near a crease move onto it and edges cutting across
/// it flip to run along it (tracker/crease_snap.h, with `angle`), so that sharp edges such as a
/// slot cut into a ball are edges of the mesh instead of chamfers whose triangles leave the
/// surface by up to half their size. Edge lengths stay those of the remeshing.
struct CreaseRefinementOptions {
    static constexpr int MAX_LEVELS = 4;  ///< 16× finer than edge_length at most
    int levels = 0;                       ///< halvings, in [0, MAX_LEVELS]; 0 = off
    double angle = 0.35;                  ///< radians, in (0, π); with snap in (0, π/2)
    double band = 0.0;                    ///< metres, ≥ 0; 0 = 2·edge_length
    bool snap = false;                    ///< put vertices and edges onto the creases
    void validate() const;                ///< throws std::invalid_argument naming the field
};

/// Options of mesh_implicit_shape().
struct ImplicitMeshOptions {
    double edge_length = 0.0;       ///< requested mean edge length (metres, > 0)
    int remesh_iterations = 8;      ///< isotropic remeshing iterations after marching tetrahedra
    int projection_iterations = 8;  ///< Newton steps onto φ = 0 per projected point
    CreaseRefinementOptions crease;
    /// A periodic mesh (issue 39): along each axis that wraps, the lattice covers one period
    /// and its last cells join its first, so the mesh closes across the box's faces (a column
    /// running through the box becomes a closed tube). The shape must be periodic along those
    /// axes (checked on the lattice). No crease refinement or snapping with periods.
    MeshPeriods periods;
    /// Checked per grid slab and remeshing pass: throws meniscus::Cancelled once requested.
    CancellationToken cancel;
    void validate() const;          ///< throws std::invalid_argument naming the field
};

/// Quality of the produced mesh, for reports and checks.
struct ImplicitMeshReport {
    int vertices = 0;
    int triangles = 0;
    double mean_edge_length = 0.0;
    double min_angle_degrees = 0.0;
    double max_angle_degrees = 0.0;
    double max_abs_phi = 0.0;  ///< largest |φ| over vertices (how far off the surface)
    /// Mean edge length before crease refinement: the nominal ξ of a locally refined mesh
    /// (TrackerOptions::characteristic_length).
    double unrefined_mean_edge_length = 0.0;
    int crease_vertices = 0;  ///< crease vertices found before crease refinement
    int crease_splits = 0;    ///< edges split by crease refinement
    int crease_snaps = 0;     ///< vertex moves onto creases (CreaseRefinementOptions::snap)
    int crease_flips = 0;     ///< edges flipped to run along creases
    int snapped_vertices = 0; ///< vertices on a crease or corner after snapping

    /// The ξ to give a tracker of this mesh (TrackerOptions::characteristic_length): the
    /// unrefined mean edge length when crease refinement split edges, else 0 (the tracker then
    /// takes the mesh's own mean edge length, which is the same).
    double nominal_characteristic_length() const {
        return crease_splits > 0 ? unrefined_mean_edge_length : 0.0;
    }
};

/// Meshes `shape`. Throws std::invalid_argument on bad options or an unbounded shape (a
/// half-space not intersected with a box), std::runtime_error if the shape produces no surface
/// at this resolution (e.g. smaller than the edge length).
SurfaceMesh mesh_implicit_shape(const ImplicitShape& shape, const ImplicitMeshOptions& options,
                                ImplicitMeshReport* report = nullptr);

/// Moves x onto φ = 0 by Newton steps along the gradient (at most `iterations`).
Vec3 project_to_zero_set(const ImplicitShape& shape, const Vec3& x, int iterations);

}  // namespace meniscus::tracker
