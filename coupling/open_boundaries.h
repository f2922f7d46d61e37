#pragma once
/// \file The interface mesh at the open faces of the fluid box (fluid/boundary.h).
///
/// Inflow: the mesh behind an inflow face (outside the box across it) belongs to the nozzle — a
/// liquid jet's surface continued into its pipe, or a gas bubble's into its orifice — and stays
/// where it is (held_vertices(): the tracker's pinned vertices, no volume correction). The
/// surface inside the box moves with the fluid, so it stretches away from the held part and
/// grows from the rim of the inflow region (the remeshing splits what stretches). The volume
/// flowing in (the discrete flux of the inflow's face velocities over the step) is added to the
/// target of the component that reaches behind the face, when that component encloses the
/// inflow's phase.
///
/// Outflow: the mesh beyond an outflow face is clipped (tracker/topology/clip.h) between
/// OpenBoundaryOptions::clip_near_cells and clip_far_cells cells beyond the face, so the surface
/// still runs on a little past the face: the cells next to it see a smooth surface, not the
/// cap's crease, in φ and in the curvature; a component wholly beyond the face goes whole. What
/// is removed is reported by phase and taken off the target of its component (a component that
/// leaves whole takes its target with it).

#include "coupling/volume_correction.h"
#include "fluid/boundary.h"
#include "fluid/mac_grid.h"
#include "tracker/mesh.h"

#include <cstdint>
#include <string>
#include <vector>

namespace meniscus::coupling {

/// Where the mesh is cut beyond an outflow face. Defaults here and nowhere else.
struct OpenBoundaryOptions {
    /// The cut lies between these many cells beyond an outflow face (near < far), at the place
    /// in that range farthest from the vertices (ClipPlane). The curvature smoothing reaches
    /// about two cells along the surface: the cap's crease must stay out of the box's cells.
    double clip_near_cells = 2.0;
    double clip_far_cells = 3.0;
    void validate() const;  ///< throws std::invalid_argument naming the field
};

/// Volumes (m³) that entered through inflow faces and were clipped off at outflow faces.
struct BoundaryVolumes {
    double liquid_in = 0.0;
    double gas_in = 0.0;
    double liquid_out = 0.0;
    double gas_out = 0.0;
    BoundaryVolumes& operator+=(const BoundaryVolumes& other) {
        liquid_in += other.liquid_in;
        gas_in += other.gas_in;
        liquid_out += other.liquid_out;
        gas_out += other.gas_out;
        return *this;
    }
};

/// What apply_open_boundaries() did in one step.
struct OpenBoundaryReport {
    BoundaryVolumes volumes;
    int clips = 0;               ///< outflow faces where the mesh was cut
    int components_removed = 0;  ///< components that left whole
    /// Outflow faces whose cut had to wait for a later step (tracker::ClipReport::deferred), and
    /// the last reason.
    int deferred_clips = 0;
    std::string deferred;
    /// Inflows with speed whose volume went to no component's target: no component reaches
    /// behind the face, or the one that does encloses the other phase (volume correction on).
    int unfed_inflows = 0;
};

/// The part of the mesh an inflow face feeds: the component reaching behind the face nearest the
/// centre of the inflow region (the jet, or the bubble growing at its orifice).
struct InflowAttachment {
    int axis = 0;
    int side = 0;
    int vertex = tracker::INVALID_INDEX;  ///< one of its vertices behind the face; none: INVALID
    /// Farthest distance (m) of its vertices from the face into the box: the length of a jet
    /// still attached to its nozzle (0 when none).
    double reach = 0.0;
    tracker::LabelPair labels;  ///< of its triangles
    double volume = 0.0;        ///< its signed enclosed volume (m³)
};

/// One entry per inflow face of `boundaries`, in axis and side order.
std::vector<InflowAttachment> inflow_attachments(const tracker::SurfaceMesh& mesh,
                                                 const fluid::MacGrid& grid,
                                                 const fluid::BoundaryOptions& boundaries);

/// 1 for every live vertex beyond an inflow face of the box (the nozzle's part of the mesh,
/// which the fluid does not move), 0 elsewhere; sized mesh.num_vertices().
std::vector<std::uint8_t> held_vertices(const tracker::SurfaceMesh& mesh,
                                        const fluid::MacGrid& grid,
                                        const fluid::BoundaryOptions& boundaries);

/// One step's mesh changes and volume bookkeeping at the open faces (see the file comment):
/// clips the mesh beyond every outflow face and adds each inflow's volume over the step of `dt`
/// (s, > 0) that ended at `time` (s; the fluid's, for a pulsed inflow).
/// `liquid_region` is the label of the liquid (RasterizeOptions::liquid_region). With
/// `volumes` (between its begin_step() and match_components()) the targets follow. Throws
/// std::invalid_argument on invalid options or dt.
OpenBoundaryReport apply_open_boundaries(tracker::SurfaceMesh& mesh, const fluid::MacGrid& grid,
                                         const fluid::BoundaryOptions& boundaries, double time,
                                         double dt, int liquid_region,
                                         const OpenBoundaryOptions& options,
                                         VolumeTracker* volumes);

}  // namespace meniscus::coupling
