#include "coupling/periodic_images.h"

#include <array>
#include <cmath>
#include <cstdint>
#include <stdexcept>
#include <unordered_map>

namespace meniscus::coupling {

using tracker::Vec3;

UnrolledMesh unroll_periodic_mesh(const tracker::SurfaceMesh& mesh, double margin) {
    if (!(margin >= 0.0) || !std::isfinite(margin))
        throw std::invalid_argument("unroll_periodic_mesh: margin must be a finite number >= 0");
    const tracker::MeshPeriods& periods = mesh.periods();
    // Images k·L for k in [−reach, reach] along each wrapping axis cover the box and the margin
    // (an element is far shorter than a period).
    std::array<int, 3> reach{0, 0, 0};
    for (int a = 0; a < 3; ++a)
        if (periods.wraps(a))
            reach[a] = 1 + static_cast<int>(std::ceil(margin / periods.length[a]));
    // A vertex image is (source vertex, whole periods from its stored position): keyed densely.
    const int span = 2 * (reach[0] + reach[1] + reach[2]) + 3;  // offsets in [−(r+1), r+1]
    const auto key = [&](int v, const std::array<int, 3>& k) {
        const int half = span / 2;
        return (static_cast<std::int64_t>(v) * span + (k[0] + half)) * span * span +
               (k[1] + half) * span + (k[2] + half);
    };
    std::unordered_map<std::int64_t, int> image_index;
    UnrolledMesh out;
    std::vector<Vec3> positions;
    std::vector<tracker::Triangle> triangles;
    std::vector<tracker::LabelPair> labels;
    const Vec3 lo = periods.origin, hi = periods.origin + periods.length;
    for (int ti = 0; ti < mesh.num_triangles(); ++ti) {
        if (!mesh.triangle_alive(ti))
            continue;
        const tracker::Triangle& t = mesh.triangle(ti);
        const std::array<Vec3, 3> c = mesh.triangle_positions(ti);
        // Whole periods of each corner's minimum image from its stored position.
        std::array<std::array<int, 3>, 3> offset{};
        for (int q = 0; q < 3; ++q)
            for (int a = 0; a < 3; ++a)
                offset[q][a] = periods.wraps(a)
                                   ? static_cast<int>(std::lround(
                                         (c[q][a] - mesh.position(t[q])[a]) / periods.length[a]))
                                   : 0;
        Vec3 box_lo = c[0].cwiseMin(c[1]).cwiseMin(c[2]);
        Vec3 box_hi = c[0].cwiseMax(c[1]).cwiseMax(c[2]);
        std::array<int, 3> k{};
        for (k[2] = -reach[2]; k[2] <= reach[2]; ++k[2])
            for (k[1] = -reach[1]; k[1] <= reach[1]; ++k[1])
                for (k[0] = -reach[0]; k[0] <= reach[0]; ++k[0]) {
                    bool inside = true;
                    for (int a = 0; a < 3 && inside; ++a)
                        if (periods.wraps(a)) {
                            const double s = k[a] * periods.length[a];
                            inside =
                                box_hi[a] + s >= lo[a] - margin && box_lo[a] + s <= hi[a] + margin;
                        }
                    if (!inside)
                        continue;
                    tracker::Triangle image{};
                    for (int q = 0; q < 3; ++q) {
                        std::array<int, 3> total{};
                        for (int a = 0; a < 3; ++a)
                            total[a] = offset[q][a] + k[a];
                        const auto [it, added] = image_index.emplace(
                            key(t[q], total), static_cast<int>(positions.size()));
                        if (added) {
                            Vec3 p = mesh.position(t[q]);
                            for (int a = 0; a < 3; ++a)
                                p[a] += total[a] * periods.length[a];
                            positions.push_back(p);
                            out.source_vertex.push_back(t[q]);
                        }
                        image[q] = it->second;
                    }
                    triangles.push_back(image);
                    labels.push_back(mesh.labels(ti));
                    out.source_triangle.push_back(ti);
                }
    }
    out.mesh = tracker::SurfaceMesh(std::move(positions), triangles, labels);
    return out;
}

namespace {

/// One pass of cut_at_box(): keeps the side where `inside(p)` ≥ 0 (an affine function).
struct PlaneCut {
    int axis;
    double plane;
    double sign;  // +1 keeps x_axis ≥ plane, −1 keeps x_axis ≤ plane
    double inside(const Vec3& p) const { return sign * (p[axis] - plane); }
};

void cut_once(std::vector<Vec3>& positions, std::vector<tracker::Triangle>& triangles,
              std::vector<tracker::LabelPair>& labels, std::vector<Vec3>* values,
              const PlaneCut& cut) {
    std::vector<double> d(positions.size());
    for (size_t v = 0; v < positions.size(); ++v)
        d[v] = cut.inside(positions[v]);
    std::unordered_map<std::int64_t, int> crossing;  // edge (lo, hi) → its new vertex
    const auto split = [&](int a, int b) {
        const int lo = std::min(a, b), hi = std::max(a, b);
        const std::int64_t key =
            static_cast<std::int64_t>(lo) << 32 | static_cast<std::uint32_t>(hi);
        const auto [it, added] = crossing.emplace(key, static_cast<int>(positions.size()));
        if (added) {
            // From the lower index, so both triangles on the edge get the same point.
            const double t = d[static_cast<size_t>(lo)] /
                             (d[static_cast<size_t>(lo)] - d[static_cast<size_t>(hi)]);
            positions.push_back(
                positions[static_cast<size_t>(lo)] +
                t * (positions[static_cast<size_t>(hi)] - positions[static_cast<size_t>(lo)]));
            positions.back()[cut.axis] = cut.plane;  // exactly on the face
            if (values)
                values->push_back(
                    (*values)[static_cast<size_t>(lo)] +
                    t * ((*values)[static_cast<size_t>(hi)] - (*values)[static_cast<size_t>(lo)]));
        }
        return it->second;
    };
    std::vector<tracker::Triangle> kept;
    std::vector<tracker::LabelPair> kept_labels;
    for (size_t ti = 0; ti < triangles.size(); ++ti) {
        const tracker::Triangle& t = triangles[ti];
        std::array<int, 4> polygon{};
        int n = 0;
        for (int k = 0; k < 3; ++k) {
            const int a = t[static_cast<size_t>(k)], b = t[static_cast<size_t>((k + 1) % 3)];
            const double da = d[static_cast<size_t>(a)], db = d[static_cast<size_t>(b)];
            if (da >= 0.0)
                polygon[static_cast<size_t>(n++)] = a;
            if ((da > 0.0 && db < 0.0) || (da < 0.0 && db > 0.0))
                polygon[static_cast<size_t>(n++)] = split(a, b);
        }
        for (int k = 1; k + 1 < n; ++k) {  // a fan keeps the orientation
            kept.push_back(
                {polygon[0], polygon[static_cast<size_t>(k)], polygon[static_cast<size_t>(k + 1)]});
            kept_labels.push_back(labels[ti]);
        }
    }
    triangles.swap(kept);
    labels.swap(kept_labels);
}

}  // namespace

tracker::SurfaceMesh cut_at_box(const tracker::SurfaceMesh& mesh,
                                const tracker::MeshPeriods& periods,
                                std::vector<tracker::Vec3>* values) {
    if (values && values->size() != static_cast<size_t>(mesh.num_vertices()))
        throw std::invalid_argument("cut_at_box: values must be sized num_vertices()");
    std::vector<Vec3> positions = mesh.positions();
    std::vector<tracker::Triangle> triangles;
    std::vector<tracker::LabelPair> labels;
    for (int ti = 0; ti < mesh.num_triangles(); ++ti)
        if (mesh.triangle_alive(ti)) {
            triangles.push_back(mesh.triangle(ti));
            labels.push_back(mesh.labels(ti));
        }
    for (int a = 0; a < 3; ++a)
        if (periods.wraps(a)) {
            cut_once(positions, triangles, labels, values, {a, periods.origin[a], 1.0});
            cut_once(positions, triangles, labels, values,
                     {a, periods.origin[a] + periods.length[a], -1.0});
        }
    // Vertices no triangle uses any more (beyond the faces) are dropped.
    std::vector<int> map(positions.size(), tracker::INVALID_INDEX);
    std::vector<Vec3> used, used_values;
    for (tracker::Triangle& t : triangles)
        for (int& v : t) {
            int& m = map[static_cast<size_t>(v)];
            if (m == tracker::INVALID_INDEX) {
                m = static_cast<int>(used.size());
                used.push_back(positions[static_cast<size_t>(v)]);
                if (values)
                    used_values.push_back((*values)[static_cast<size_t>(v)]);
            }
            v = m;
        }
    if (values)
        values->swap(used_values);
    return tracker::SurfaceMesh(std::move(used), triangles, labels);
}

}  // namespace meniscus::coupling
