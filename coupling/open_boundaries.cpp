#include "coupling/open_boundaries.h"

#include "tracker/mesh_measures.h"
#include "tracker/topology/clip.h"

#include <cmath>
#include <limits>
#include <stdexcept>

namespace meniscus::coupling {

namespace {

/// The box's corners.
struct Box {
    Eigen::Vector3d lo;
    Eigen::Vector3d hi;
    explicit Box(const fluid::MacGrid& grid)
        : lo(grid.origin()),
          hi(grid.origin() + grid.dx() * Eigen::Vector3d(grid.nx(), grid.ny(), grid.nz())) {}
    /// Is x beyond face (axis, side), outside the box across it?
    bool beyond(const Eigen::Vector3d& x, int axis, int side) const {
        return side == 0 ? x[axis] < lo[axis] : x[axis] > hi[axis];
    }
};

/// The region the signed volume `volume` of a component with `labels` encloses: the one
/// behind its triangles when they face outwards (volume ≥ 0), else the one in front.
int enclosed_region(const tracker::LabelPair& labels, double volume) {
    return volume >= 0.0 ? labels.inside : labels.outside;
}

/// Adds `amount` (m³, ≥ 0) of liquid or gas to the in or out volumes.
void count(BoundaryVolumes& v, bool in, bool liquid, double amount) {
    (in ? (liquid ? v.liquid_in : v.gas_in) : (liquid ? v.liquid_out : v.gas_out)) += amount;
}

/// The centre of the inflow region of face (axis, side) in the face's plane.
Eigen::Vector3d inflow_centre(const fluid::FaceBoundary& face, const Box& box, int axis, int side) {
    Eigen::Vector3d centre = face.inflow.region == fluid::InflowRegion::disc
                                 ? face.inflow.centre
                                 : Eigen::Vector3d(0.5 * (box.lo + box.hi));
    centre[axis] = side == 0 ? box.lo[axis] : box.hi[axis];
    return centre;
}

}  // namespace

void OpenBoundaryOptions::validate() const {
    if (!(clip_near_cells >= 0.0) || !std::isfinite(clip_near_cells))
        throw std::invalid_argument("clip_near_cells: expected a number >= 0");
    if (!(clip_far_cells > clip_near_cells) || !std::isfinite(clip_far_cells))
        throw std::invalid_argument("clip_far_cells: expected a number > clip_near_cells");
}

std::vector<std::uint8_t> held_vertices(const tracker::SurfaceMesh& mesh,
                                        const fluid::MacGrid& grid,
                                        const fluid::BoundaryOptions& boundaries) {
    std::vector<std::uint8_t> held(static_cast<size_t>(mesh.num_vertices()), 0);
    const Box box(grid);
    for (int axis = 0; axis < 3; ++axis)
        for (int side = 0; side < 2; ++side) {
            if (boundaries.at(axis, side) != fluid::BoundaryType::inflow)
                continue;
            for (int vi = 0; vi < mesh.num_vertices(); ++vi)
                if (mesh.vertex_alive(vi) && box.beyond(mesh.position(vi), axis, side))
                    held[static_cast<size_t>(vi)] = 1;
        }
    return held;
}

std::vector<InflowAttachment> inflow_attachments(const tracker::SurfaceMesh& mesh,
                                                 const fluid::MacGrid& grid,
                                                 const fluid::BoundaryOptions& boundaries) {
    std::vector<InflowAttachment> attached;
    const Box box(grid);
    tracker::Components components;
    std::vector<double> volumes;
    for (int axis = 0; axis < 3; ++axis)
        for (int side = 0; side < 2; ++side) {
            const fluid::FaceBoundary& face = boundaries.face(axis, side);
            if (face.type != fluid::BoundaryType::inflow)
                continue;
            InflowAttachment a;
            a.axis = axis;
            a.side = side;
            // The vertex behind the face nearest the inflow region's centre names the component.
            const Eigen::Vector3d centre = inflow_centre(face, box, axis, side);
            double best = std::numeric_limits<double>::infinity();
            for (int vi = 0; vi < mesh.num_vertices(); ++vi) {
                if (!mesh.vertex_alive(vi) || mesh.vertex_triangles(vi).empty() ||
                    !box.beyond(mesh.position(vi), axis, side))
                    continue;
                Eigen::Vector3d offset = mesh.position(vi) - centre;
                offset[axis] = 0.0;
                if (offset.squaredNorm() < best) {
                    best = offset.squaredNorm();
                    a.vertex = vi;
                }
            }
            if (a.vertex != tracker::INVALID_INDEX) {
                if (components.count == 0) {
                    components = tracker::triangle_components(mesh);
                    volumes = tracker::component_volumes(mesh, components);
                }
                const int ti = mesh.vertex_triangles(a.vertex).front();
                const int comp = components.triangle_component[static_cast<size_t>(ti)];
                a.labels = mesh.labels(ti);
                a.volume = volumes[static_cast<size_t>(comp)];
                const double inward = side == 0 ? 1.0 : -1.0;
                for (int tj = 0; tj < mesh.num_triangles(); ++tj)
                    if (mesh.triangle_alive(tj) &&
                        components.triangle_component[static_cast<size_t>(tj)] == comp)
                        for (int v : mesh.triangle(tj))
                            a.reach =
                                std::max(a.reach, inward * (mesh.position(v)[axis] - centre[axis]));
            }
            attached.push_back(a);
        }
    return attached;
}

OpenBoundaryReport apply_open_boundaries(tracker::SurfaceMesh& mesh, const fluid::MacGrid& grid,
                                         const fluid::BoundaryOptions& boundaries, double time,
                                         double dt, int liquid_region,
                                         const OpenBoundaryOptions& options,
                                         VolumeTracker* volumes) {
    options.validate();
    if (!(dt > 0.0) || !std::isfinite(dt))
        throw std::invalid_argument("apply_open_boundaries: dt must be a finite number > 0");
    OpenBoundaryReport report;
    const Box box(grid);
    const double dx = grid.dx();

    // Inflow: the volume of the step goes to the component behind the face.
    const std::vector<InflowAttachment> attached = boundaries.inflow()
                                                       ? inflow_attachments(mesh, grid, boundaries)
                                                       : std::vector<InflowAttachment>{};
    for (const InflowAttachment& a : attached) {
        const fluid::FaceBoundary& face = boundaries.face(a.axis, a.side);
        if (face.inflow.speed == 0.0)
            continue;
        // The step's velocities are those of its end: its inflow rate too.
        const double entered =
            fluid::inflow_volume_rate(grid, boundaries, a.axis, a.side, time) * dt;
        const bool liquid = face.inflow.phase == fluid::InflowPhase::liquid;
        count(report.volumes, true, liquid, entered);
        if (!volumes)
            continue;
        const bool fed = a.vertex != tracker::INVALID_INDEX &&
                         (enclosed_region(a.labels, a.volume) == liquid_region) == liquid &&
                         volumes->add_to_target(a.vertex, a.volume >= 0.0 ? entered : -entered);
        report.unfed_inflows += fed ? 0 : 1;
    }

    // Outflow: clip beyond the face; the removed volume leaves its component's target.
    for (int axis = 0; axis < 3; ++axis)
        for (int side = 0; side < 2; ++side) {
            if (boundaries.at(axis, side) != fluid::BoundaryType::outflow)
                continue;
            const double face = side == 0 ? box.lo[axis] : box.hi[axis];
            const double outward = side == 0 ? -1.0 : 1.0;
            tracker::ClipPlane plane;
            plane.axis = axis;
            plane.side = side;
            plane.near = face + outward * options.clip_near_cells * dx;
            plane.far = face + outward * options.clip_far_cells * dx;
            plane.gone = face;  // wholly outside the box: gone, wherever the cut falls
            const tracker::ClipReport clip = tracker::clip_mesh(mesh, plane);
            if (!clip.deferred.empty()) {
                ++report.deferred_clips;
                report.deferred = clip.deferred;
            }
            if (!clip.clipped)
                continue;
            ++report.clips;
            report.components_removed += clip.components_removed;
            for (const tracker::ClippedComponent& piece : clip.components) {
                count(report.volumes, false,
                      enclosed_region(piece.labels, piece.removed_volume) == liquid_region,
                      std::abs(piece.removed_volume));
                if (volumes && piece.kept_vertex != tracker::INVALID_INDEX)
                    volumes->add_to_target(piece.kept_vertex, -piece.removed_volume);
            }
        }
    return report;
}

}  // namespace meniscus::coupling
