#include "coupling/interpolate.h"

#include "tracker/mesh_measures.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <optional>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <utility>

namespace meniscus::coupling {

namespace {

/// A linear combination Σ w_f u_f of the faces of one velocity component: what a sampler below
/// computes when the field it reads yields unit forms instead of values, i.e. its weights.
struct LinearForm {
    static constexpr int CAPACITY = 64;  ///< the samplers combine at most 27 face reads
    std::array<std::pair<std::size_t, double>, CAPACITY> terms{};
    int count = 0;

    static LinearForm unit(std::size_t face) {
        LinearForm f;
        f.terms[0] = {face, 1.0};
        f.count = 1;
        return f;
    }
    LinearForm& operator+=(const LinearForm& o) {
        if (count + o.count > CAPACITY)
            throw std::logic_error("LinearForm: more terms than a sampler combines");
        for (int t = 0; t < o.count; ++t)
            terms[static_cast<size_t>(count++)] = o.terms[static_cast<size_t>(t)];
        return *this;
    }
};

LinearForm operator*(double s, LinearForm f) {
    for (int t = 0; t < f.count; ++t)
        f.terms[static_cast<size_t>(t)].second *= s;
    return f;
}
LinearForm operator+(LinearForm a, const LinearForm& b) { return a += b; }
LinearForm operator-(LinearForm a, const LinearForm& b) { return a += -1.0 * b; }

/// The samples of one component as values (double) or as unit forms of their flat index.
template <typename T>
struct FieldReader {
    const fluid::Array3<double>& field;
    int ni() const { return field.ni(); }
    int nj() const { return field.nj(); }
    int nk() const { return field.nk(); }
    T operator()(int i, int j, int k) const {
        if constexpr (std::is_same_v<T, LinearForm>)
            return LinearForm::unit(field.index(i, j, k));
        else
            return field(i, j, k);
    }
};

/// Lower node of the linear-interpolation interval of lattice coordinate `s` (clamped into the
/// lattice of `extent` nodes) and the fraction within it.
std::pair<int, double> lattice_interval(double s, int extent) {
    if (extent < 2)
        return {0, 0.0};
    const double clamped = std::clamp(s, 0.0, extent - 1.0);
    const int lower = std::min(static_cast<int>(std::floor(clamped)), extent - 2);
    return {lower, clamped - lower};
}

/// Trilinear sample of component `axis` at `grid_position` (cell units), points outside the face
/// lattice clamped onto it: fluid::interpolate_trilinear for values, its weights for forms.
template <typename T>
T sample_component_trilinear(const fluid::MacGrid& grid, int axis,
                             const Eigen::Vector3d& grid_position) {
    const fluid::FieldLocation location = fluid::face_location(axis);
    if constexpr (!std::is_same_v<T, LinearForm>) {
        return fluid::interpolate_trilinear(grid.velocity(axis), location, grid_position);
    } else {
        const FieldReader<T> field{grid.velocity(axis)};
        const Eigen::Vector3d g = grid_position - fluid::field_offset(location);
        const std::array<int, 3> extent{field.ni(), field.nj(), field.nk()};
        std::array<std::pair<int, double>, 3> cell{};
        for (int d = 0; d < 3; ++d)
            cell[static_cast<size_t>(d)] = lattice_interval(g[d], extent[static_cast<size_t>(d)]);
        T value{};
        for (int c = 0; c < 8; ++c) {
            std::array<int, 3> node{};
            double weight = 1.0;
            for (int d = 0; d < 3; ++d) {
                const int up = (c >> d) & 1;
                const auto [lower, f] = cell[static_cast<size_t>(d)];
                node[static_cast<size_t>(d)] =
                    std::min(lower + up, extent[static_cast<size_t>(d)] - 1);
                weight *= up ? f : 1.0 - f;
            }
            if (weight != 0.0)
                value += weight * field(node[0], node[1], node[2]);
        }
        return value;
    }
}

/// Quadratic B-spline weights of the nodes n−1, n, n+1 for a point at offset f ∈ [−½, ½] from
/// node n: they sum to 1 and have first moment f, hence reproduce linear functions.
std::array<double, 3> quadratic_bspline_weights(double f) {
    const double lo = 0.5 - f;
    const double hi = 0.5 + f;
    return {0.5 * lo * lo, 0.75 - f * f, 0.5 * hi * hi};
}

/// Quadratic B-spline sample of velocity component `axis` at `grid_position` (cell units from
/// the origin); falls back to trilinear where the stencil leaves the face lattice.
template <typename T>
T sample_component_bspline(const fluid::MacGrid& grid, int axis,
                           const Eigen::Vector3d& grid_position) {
    const FieldReader<T> field{grid.velocity(axis)};
    const fluid::FieldLocation location = fluid::face_location(axis);
    const Eigen::Vector3d g = grid_position - fluid::field_offset(location);
    const std::array<int, 3> extent{field.ni(), field.nj(), field.nk()};
    std::array<int, 3> node{};
    std::array<std::array<double, 3>, 3> weights{};
    for (int d = 0; d < 3; ++d) {
        const double nearest = std::floor(g[d] + 0.5);
        node[static_cast<size_t>(d)] = static_cast<int>(nearest);
        if (!(nearest >= 1.0 && nearest <= extent[static_cast<size_t>(d)] - 2.0))
            return sample_component_trilinear<T>(grid, axis, grid_position);
        weights[static_cast<size_t>(d)] = quadratic_bspline_weights(g[d] - nearest);
    }
    T value{};
    for (int c = 0; c < 3; ++c) {
        for (int b = 0; b < 3; ++b) {
            const std::array<double, 3>& wx = weights[0];
            const double w = weights[2][static_cast<size_t>(c)] * weights[1][static_cast<size_t>(b)];
            const int j = node[1] - 1 + b, k = node[2] - 1 + c;
            value += (w * wx[0]) * field(node[0] - 1, j, k);
            value += (w * wx[1]) * field(node[0], j, k);
            value += (w * wx[2]) * field(node[0] + 1, j, k);
        }
    }
    return value;
}

/// One-sided sample (VelocityInterpolation::one_sided) of velocity component `axis` at
/// `grid_position` (cell units) for an interface with unit normal `n` there.
template <typename T>
T sample_component_one_sided(const fluid::MacGrid& grid, int axis,
                             const Eigen::Vector3d& grid_position, const Eigen::Vector3d& n) {
    const FieldReader<T> field{grid.velocity(axis)};
    const std::array<int, 3> extent{field.ni(), field.nj(), field.nk()};
    // Points outside the face lattice are clamped onto it, as trilinear sampling does: vertices
    // far outside the domain (the cut ends of a wall-crossing column) must not see the columns
    // extrapolated over many cells.
    Eigen::Vector3d g = grid_position - fluid::field_offset(fluid::face_location(axis));
    for (int d = 0; d < 3; ++d)
        g[d] = std::clamp(g[d], 0.0, extent[static_cast<size_t>(d)] - 1.0);
    int a = 0;  // the column axis: the one closest to the normal
    n.cwiseAbs().maxCoeff(&a);
    const int b = (a + 1) % 3, e = (a + 2) % 3;
    const auto [ib, fb] = lattice_interval(g[b], extent[static_cast<size_t>(b)]);
    const auto [ie, fe] = lattice_interval(g[e], extent[static_cast<size_t>(e)]);
    const int na = extent[static_cast<size_t>(a)];
    T value{};
    for (int cb = 0; cb < 2; ++cb) {
        for (int ce = 0; ce < 2; ++ce) {
            const double weight = (cb ? fb : 1.0 - fb) * (ce ? fe : 1.0 - fe);
            if (weight == 0.0)
                continue;
            std::array<int, 3> node{};
            node[static_cast<size_t>(b)] = std::min(ib + cb, extent[static_cast<size_t>(b)] - 1);
            node[static_cast<size_t>(e)] = std::min(ie + ce, extent[static_cast<size_t>(e)] - 1);
            // Where the tangent plane n·(p − x) = 0 crosses this column.
            const double s = g[a] - (n[b] * (node[static_cast<size_t>(b)] - g[b]) +
                                     n[e] * (node[static_cast<size_t>(e)] - g[e])) /
                                        n[a];
            const auto at = [&](int i) {
                node[static_cast<size_t>(a)] = i;
                return field(node[0], node[1], node[2]);
            };
            T column{};
            if (na >= 4 && s >= 1.0 && s < na - 2.0) {
                const int i0 = static_cast<int>(std::floor(s));
                const double d = s - i0;
                const T f0 = at(i0), f1 = at(i0 + 1);
                const T below = f0 + d * (f0 - at(i0 - 1));
                const T above = f1 + (1.0 - d) * (f1 - at(i0 + 2));
                column = (1.0 - d) * below + d * above;
            } else if (na >= 2) {  // near a wall: linear along the column (extrapolated past
                                   // its ends, which keeps linear fields exact)
                const int i0 = std::clamp(static_cast<int>(std::floor(s)), 0, na - 2);
                const double d = s - i0;
                column = (1.0 - d) * at(i0) + d * at(i0 + 1);
            } else {
                column = at(0);
            }
            value += weight * column;
        }
    }
    return value;
}

/// Each component at `grid_position` (cell units) with `method`, as values or forms.
template <typename T>
std::array<T, 3> sample_components(const fluid::MacGrid& grid, const Eigen::Vector3d& g,
                                   VelocityInterpolation method, const Eigen::Vector3d& normal) {
    const double length = normal.norm();
    const bool one_sided =
        method == VelocityInterpolation::one_sided && length > 0.0 && std::isfinite(length);
    std::array<T, 3> velocity{};
    for (int axis = 0; axis < 3; ++axis) {
        T& v = velocity[static_cast<size_t>(axis)];
        if (one_sided)
            v = sample_component_one_sided<T>(grid, axis, g, normal / length);
        else if (method == VelocityInterpolation::quadratic_bspline)
            v = sample_component_bspline<T>(grid, axis, g);
        else
            v = sample_component_trilinear<T>(grid, axis, g);
    }
    return velocity;
}

/// The velocity of a vertex at x with normal n as interpolate_vertex_velocities() takes it:
/// outside a free-slip wall (mirror), the sample at the reflected point and normal with the
/// wall-normal component negated back.
template <typename T>
std::array<T, 3> sample_vertex(const fluid::MacGrid& grid, Eigen::Vector3d x, Eigen::Vector3d n,
                               const InterpolateOptions& options,
                               const fluid::BoundaryOptions& walls) {
    const Eigen::Vector3d lo = grid.origin();
    const Eigen::Vector3d hi =
        lo + grid.dx() * Eigen::Vector3d(grid.nx(), grid.ny(), grid.nz());
    std::array<bool, 3> reflected{};
    if (options.outside == OutsideVelocity::mirror)
        for (int d = 0; d < 3; ++d) {
            const int side = x[d] < lo[d] ? 0 : x[d] > hi[d] ? 1 : -1;
            if (side < 0 || walls.at(d, side) != fluid::BoundaryType::free_slip)
                continue;
            const double plane = side == 0 ? lo[d] : hi[d];
            x[d] = 2.0 * plane - x[d];
            n[d] = -n[d];
            reflected[static_cast<size_t>(d)] = true;
        }
    std::array<T, 3> v = sample_components<T>(grid, grid.to_grid(x), options.method, n);
    for (int d = 0; d < 3; ++d)
        if (reflected[static_cast<size_t>(d)])
            v[static_cast<size_t>(d)] = -1.0 * v[static_cast<size_t>(d)];
    return v;
}

/// Cells of copies added on each side of a periodic axis for sampling: more than any stencil
/// here reaches beyond the point's cell (the one-sided columns reach two faces).
constexpr int PERIODIC_PAD_CELLS = 4;

/// A copy of `grid` grown by `pad` cells on both sides of each periodic axis, the added faces
/// being the periodic images of the box's (face index I of the copy is face (I − pad) mod n of
/// the box, the seam's copy at n left out). Its samplers need no knowledge of periods: a point of
/// the box lies `pad` cells from the copy's ends along those axes.
fluid::MacGrid padded_periodic_copy(const fluid::MacGrid& grid, int pad) {
    std::array<int, 3> n{grid.nx(), grid.ny(), grid.nz()}, grown = n;
    Eigen::Vector3d origin = grid.origin();
    for (int a = 0; a < 3; ++a)
        if (grid.periodic()[static_cast<size_t>(a)]) {
            grown[static_cast<size_t>(a)] += 2 * pad;
            origin[a] -= pad * grid.dx();
        }
    fluid::MacGrid copy(grown[0], grown[1], grown[2], grid.dx(), origin);
    for (int axis = 0; axis < 3; ++axis) {
        const fluid::Array3<double>& from = grid.velocity(axis);
        fluid::Array3<double>& to = copy.velocity(axis);
        const auto source = [&](int index, int a) {
            if (!grid.periodic()[static_cast<size_t>(a)])
                return index;
            const int m = n[static_cast<size_t>(a)];
            return ((index - pad) % m + m) % m;
        };
        for (int k = 0; k < to.nk(); ++k)
            for (int j = 0; j < to.nj(); ++j)
                for (int i = 0; i < to.ni(); ++i)
                    to(i, j, k) = from(source(i, 0), source(j, 1), source(k, 2));
    }
    return copy;
}

bool any_periodic(const fluid::MacGrid& grid) {
    return grid.periodic()[0] || grid.periodic()[1] || grid.periodic()[2];
}

}  // namespace

void InterpolateOptions::validate() const {
    if (method != VelocityInterpolation::trilinear &&
        method != VelocityInterpolation::quadratic_bspline &&
        method != VelocityInterpolation::one_sided)
        throw std::invalid_argument("method: expected trilinear, quadratic_bspline or one_sided");
    if (outside != OutsideVelocity::clamp && outside != OutsideVelocity::mirror)
        throw std::invalid_argument("outside: expected clamp or mirror");
}

Eigen::Vector3d sample_grid_velocity(const fluid::MacGrid& grid, const Eigen::Vector3d& x,
                                     VelocityInterpolation method, const Eigen::Vector3d& normal) {
    const std::array<double, 3> v = sample_components<double>(grid, grid.to_grid(x), method, normal);
    return {v[0], v[1], v[2]};
}

std::vector<tracker::Vec3> interpolate_vertex_velocities(const fluid::MacGrid& grid,
                                                         const tracker::SurfaceMesh& mesh,
                                                         const InterpolateOptions& options,
                                                         const fluid::BoundaryOptions& walls) {
    options.validate();
    walls.validate();
    std::vector<tracker::Vec3> velocities(static_cast<size_t>(mesh.num_vertices()),
                                          tracker::Vec3::Zero());
    // A periodic box is sampled on a copy grown by its images (vertices of a periodic mesh lie
    // in the box, so every stencil stays inside the copy).
    std::optional<fluid::MacGrid> padded;
    if (any_periodic(grid))
        padded.emplace(padded_periodic_copy(grid, PERIODIC_PAD_CELLS));
    const fluid::MacGrid& sampled = padded ? *padded : grid;
    const std::vector<tracker::Vec3> normals = options.method == VelocityInterpolation::one_sided
                                                   ? tracker::area_weighted_vertex_normals(mesh)
                                                   : std::vector<tracker::Vec3>{};
    tbb::parallel_for(
        tbb::blocked_range<int>(0, mesh.num_vertices()), [&](const tbb::blocked_range<int>& range) {
            for (int vi = range.begin(); vi != range.end(); ++vi) {
                if (!mesh.vertex_alive(vi))
                    continue;
                const std::array<double, 3> v = sample_vertex<double>(
                    sampled, mesh.position(vi),
                    normals.empty() ? Eigen::Vector3d::Zero() : normals[static_cast<size_t>(vi)],
                    options, walls);
                velocities[static_cast<size_t>(vi)] = tracker::Vec3(v[0], v[1], v[2]);
            }
        });
    return velocities;
}

Eigen::SparseMatrix<double, Eigen::RowMajor> vertex_velocity_weights(
    const fluid::MacGrid& grid, const tracker::SurfaceMesh& mesh, const std::vector<int>& vertices,
    const InterpolateOptions& options, const fluid::BoundaryOptions& walls) {
    options.validate();
    walls.validate();
    if (any_periodic(grid))
        throw std::invalid_argument(
            "vertex_velocity_weights: not available on a periodic grid (its forms would name the "
            "faces of the box's images)");
    const std::vector<tracker::Vec3> normals = options.method == VelocityInterpolation::one_sided
                                                   ? tracker::area_weighted_vertex_normals(mesh)
                                                   : std::vector<tracker::Vec3>{};
    const std::size_t offsets[3] = {0, grid.u().size(), grid.u().size() + grid.v().size()};
    std::vector<Eigen::Triplet<double>> entries;
    entries.reserve(vertices.size() * 3 * 16);
    for (std::size_t p = 0; p < vertices.size(); ++p) {
        const int vi = vertices[p];
        if (vi < 0 || vi >= mesh.num_vertices() || !mesh.vertex_alive(vi))
            throw std::invalid_argument("vertex_velocity_weights: vertex " + std::to_string(vi) +
                                        " is not a live vertex of the mesh");
        const std::array<LinearForm, 3> forms = sample_vertex<LinearForm>(
            grid, mesh.position(vi),
            normals.empty() ? Eigen::Vector3d::Zero() : normals[static_cast<size_t>(vi)],
            options, walls);
        for (int a = 0; a < 3; ++a) {
            const LinearForm& f = forms[static_cast<size_t>(a)];
            for (int t = 0; t < f.count; ++t) {
                const auto& [face, weight] = f.terms[static_cast<size_t>(t)];
                if (weight != 0.0)
                    entries.emplace_back(static_cast<Eigen::Index>(3 * p + a),
                                         static_cast<Eigen::Index>(offsets[a] + face), weight);
            }
        }
    }
    Eigen::SparseMatrix<double, Eigen::RowMajor> weights(
        static_cast<Eigen::Index>(3 * vertices.size()),
        static_cast<Eigen::Index>(offsets[2] + grid.w().size()));
    weights.setFromTriplets(entries.begin(), entries.end());
    return weights;
}

}  // namespace meniscus::coupling
