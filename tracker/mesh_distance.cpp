#include "tracker/mesh_distance.h"

#include "tracker/distance.h"

#include <algorithm>
#include <limits>
#include <stdexcept>

namespace meniscus::tracker {

MeshDistance::MeshDistance(const SurfaceMesh& mesh) {
    double edge_sum = 0.0;
    for (int ti = 0; ti < mesh.num_triangles(); ++ti) {
        if (!mesh.triangle_alive(ti))
            continue;
        const Triangle& t = mesh.triangle(ti);
        // A periodic mesh's triangle at the image of its first corner (in the box).
        const std::array<Vec3, 3> c =
            mesh.periodic() ? mesh.triangle_positions(ti)
                            : std::array<Vec3, 3>{mesh.position(t[0]), mesh.position(t[1]),
                                                  mesh.position(t[2])};
        Box3d box(c[0]);
        box.extend(c[1]);
        box.extend(c[2]);
        m_corners.push_back(c);
        m_boxes.push_back(box);
        m_bounds.extend(box);
        edge_sum += (c[1] - c[0]).norm() + (c[2] - c[1]).norm() + (c[0] - c[2]).norm();
    }
    if (m_corners.empty())
        throw std::invalid_argument("MeshDistance: the mesh has no live triangle");
    // Start with a box about one edge wide: most queries near the surface end there.
    m_initial_half_width = std::max(edge_sum / (3.0 * static_cast<double>(m_corners.size())),
                                    1e-12 * m_bounds.diagonal().norm());
    if (!(m_initial_half_width > 0.0))
        m_initial_half_width = 1.0;  // every triangle is one point
    m_grid = std::make_unique<LooseGrid>(m_boxes);
    m_periods = mesh.periods();
}

double MeshDistance::distance(const Vec3& p) const {
    if (!m_periods.any())
        return distance_to_stored(p, std::numeric_limits<double>::infinity());
    // Each triangle is stored at the image whose first corner lies in the box, and p is taken
    // into the box: along a wrapping axis they are less than a period (plus an edge) apart, so
    // the nearest image of any triangle is one of the stored triangles seen from p shifted by
    // −1, 0 or +1 period along each wrapping axis.
    const Vec3 q = m_periods.wrap(p);
    double best = distance_to_stored(q, std::numeric_limits<double>::infinity());
    std::array<int, 3> k{};
    for (k[0] = -1; k[0] <= 1; ++k[0])
        for (k[1] = -1; k[1] <= 1; ++k[1])
            for (k[2] = -1; k[2] <= 1; ++k[2]) {
                Vec3 shift = Vec3::Zero();
                bool moved = false, skip = false;
                for (int a = 0; a < 3; ++a) {
                    skip = skip || (k[static_cast<size_t>(a)] != 0 && !m_periods.wraps(a));
                    moved = moved || k[static_cast<size_t>(a)] != 0;
                    shift[a] = k[static_cast<size_t>(a)] * m_periods.length[a];
                }
                if (skip || !moved)
                    continue;
                const Vec3 image = q + shift;
                // The distance to the triangles' bounding box bounds this image's from below.
                if (m_bounds.exteriorDistance(image) < best)
                    best = distance_to_stored(image, best);
            }
    return best;
}

double MeshDistance::distance_to_stored(const Vec3& p, double best) const {
    std::vector<int> ids;
    double half_width = m_initial_half_width;
    for (;;) {
        const Box3d query(p - Vec3::Constant(half_width), p + Vec3::Constant(half_width));
        m_grid->query(query, ids);
        for (int id : ids) {
            const auto& c = m_corners[static_cast<size_t>(id)];
            best = std::min(best, point_triangle_proximity(p, c[0], c[1], c[2]).distance);
        }
        // A triangle closer than `best` ≤ half_width has a point inside the query box, so its
        // box overlaps it and it was tested. A box that holds every triangle tested them all.
        if (best <= half_width || query.contains(m_bounds))
            return best;
        half_width *= 2.0;
    }
}

}  // namespace meniscus::tracker
