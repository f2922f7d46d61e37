#include "tracker/broadphase.h"

#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace meniscus::tracker {

namespace {

/// Boxes covering more cells than this are kept in a list checked on every query instead (as
/// SpatialHash does).
constexpr long long MAX_CELLS_PER_BOX = SpatialHash::MAX_CELLS_PER_BOX;
/// Grain of parallel pair enumeration (elements, or grid cells for self joins).
constexpr size_t PARALLEL_GRAIN = 256;
constexpr size_t SELF_JOIN_GRAIN = 64;

template <typename Pair, typename Emit>
std::vector<Pair> collect_parallel(size_t count, Emit&& emit) {
    tbb::enumerable_thread_specific<std::vector<Pair>> local;
    tbb::parallel_for(tbb::blocked_range<size_t>(0, count, PARALLEL_GRAIN),
                      [&](const tbb::blocked_range<size_t>& r) {
                          auto& out = local.local();
                          std::vector<int> scratch;
                          for (size_t i = r.begin(); i < r.end(); ++i)
                              emit(static_cast<int>(i), scratch, out);
                      });
    std::vector<Pair> all;
    for (auto& part : local)
        all.insert(all.end(), part.begin(), part.end());
    std::sort(all.begin(), all.end());
    return all;
}

bool shares_vertex(const Edge& a, const Edge& b) {
    return a[0] == b[0] || a[0] == b[1] || a[1] == b[0] || a[1] == b[1];
}

void check_sizes(const SurfaceMesh& mesh, const std::vector<Vec3>& x_t0,
                 const std::vector<Vec3>& x_t1, double padding) {
    const size_t n = static_cast<size_t>(mesh.num_vertices());
    if (x_t0.size() != n || x_t1.size() != n)
        throw std::invalid_argument("broad phase: " + std::to_string(x_t0.size()) + " and " +
                                    std::to_string(x_t1.size()) + " positions for " +
                                    std::to_string(n) + " vertices");
    if (!(padding >= 0.0))
        throw std::invalid_argument("broad phase: padding must be >= 0");
}

Box3d vertex_box(const std::vector<Vec3>& x_t0, const std::vector<Vec3>& x_t1, int vi,
                 double padding) {
    return swept_box({&x_t0[static_cast<size_t>(vi)]}, {&x_t1[static_cast<size_t>(vi)]}, padding);
}

Box3d edge_box(const std::vector<Vec3>& x_t0, const std::vector<Vec3>& x_t1, const Edge& e,
               double padding) {
    const auto a = static_cast<size_t>(e[0]), b = static_cast<size_t>(e[1]);
    return swept_box({&x_t0[a], &x_t0[b]}, {&x_t1[a], &x_t1[b]}, padding);
}

Box3d triangle_box(const std::vector<Vec3>& x_t0, const std::vector<Vec3>& x_t1, const Triangle& t,
                   double padding) {
    const auto a = static_cast<size_t>(t[0]), b = static_cast<size_t>(t[1]),
               c = static_cast<size_t>(t[2]);
    return swept_box({&x_t0[a], &x_t0[b], &x_t0[c]}, {&x_t1[a], &x_t1[b], &x_t1[c]}, padding);
}

// ---- periodic meshes (issue 39) -----------------------------------------------------------

/// Extra padding of a periodic mesh's boxes, in units of the largest coordinate of the box the
/// mesh wraps around: the pairs' shifts and the images' shifts are sums of whole periods and
/// coordinates, rounded differently; this covers that rounding (~10⁻¹⁴ of the box).
constexpr double PERIODIC_ROUNDING_PADDING = 64.0 * std::numeric_limits<double>::epsilon();

double periodic_padding(const MeshPeriods& periods, double padding) {
    const double scale = (periods.origin.cwiseAbs() + periods.length).maxCoeff();
    return padding + PERIODIC_ROUNDING_PADDING * scale;
}

/// The whole-period shift that moves p into the fundamental box (0 when it lies there already,
/// and along axes that do not wrap).
Vec3 into_box(const MeshPeriods& periods, const Vec3& p) {
    Vec3 s = Vec3::Zero();
    for (int a = 0; a < 3; ++a)
        if (periods.wraps(a)) {
            const double u = p[a] - periods.origin[a];
            if (u < 0.0 || u >= periods.length[a])
                s[a] = -periods.length[a] * std::floor(u / periods.length[a]);
        }
    return s;
}

/// Box of the element with corners `v` swept x_t0 → x_t1 on a periodic mesh: every corner at
/// its image nearest the first corner at t0 (the same shift at t0 and t1), the whole element
/// moved by whole periods so that its first corner at t0 lies in the fundamental box.
template <size_t N>
Box3d periodic_box(const MeshPeriods& periods, const std::vector<Vec3>& x_t0,
                   const std::vector<Vec3>& x_t1, const std::array<int, N>& v, double padding) {
    const Vec3& first = x_t0[static_cast<size_t>(v[0])];
    const Vec3 base = into_box(periods, first);
    Box3d b;
    for (size_t k = 0; k < N; ++k) {
        const auto i = static_cast<size_t>(v[k]);
        const Vec3 s = k == 0 ? base : Vec3(periods.shift_towards(x_t0[i], first) + base);
        b.extend(Vec3(x_t0[i] + s));
        b.extend(Vec3(x_t1[i] + s));
    }
    b.min().array() -= padding;
    b.max().array() += padding;
    return b;
}

Box3d shifted(const Box3d& b, const Vec3& s) {
    return Box3d(Vec3(b.min() + s), Vec3(b.max() + s));
}

/// The whole-period shifts of the images of `box` that can overlap another element's box
/// (excluding 0): along each wrapping axis, +length when the box lies within `reach` of the
/// low face, −length when within `reach` of the high face; every combination over the axes.
void image_shifts(const MeshPeriods& periods, const Vec3& reach, const Box3d& box,
                  std::vector<Vec3>& out) {
    out.clear();
    out.push_back(Vec3::Zero());
    for (int a = 0; a < 3; ++a) {
        if (!periods.wraps(a))
            continue;
        const double lo = periods.origin[a], hi = lo + periods.length[a];
        const bool near_low = box.min()[a] <= lo + reach[a];
        const bool near_high = box.max()[a] >= hi - reach[a];
        const size_t count = out.size();
        for (const double sign : {1.0, -1.0}) {
            if (sign > 0.0 ? !near_low : !near_high)
                continue;
            for (size_t k = 0; k < count; ++k) {
                Vec3 s = out[k];
                s[a] = sign * periods.length[a];
                out.push_back(s);
            }
        }
    }
    out.erase(out.begin());  // the element itself
}

/// Appends to `boxes` (one per element) the images image_shifts() gives, and to `image_of` the
/// element of each.
void append_images(const MeshPeriods& periods, const Vec3& reach, std::vector<Box3d>& boxes,
                   std::vector<int>& image_of) {
    const size_t n = boxes.size();
    std::vector<Vec3> shifts;
    for (size_t i = 0; i < n; ++i) {
        if (boxes[i].isEmpty())
            continue;
        image_shifts(periods, reach, boxes[i], shifts);
        for (const Vec3& s : shifts) {
            boxes.push_back(shifted(boxes[i], s));
            image_of.push_back(static_cast<int>(i));
        }
    }
}

/// reach ← per axis the larger of reach and the extents of the non-empty boxes.
void extend_reach(const std::vector<Box3d>& boxes, Vec3& reach) {
    for (const Box3d& b : boxes)
        if (!b.isEmpty())
            reach = reach.cwiseMax(b.sizes());
}

/// The 3^k whole-period shifts (k wrapping axes), the zero shift first.
std::vector<Vec3> all_shifts(const MeshPeriods& periods) {
    std::vector<Vec3> out{Vec3::Zero()};
    for (int a = 0; a < 3; ++a) {
        if (!periods.wraps(a))
            continue;
        const size_t count = out.size();
        for (const double sign : {1.0, -1.0})
            for (size_t k = 0; k < count; ++k) {
                Vec3 s = out[k];
                s[a] = sign * periods.length[a];
                out.push_back(s);
            }
    }
    return out;
}

/// Box of element `v` as BroadPhase builds it (periodic or not).
template <size_t N>
Box3d element_box(const SurfaceMesh& mesh, const std::vector<Vec3>& x_t0,
                  const std::vector<Vec3>& x_t1, const std::array<int, N>& v, double padding) {
    if (mesh.periodic())
        return periodic_box(mesh.periods(), x_t0, x_t1, v,
                            periodic_padding(mesh.periods(), padding));
    Box3d b;
    for (size_t k = 0; k < N; ++k) {
        b.extend(x_t0[static_cast<size_t>(v[k])]);
        b.extend(x_t1[static_cast<size_t>(v[k])]);
    }
    b.min().array() -= padding;
    b.max().array() += padding;
    return b;
}

/// True when `a` overlaps `b` or one of b's images (`shifts` from all_shifts()).
bool overlaps_some_image(const Box3d& a, const Box3d& b, const std::vector<Vec3>& shifts) {
    for (const Vec3& s : shifts)
        if (closed_boxes_overlap(a, shifted(b, s)))
            return true;
    return false;
}

}  // namespace

Box3d swept_box(std::initializer_list<const Vec3*> p_t0, std::initializer_list<const Vec3*> p_t1,
                double padding) {
    Box3d b;
    for (const Vec3* p : p_t0)
        b.extend(*p);
    for (const Vec3* p : p_t1)
        b.extend(*p);
    b.min().array() -= padding;
    b.max().array() += padding;
    return b;
}

// ---- LooseGrid ----------------------------------------------------------------------------

namespace {

/// Loose-grid cell size as a multiple of the mean box extent: elements up to one cell wide sit
/// in one cell; bigger ones go to the oversized list.
constexpr double LOOSE_CELL_FACTOR = 2.0;
/// Elements wider than (1 − this) cells count as oversized. The margin makes the neighbour
/// argument survive the rounding of min/cell: two overlapping elements of at most that width
/// have computed cells at most one apart on every axis (the relative rounding of a quotient is
/// 2⁻⁵³, times at most 2²¹ cells from the origin, is far below this margin).
constexpr double LOOSE_WIDTH_MARGIN = 1e-6;
/// Half of the 26 neighbour offsets: the ones lexicographically after (0, 0, 0).
constexpr int HALF_STENCIL[13][3] = {{0, 0, 1},  {0, 1, -1},  {0, 1, 0},  {0, 1, 1},  {1, -1, -1},
                                     {1, -1, 0}, {1, -1, 1},  {1, 0, -1}, {1, 0, 0},  {1, 0, 1},
                                     {1, 1, -1}, {1, 1, 0},   {1, 1, 1}};

/// Closed-box overlap on raw coordinates (the hot loop of the pair enumeration). Evaluates all
/// six comparisons without short-circuiting: most candidates fail on a random axis, and one
/// well-predicted branch on the combined result is cheaper than up to six unpredictable ones.
inline bool boxes_overlap(const Box3d& a, const Box3d& b) {
    const bool x = (a.min().x() <= b.max().x()) & (b.min().x() <= a.max().x());
    const bool y = (a.min().y() <= b.max().y()) & (b.min().y() <= a.max().y());
    const bool z = (a.min().z() <= b.max().z()) & (b.min().z() <= a.max().z());
    return x & y & z;
}

}  // namespace

std::int64_t LooseGrid::cell_key(const Eigen::Array3i& c) const {
    return SpatialHash::key(c.x(), c.y(), c.z());
}

LooseGrid::LooseGrid(const std::vector<Box3d>& boxes) : m_boxes(boxes) {
    double sum = 0.0;
    int n = 0;
    for (const Box3d& b : boxes) {
        if (b.isEmpty())
            continue;
        sum += b.sizes().maxCoeff();
        ++n;
    }
    m_cell = n > 0 && sum > 0.0 ? LOOSE_CELL_FACTOR * sum / n : 1.0;
    // Counting build in O(n): cells are numbered in order of first appearance, then ids are
    // placed cell by cell in increasing order (no sort).
    std::vector<Eigen::Array3i> coords_of(boxes.size());
    std::vector<int> cell_of(boxes.size(), -1);
    Eigen::Array3i lo_all = Eigen::Array3i::Constant(std::numeric_limits<int>::max());
    Eigen::Array3i hi_all = Eigen::Array3i::Constant(std::numeric_limits<int>::min());
    const double limit = (1 << 20) - 2;
    for (size_t i = 0; i < boxes.size(); ++i) {
        const Box3d& b = boxes[i];
        if (b.isEmpty())
            continue;
        const Eigen::Array3d lo = (b.min().array() / m_cell).floor();
        if (b.sizes().maxCoeff() > (1.0 - LOOSE_WIDTH_MARGIN) * m_cell || (lo.abs() > limit).any() ||
            !lo.allFinite()) {
            m_oversized.push_back(static_cast<int>(i));
            continue;
        }
        coords_of[i] = lo.cast<int>();
        cell_of[i] = 0;  // placed below
        lo_all = lo_all.min(coords_of[i]);
        hi_all = hi_all.max(coords_of[i]);
    }
    // A dense table when the block of occupied cells (with the one-cell rim the stencils and
    // queries look at) is at most a few times the element count: a lookup is then an index
    // computation instead of a hash probe.
    const int placed = n - static_cast<int>(m_oversized.size());
    if (placed > 0) {
        const Eigen::Array3i block = hi_all - lo_all + 3;
        if (block.cast<double>().prod() <= std::max(8.0 * placed, 4096.0)) {
            m_dense_lo = lo_all - 1;
            m_dense_size = block;
            m_dense.assign(static_cast<size_t>(block.prod()), -1);
        }
    }
    if (m_dense.empty()) {
        size_t slots = 16;
        while (slots < 2 * static_cast<size_t>(n))
            slots *= 2;
        m_slot_key.assign(slots, -1);
        m_slot_cell.assign(slots, -1);
    }
    for (size_t i = 0; i < boxes.size(); ++i) {
        if (cell_of[i] < 0)
            continue;
        const Eigen::Array3i& coords = coords_of[i];
        int* entry = nullptr;
        if (!m_dense.empty()) {
            entry = &m_dense[dense_slot(coords)];
        } else {
            const std::int64_t key = cell_key(coords);
            const size_t slot = hash_slot(key);
            m_slot_key[slot] = key;
            entry = &m_slot_cell[slot];
        }
        if (*entry == -1) {
            *entry = static_cast<int>(m_cells.size());
            m_cells.push_back({coords, 0, 0});
        }
        const int c = *entry;
        cell_of[i] = c;
        ++m_cells[static_cast<size_t>(c)].end;  // count for now
    }
    int offset = 0;
    for (Cell& cell : m_cells) {
        cell.begin = offset;
        offset += cell.end;
        cell.end = cell.begin;  // fill cursor
    }
    m_ids.resize(static_cast<size_t>(offset));
    m_cell_boxes.resize(static_cast<size_t>(offset));
    for (size_t i = 0; i < boxes.size(); ++i) {
        if (cell_of[i] < 0)
            continue;
        const auto pos = static_cast<size_t>(m_cells[static_cast<size_t>(cell_of[i])].end++);
        m_ids[pos] = static_cast<int>(i);
        m_cell_boxes[pos] = boxes[i];
    }
    m_cell_union.resize(m_cells.size());  // default: empty
    for (size_t c = 0; c < m_cells.size(); ++c)
        for (int k = m_cells[c].begin; k < m_cells[c].end; ++k)
            m_cell_union[c].extend(m_cell_boxes[static_cast<size_t>(k)]);
}

size_t LooseGrid::hash_slot(std::int64_t key) const {
    const size_t mask = m_slot_key.size() - 1;
    size_t slot = SpatialHash::mix_key(key) & mask;
    while (m_slot_key[slot] != -1 && m_slot_key[slot] != key)
        slot = (slot + 1) & mask;
    return slot;
}

size_t LooseGrid::dense_slot(const Eigen::Array3i& coords) const {
    const Eigen::Array3i d = coords - m_dense_lo;
    return static_cast<size_t>(d.x() + m_dense_size.x() * (d.y() + m_dense_size.y() * d.z()));
}

int LooseGrid::find_cell(const Eigen::Array3i& coords) const {
    if (!m_dense.empty()) {
        const Eigen::Array3i d = coords - m_dense_lo;
        if ((d < 0).any() || (d >= m_dense_size).any())
            return -1;
        return m_dense[dense_slot(coords)];
    }
    if (m_slot_key.empty())
        return -1;
    const std::int64_t key = cell_key(coords);
    const size_t slot = hash_slot(key);
    return m_slot_key[slot] == -1 ? -1 : m_slot_cell[slot];
}

template <typename F>
void LooseGrid::visit(size_t task, F&& f) const {
    if (task < m_cells.size()) {
        const Cell& cell = m_cells[task];
        for (int a = cell.begin; a < cell.end; ++a) {
            const Box3d& box_a = m_cell_boxes[static_cast<size_t>(a)];
            for (int b = a + 1; b < cell.end; ++b)
                if (boxes_overlap(box_a, m_cell_boxes[static_cast<size_t>(b)]))
                    f(m_ids[static_cast<size_t>(a)], m_ids[static_cast<size_t>(b)]);
        }
        // Against each neighbour only the elements that reach the neighbour's bounding box:
        // most of a cell's elements lie away from the face, edge or corner it shares.
        const Box3d& union_a = m_cell_union[task];
        for (const auto& offset : HALF_STENCIL) {
            const int nb =
                find_cell(cell.coords + Eigen::Array3i(offset[0], offset[1], offset[2]));
            if (nb < 0)
                continue;
            const Box3d& union_b = m_cell_union[static_cast<size_t>(nb)];
            if (!boxes_overlap(union_a, union_b))
                continue;
            const Cell& other = m_cells[static_cast<size_t>(nb)];
            for (int a = cell.begin; a < cell.end; ++a) {
                const Box3d& box_a = m_cell_boxes[static_cast<size_t>(a)];
                if (!boxes_overlap(box_a, union_b))
                    continue;
                for (int b = other.begin; b < other.end; ++b)
                    if (boxes_overlap(box_a, m_cell_boxes[static_cast<size_t>(b)]))
                        f(m_ids[static_cast<size_t>(a)], m_ids[static_cast<size_t>(b)]);
            }
        }
        return;
    }
    // An oversized element against every other element (two oversized ones once).
    const int io = m_oversized[task - m_cells.size()];
    const Box3d& box_o = m_boxes[static_cast<size_t>(io)];
    // The others through the cells that can hold an overlapping element: its min corner lies
    // within one cell below box_o (it is at most one cell wide), as in query().
    const Eigen::Array3d lo_d = ((box_o.min().array() - m_cell) / m_cell).floor();
    const Eigen::Array3d hi_d = (box_o.max().array() / m_cell).floor();
    const double limit = (1 << 20) - 2;
    if (((hi_d - lo_d) + 1.0).prod() <= static_cast<double>(MAX_CELLS_PER_BOX) &&
        (lo_d.abs() <= limit).all() && (hi_d.abs() <= limit).all()) {
        const Eigen::Array3i lo = lo_d.cast<int>(), hi = hi_d.cast<int>();
        for (int z = lo.z(); z <= hi.z(); ++z)
            for (int y = lo.y(); y <= hi.y(); ++y)
                for (int x = lo.x(); x <= hi.x(); ++x) {
                    const int c = find_cell(Eigen::Array3i(x, y, z));
                    if (c < 0)
                        continue;
                    const Cell& cell = m_cells[static_cast<size_t>(c)];
                    for (int k = cell.begin; k < cell.end; ++k)
                        if (boxes_overlap(box_o, m_cell_boxes[static_cast<size_t>(k)]))
                            f(io, m_ids[static_cast<size_t>(k)]);
                }
        for (int jo : m_oversized)
            if (jo > io && boxes_overlap(box_o, m_boxes[static_cast<size_t>(jo)]))
                f(io, jo);
        return;
    }
    for (size_t j = 0; j < m_boxes.size(); ++j) {
        const int ij = static_cast<int>(j);
        if (ij == io || m_boxes[j].isEmpty() || !boxes_overlap(box_o, m_boxes[j]))
            continue;
        if (ij < io && std::binary_search(m_oversized.begin(), m_oversized.end(), ij))
            continue;
        f(io, ij);
    }
}

void LooseGrid::query(const Box3d& box, std::vector<int>& out) const {
    out.clear();
    const Eigen::Array3d lo_d = ((box.min().array() - m_cell) / m_cell).floor();
    const Eigen::Array3d hi_d = (box.max().array() / m_cell).floor();
    const double limit = (1 << 20) - 2;
    const double cells = ((hi_d - lo_d) + 1.0).prod();
    if (!(cells <= static_cast<double>(MAX_CELLS_PER_BOX)) || (lo_d.abs() > limit).any() ||
        (hi_d.abs() > limit).any()) {
        for (size_t i = 0; i < m_boxes.size(); ++i)
            if (!m_boxes[i].isEmpty() && closed_boxes_overlap(m_boxes[i], box))
                out.push_back(static_cast<int>(i));
        return;
    }
    const Eigen::Array3i lo = lo_d.cast<int>(), hi = hi_d.cast<int>();
    for (int z = lo.z(); z <= hi.z(); ++z)
        for (int y = lo.y(); y <= hi.y(); ++y)
            for (int x = lo.x(); x <= hi.x(); ++x) {
                const int c = find_cell(Eigen::Array3i(x, y, z));
                if (c < 0 || !boxes_overlap(m_cell_union[static_cast<size_t>(c)], box))
                    continue;
                const Cell& cell = m_cells[static_cast<size_t>(c)];
                for (int k = cell.begin; k < cell.end; ++k)
                    if (boxes_overlap(m_cell_boxes[static_cast<size_t>(k)], box))
                        out.push_back(m_ids[static_cast<size_t>(k)]);
            }
    for (int id : m_oversized)
        if (closed_boxes_overlap(m_boxes[static_cast<size_t>(id)], box))
            out.push_back(id);
    std::sort(out.begin(), out.end());
    out.erase(std::unique(out.begin(), out.end()), out.end());
}

// ---- BroadPhase ---------------------------------------------------------------------------

namespace {

template <typename MakeBox>
std::vector<Box3d> boxes_of(int count, MakeBox&& make) {
    std::vector<Box3d> boxes(static_cast<size_t>(count));  // default: empty
    tbb::parallel_for(tbb::blocked_range<int>(0, count, 4096),
                      [&](const tbb::blocked_range<int>& r) {
                          for (int i = r.begin(); i < r.end(); ++i)
                              make(i, boxes[static_cast<size_t>(i)]);
                      });
    return boxes;
}

/// Every overlapping pair of `grid`, through `emit(i, j, out)` (i, j unordered), in parallel over
/// the grid's tasks; sorted, so the result does not depend on the threading.
template <typename Pair, typename Emit>
std::vector<Pair> self_join(const LooseGrid& grid, Emit&& emit) {
    tbb::enumerable_thread_specific<std::vector<Pair>> local;
    tbb::parallel_for(tbb::blocked_range<size_t>(0, grid.num_tasks(), SELF_JOIN_GRAIN),
                      [&](const tbb::blocked_range<size_t>& r) {
                          auto& out = local.local();
                          for (size_t task = r.begin(); task < r.end(); ++task)
                              grid.visit(task, [&](int i, int j) { emit(i, j, out); });
                      });
    std::vector<Pair> all;
    for (auto& part : local)
        all.insert(all.end(), part.begin(), part.end());
    std::sort(all.begin(), all.end());
    return all;
}

}  // namespace

BroadPhase::BroadPhase(const SurfaceMesh& mesh, double padding)
    : BroadPhase(mesh, mesh.positions(), mesh.positions(), padding) {}

BroadPhase::BroadPhase(const SurfaceMesh& mesh, const std::vector<Vec3>& x_t0,
                       const std::vector<Vec3>& x_t1, double padding)
    : m_mesh(mesh), m_num_edges(mesh.num_edges()), m_num_triangles(mesh.num_triangles()) {
    check_sizes(mesh, x_t0, x_t1, padding);
    if (!mesh.periodic()) {
        m_vertex_boxes = boxes_of(mesh.num_vertices(), [&](int vi, Box3d& b) {
            if (mesh.vertex_alive(vi) && !mesh.vertex_triangles(vi).empty())
                b = vertex_box(x_t0, x_t1, vi, padding);
        });
        m_edge_boxes = boxes_of(mesh.num_edges(), [&](int ei, Box3d& b) {
            if (mesh.edge_alive(ei))
                b = edge_box(x_t0, x_t1, mesh.edge(ei), padding);
        });
        m_triangle_boxes = boxes_of(mesh.num_triangles(), [&](int ti, Box3d& b) {
            if (mesh.triangle_alive(ti))
                b = triangle_box(x_t0, x_t1, mesh.triangle(ti), padding);
        });
    } else {
        m_vertex_boxes = boxes_of(mesh.num_vertices(), [&](int vi, Box3d& b) {
            if (mesh.vertex_alive(vi) && !mesh.vertex_triangles(vi).empty())
                b = element_box(mesh, x_t0, x_t1, std::array<int, 1>{vi}, padding);
        });
        m_edge_boxes = boxes_of(mesh.num_edges(), [&](int ei, Box3d& b) {
            if (mesh.edge_alive(ei))
                b = element_box(mesh, x_t0, x_t1, mesh.edge(ei), padding);
        });
        m_triangle_boxes = boxes_of(mesh.num_triangles(), [&](int ti, Box3d& b) {
            if (mesh.triangle_alive(ti))
                b = element_box(mesh, x_t0, x_t1, mesh.triangle(ti), padding);
        });
        Vec3 reach = Vec3::Zero();
        extend_reach(m_vertex_boxes, reach);
        extend_reach(m_edge_boxes, reach);
        extend_reach(m_triangle_boxes, reach);
        append_images(mesh.periods(), reach, m_edge_boxes, m_edge_image_of);
        append_images(mesh.periods(), reach, m_triangle_boxes, m_triangle_image_of);
    }
    m_edges.emplace(m_edge_boxes);
    m_triangles.emplace(m_triangle_boxes);
}

std::vector<VertexTrianglePair> BroadPhase::vertex_triangle_pairs() const {
    if (!m_mesh.periodic())
        return collect_parallel<VertexTrianglePair>(
            m_vertex_boxes.size(),
            [&](int vi, std::vector<int>& scratch, std::vector<VertexTrianglePair>& out) {
                const Box3d& vb = m_vertex_boxes[static_cast<size_t>(vi)];
                if (vb.isEmpty())
                    return;
                m_triangles->query(vb, scratch);
                for (int ti : scratch) {
                    const Triangle& t = m_mesh.triangle(ti);
                    if (t[0] != vi && t[1] != vi && t[2] != vi)
                        out.push_back({vi, ti});
                }
            });
    // Periodic: the ids found are triangles or their images; each triangle once per vertex.
    return collect_parallel<VertexTrianglePair>(
        m_vertex_boxes.size(),
        [&](int vi, std::vector<int>& scratch, std::vector<VertexTrianglePair>& out) {
            const Box3d& vb = m_vertex_boxes[static_cast<size_t>(vi)];
            if (vb.isEmpty())
                return;
            m_triangles->query(vb, scratch);
            for (int& id : scratch)
                id = triangle_of(id);
            std::sort(scratch.begin(), scratch.end());
            scratch.erase(std::unique(scratch.begin(), scratch.end()), scratch.end());
            for (int ti : scratch) {
                const Triangle& t = m_mesh.triangle(ti);
                if (t[0] != vi && t[1] != vi && t[2] != vi)
                    out.push_back({vi, ti});
            }
        });
}

namespace {

template <typename Pair>
void deduplicate(std::vector<Pair>& sorted) {
    sorted.erase(std::unique(sorted.begin(), sorted.end()), sorted.end());
}

}  // namespace

std::vector<EdgeEdgePair> BroadPhase::edge_edge_pairs() const {
    if (!m_mesh.periodic())
        return self_join<EdgeEdgePair>(*m_edges,
                                       [&](int ei, int ej, std::vector<EdgeEdgePair>& out) {
                                           if (!shares_vertex(m_mesh.edge(ei), m_mesh.edge(ej)))
                                               out.push_back({std::min(ei, ej), std::max(ei, ej)});
                                       });
    // Periodic: an element against the images of the others (two images overlap only where
    // their elements do, which is found without them); an edge never pairs with its own image.
    std::vector<EdgeEdgePair> pairs =
        self_join<EdgeEdgePair>(*m_edges, [&](int i, int j, std::vector<EdgeEdgePair>& out) {
            if (i >= m_num_edges && j >= m_num_edges)
                return;
            const int ei = edge_of(i), ej = edge_of(j);
            if (ei != ej && !shares_vertex(m_mesh.edge(ei), m_mesh.edge(ej)))
                out.push_back({std::min(ei, ej), std::max(ei, ej)});
        });
    deduplicate(pairs);
    return pairs;
}

std::vector<TrianglePair> BroadPhase::triangle_pairs() const {
    if (!m_mesh.periodic())
        return self_join<TrianglePair>(*m_triangles,
                                       [](int ti, int tj, std::vector<TrianglePair>& out) {
                                           out.push_back({std::min(ti, tj), std::max(ti, tj)});
                                       });
    std::vector<TrianglePair> pairs =
        self_join<TrianglePair>(*m_triangles, [&](int i, int j, std::vector<TrianglePair>& out) {
            if (i >= m_num_triangles && j >= m_num_triangles)
                return;
            const int ti = triangle_of(i), tj = triangle_of(j);
            if (ti != tj)
                out.push_back({std::min(ti, tj), std::max(ti, tj)});
        });
    deduplicate(pairs);
    return pairs;
}

std::vector<EdgeEdgePair> static_edge_edge_pairs(const SurfaceMesh& mesh, double padding,
                                                 const std::function<bool(int, int)>& keep) {
    const std::vector<Vec3>& x = mesh.positions();
    check_sizes(mesh, x, x, padding);
    if (!mesh.periodic()) {
        const std::vector<Box3d> boxes = boxes_of(mesh.num_edges(), [&](int ei, Box3d& b) {
            if (mesh.edge_alive(ei))
                b = edge_box(x, x, mesh.edge(ei), padding);
        });
        const LooseGrid grid(boxes);
        return self_join<EdgeEdgePair>(grid, [&](int ei, int ej, std::vector<EdgeEdgePair>& out) {
            const int a = std::min(ei, ej), b = std::max(ei, ej);
            if (!shares_vertex(mesh.edge(a), mesh.edge(b)) && keep(a, b))
                out.push_back({a, b});
        });
    }
    std::vector<Box3d> boxes = boxes_of(mesh.num_edges(), [&](int ei, Box3d& b) {
        if (mesh.edge_alive(ei))
            b = element_box(mesh, x, x, mesh.edge(ei), padding);
    });
    Vec3 reach = Vec3::Zero();
    extend_reach(boxes, reach);
    std::vector<int> image_of;
    const int n = mesh.num_edges();
    append_images(mesh.periods(), reach, boxes, image_of);
    const LooseGrid grid(boxes);
    std::vector<EdgeEdgePair> pairs =
        self_join<EdgeEdgePair>(grid, [&](int i, int j, std::vector<EdgeEdgePair>& out) {
            if (i >= n && j >= n)
                return;
            const int ei = i < n ? i : image_of[static_cast<size_t>(i - n)];
            const int ej = j < n ? j : image_of[static_cast<size_t>(j - n)];
            const int a = std::min(ei, ej), b = std::max(ei, ej);
            if (a != b && !shares_vertex(mesh.edge(a), mesh.edge(b)) && keep(a, b))
                out.push_back({a, b});
        });
    deduplicate(pairs);
    return pairs;
}

std::vector<VertexTrianglePair> brute_force_vertex_triangle_pairs(const SurfaceMesh& mesh,
                                                                  const std::vector<Vec3>& x_t0,
                                                                  const std::vector<Vec3>& x_t1,
                                                                  double padding) {
    check_sizes(mesh, x_t0, x_t1, padding);
    const std::vector<Vec3> shifts = all_shifts(mesh.periods());
    std::vector<VertexTrianglePair> out;
    for (int vi = 0; vi < mesh.num_vertices(); ++vi) {
        if (!mesh.vertex_alive(vi) || mesh.vertex_triangles(vi).empty())
            continue;
        const Box3d vb = mesh.periodic()
                             ? element_box(mesh, x_t0, x_t1, std::array<int, 1>{vi}, padding)
                             : vertex_box(x_t0, x_t1, vi, padding);
        for (int ti = 0; ti < mesh.num_triangles(); ++ti) {
            if (!mesh.triangle_alive(ti))
                continue;
            const Triangle& t = mesh.triangle(ti);
            if (t[0] == vi || t[1] == vi || t[2] == vi)
                continue;
            if (overlaps_some_image(vb, element_box(mesh, x_t0, x_t1, t, padding), shifts))
                out.push_back({vi, ti});
        }
    }
    return out;
}

std::vector<EdgeEdgePair> brute_force_edge_edge_pairs(const SurfaceMesh& mesh,
                                                      const std::vector<Vec3>& x_t0,
                                                      const std::vector<Vec3>& x_t1,
                                                      double padding) {
    check_sizes(mesh, x_t0, x_t1, padding);
    const std::vector<Vec3> shifts = all_shifts(mesh.periods());
    std::vector<EdgeEdgePair> out;
    for (int ei = 0; ei < mesh.num_edges(); ++ei) {
        if (!mesh.edge_alive(ei))
            continue;
        const Box3d a = element_box(mesh, x_t0, x_t1, mesh.edge(ei), padding);
        for (int ej = ei + 1; ej < mesh.num_edges(); ++ej) {
            if (!mesh.edge_alive(ej) || shares_vertex(mesh.edge(ei), mesh.edge(ej)))
                continue;
            if (overlaps_some_image(a, element_box(mesh, x_t0, x_t1, mesh.edge(ej), padding),
                                    shifts))
                out.push_back({ei, ej});
        }
    }
    return out;
}

std::vector<TrianglePair> brute_force_triangle_pairs(const SurfaceMesh& mesh, double padding) {
    const std::vector<Vec3>& x = mesh.positions();
    check_sizes(mesh, x, x, padding);
    const std::vector<Vec3> shifts = all_shifts(mesh.periods());
    std::vector<TrianglePair> out;
    for (int ti = 0; ti < mesh.num_triangles(); ++ti) {
        if (!mesh.triangle_alive(ti))
            continue;
        const Box3d a = element_box(mesh, x, x, mesh.triangle(ti), padding);
        for (int tj = ti + 1; tj < mesh.num_triangles(); ++tj)
            if (mesh.triangle_alive(tj) &&
                overlaps_some_image(a, element_box(mesh, x, x, mesh.triangle(tj), padding), shifts))
                out.push_back({ti, tj});
    }
    return out;
}

}  // namespace meniscus::tracker
