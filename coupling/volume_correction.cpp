#include "coupling/volume_correction.h"

#include "tracker/mesh_measures.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <set>
#include <stdexcept>

namespace meniscus::coupling {

using tracker::INVALID_INDEX;
using tracker::Vec3;

namespace {

/// Component of each vertex (first triangle's component; −1 for vertices without triangles).
std::vector<int> vertex_components(const tracker::SurfaceMesh& mesh, const tracker::Components& c) {
    std::vector<int> out(static_cast<size_t>(mesh.num_vertices()), -1);
    for (int vi = 0; vi < mesh.num_vertices(); ++vi) {
        if (!mesh.vertex_alive(vi) || mesh.vertex_triangles(vi).empty())
            continue;
        out[static_cast<size_t>(vi)] =
            c.triangle_component[static_cast<size_t>(mesh.vertex_triangles(vi).front())];
    }
    return out;
}

}  // namespace

VolumeTracker::VolumeTracker(tracker::SurfaceMesh& mesh) : m_mesh(mesh) {
    const tracker::Components c = tracker::triangle_components(mesh);
    m_targets = tracker::component_volumes(mesh, c);
    m_triangle_component = c.triangle_component;
    m_mesh.add_observer(this);
}

VolumeTracker::~VolumeTracker() {
    m_mesh.remove_observer(this);
}

void VolumeTracker::begin_step() {
    const tracker::Components c = tracker::triangle_components(m_mesh);
    m_vertex_component = vertex_components(m_mesh, c);
    m_old_targets = m_targets;
    if (static_cast<int>(m_old_targets.size()) != c.count) {
        // The mesh changed outside a step (should not happen): start over from its volumes.
        m_old_targets = tracker::component_volumes(m_mesh, c);
    }
}

void VolumeTracker::on_compact(const std::vector<int>& old_to_new_vertex) {
    if (m_vertex_component.empty())
        return;
    std::vector<int> moved(static_cast<size_t>(m_mesh.num_vertices()), -1);
    for (size_t old = 0; old < old_to_new_vertex.size() && old < m_vertex_component.size(); ++old) {
        const int nv = old_to_new_vertex[old];
        if (nv >= 0 && static_cast<size_t>(nv) < moved.size())
            moved[static_cast<size_t>(nv)] = m_vertex_component[old];
    }
    m_vertex_component = std::move(moved);
}

VolumeReport VolumeTracker::match_components() {
    const tracker::Components c = tracker::triangle_components(m_mesh);
    m_triangle_component = c.triangle_component;
    VolumeReport report;
    report.volumes = tracker::component_volumes(m_mesh, c);
    const std::vector<int> now = vertex_components(m_mesh, c);
    // Old components feeding each new one, and new ones fed by each old one.
    std::vector<std::set<int>> sources(static_cast<size_t>(c.count));
    std::map<int, std::set<int>> fed;
    for (size_t vi = 0; vi < now.size() && vi < m_vertex_component.size(); ++vi) {
        const int old_c = m_vertex_component[vi], new_c = now[vi];
        if (old_c < 0 || new_c < 0 || static_cast<size_t>(old_c) >= m_old_targets.size())
            continue;
        sources[static_cast<size_t>(new_c)].insert(old_c);
        fed[old_c].insert(new_c);
    }
    report.targets.assign(static_cast<size_t>(c.count), 0.0);
    for (int nc = 0; nc < c.count; ++nc) {
        const auto& src = sources[static_cast<size_t>(nc)];
        if (src.empty()) {
            report.targets[static_cast<size_t>(nc)] = report.volumes[static_cast<size_t>(nc)];
            continue;
        }
        if (src.size() > 1)
            ++report.merges;
        for (int oc : src) {
            // Share old component oc's target among the new components it feeds, by volume.
            const auto& outs = fed[oc];
            double total = 0.0;
            for (int o : outs)
                total += std::abs(report.volumes[static_cast<size_t>(o)]);
            const double share = total > 0.0
                                     ? std::abs(report.volumes[static_cast<size_t>(nc)]) / total
                                     : 1.0 / static_cast<double>(outs.size());
            report.targets[static_cast<size_t>(nc)] +=
                share * m_old_targets[static_cast<size_t>(oc)];
        }
    }
    for (const auto& [oc, outs] : fed)
        if (outs.size() > 1)
            ++report.splits;
    for (int nc = 0; nc < c.count; ++nc) {
        const double target = report.targets[static_cast<size_t>(nc)];
        if (target != 0.0)
            report.max_relative_error = std::max(
                report.max_relative_error,
                std::abs(report.volumes[static_cast<size_t>(nc)] - target) / std::abs(target));
    }
    m_targets = report.targets;
    m_vertex_component.clear();
    return report;
}

bool VolumeTracker::add_to_target(int vi, double delta) {
    const auto known = [&](int v) {
        return static_cast<size_t>(v) < m_vertex_component.size() &&
               m_vertex_component[static_cast<size_t>(v)] >= 0 &&
               static_cast<size_t>(m_vertex_component[static_cast<size_t>(v)]) <
                   m_old_targets.size();
    };
    if (vi < 0 || vi >= m_mesh.num_vertices() || !m_mesh.vertex_alive(vi))
        return false;
    // Breadth first over edges to the nearest vertex that existed at begin_step().
    std::vector<int> queue = {vi};
    std::set<int> seen = {vi};
    for (size_t head = 0; head < queue.size(); ++head) {
        const int v = queue[head];
        if (known(v)) {
            m_old_targets[static_cast<size_t>(m_vertex_component[static_cast<size_t>(v)])] += delta;
            return true;
        }
        for (int ei : m_mesh.vertex_edges(v)) {
            const int w = m_mesh.other_vertex(ei, v);
            if (seen.insert(w).second)
                queue.push_back(w);
        }
    }
    return false;
}

double VolumeTracker::add_correction(std::vector<Vec3>& velocities, double dt,
                                     const std::vector<std::uint8_t>* held) const {
    if (!(dt > 0.0))
        throw std::invalid_argument("add_correction: dt must be > 0");
    if (velocities.size() != static_cast<size_t>(m_mesh.num_vertices()))
        throw std::invalid_argument("add_correction: velocities must be sized num_vertices()");
    if (held && held->size() != velocities.size())
        throw std::invalid_argument("add_correction: held must be sized num_vertices()");
    const auto is_held = [&](size_t v) { return held && (*held)[v]; };
    const size_t nc = m_targets.size();
    std::vector<double> volume(nc, 0.0), area(nc, 0.0);
    std::vector<Vec3> normal(static_cast<size_t>(m_mesh.num_vertices()), Vec3::Zero());
    tracker::Components c;
    c.count = static_cast<int>(nc);
    c.triangle_component = m_triangle_component;
    if (c.triangle_component.size() != static_cast<size_t>(m_mesh.num_triangles()))
        throw std::logic_error("add_correction: call match_components() after the mesh changes");
    volume = tracker::component_volumes(m_mesh, c);
    for (int ti = 0; ti < m_mesh.num_triangles(); ++ti) {
        if (!m_mesh.triangle_alive(ti))
            continue;
        const tracker::Triangle& t = m_mesh.triangle(ti);
        const std::array<Vec3, 3> x = m_mesh.triangle_positions(ti);  // minimum image
        const Vec3 n2 = (x[1] - x[0]).cross(x[2] - x[0]);
        area[static_cast<size_t>(c.triangle_component[static_cast<size_t>(ti)])] += 0.5 * n2.norm();
        for (int v : t)
            normal[static_cast<size_t>(v)] += n2;  // area-weighted
    }
    // Per component: the first-order volume rate of the given velocities, Σ_v u_v·∇V_v with
    // ∇V_v = Σ (area vectors of v's triangles)/3 = normal_v/6, and the rate per unit normal
    // speed, Σ_v |∇V_v|.
    std::vector<int> vertex_component(static_cast<size_t>(m_mesh.num_vertices()), -1);
    std::vector<double> rate(nc, 0.0), rate_per_speed(nc, 0.0);
    for (int vi = 0; vi < m_mesh.num_vertices(); ++vi) {
        if (!m_mesh.vertex_alive(vi) || m_mesh.vertex_triangles(vi).empty())
            continue;
        const size_t v = static_cast<size_t>(vi);
        const int comp =
            c.triangle_component[static_cast<size_t>(m_mesh.vertex_triangles(vi).front())];
        vertex_component[v] = comp;
        if (is_held(v))
            continue;  // does not move: adds no rate, takes no correction
        rate[static_cast<size_t>(comp)] += velocities[v].dot(normal[v]) / 6.0;
        rate_per_speed[static_cast<size_t>(comp)] += normal[v].norm() / 6.0;
    }
    double largest = 0.0;
    for (int vi = 0; vi < m_mesh.num_vertices(); ++vi) {
        const size_t v = static_cast<size_t>(vi);
        const int comp = vertex_component[v];
        if (comp < 0 || is_held(v))
            continue;
        const size_t ci = static_cast<size_t>(comp);
        const double n = normal[v].norm();
        if (!(area[ci] > 0.0) || !(n > 0.0) || !(rate_per_speed[ci] > 0.0))
            continue;
        // Normal speed that makes the component's volume reach its target at the end of the
        // step to first order: it removes the rate the motion would add (interpolation error;
        // parts of a surface outside the domain, which move with the clamped wall velocity)
        // and closes the remaining gap V* − V.
        const double speed = ((m_targets[ci] - volume[ci]) / dt - rate[ci]) / rate_per_speed[ci];
        velocities[v] += speed * normal[v] / n;
        largest = std::max(largest, std::abs(speed) * dt);
    }
    return largest;
}

void VolumeTracker::save_state(BinaryWriter& out) const {
    out.put_vector(m_vertex_component);
    out.put_vector(m_old_targets);
    out.put_vector(m_targets);
    out.put_vector(m_triangle_component);
}

void VolumeTracker::load_state(BinaryReader& in) {
    std::vector<int> vertex_component = in.get_vector<int>();
    std::vector<double> old_targets = in.get_vector<double>();
    std::vector<double> targets = in.get_vector<double>();
    std::vector<int> triangle_component = in.get_vector<int>();
    const auto in_range = [](const std::vector<int>& components, size_t count) {
        return std::all_of(components.begin(), components.end(), [&](int c) {
            return c >= -1 && c < static_cast<int>(count);
        });
    };
    if (!in_range(vertex_component, std::max(old_targets.size(), targets.size())) ||
        !in_range(triangle_component, std::max(old_targets.size(), targets.size())))
        throw FormatError("volume state: a component index is out of range");
    m_vertex_component = std::move(vertex_component);
    m_old_targets = std::move(old_targets);
    m_targets = std::move(targets);
    m_triangle_component = std::move(triangle_component);
}

}  // namespace meniscus::coupling
