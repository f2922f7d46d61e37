#include "fluid/mac_grid.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "fluid/clamped_trilinear.h"

namespace meniscus::fluid {

namespace {

constexpr double HALF = 0.5;

/// Clamps a lattice coordinate onto [0, n−1] and splits it into a base index and a fraction in
/// [0, 1]; the base index is at most n−2 so that base+1 is valid whenever n ≥ 2.
void split_coordinate(double s, int n, int& base, double& fraction) {
    if (n <= 1) {
        base = 0;
        fraction = 0.0;
        return;
    }
    s = std::clamp(s, 0.0, static_cast<double>(n - 1));
    base = std::min(static_cast<int>(std::floor(s)), n - 2);
    fraction = s - base;
}

}  // namespace

Eigen::Vector3d field_offset(FieldLocation location) {
    switch (location) {
        case FieldLocation::x_face:
            return {0.0, HALF, HALF};
        case FieldLocation::y_face:
            return {HALF, 0.0, HALF};
        case FieldLocation::z_face:
            return {HALF, HALF, 0.0};
        case FieldLocation::cell_centre:
            return {HALF, HALF, HALF};
    }
    return {HALF, HALF, HALF};
}

FieldLocation face_location(int axis) {
    switch (axis) {
        case 0:
            return FieldLocation::x_face;
        case 1:
            return FieldLocation::y_face;
        case 2:
            return FieldLocation::z_face;
        default:
            throw std::invalid_argument("face_location: axis must be 0, 1 or 2");
    }
}

namespace {

/// The 8 samples around a point and its fractional position between them.
struct Stencil {
    double c[8];  ///< (x, y, z) corners in the order 000, 100, 010, 110, 001, 101, 011, 111
    double fx, fy, fz;
};

/// Wraps a lattice coordinate onto a periodic lattice of `period` samples and splits it into the
/// two sample indices around it and the fraction between them.
void split_periodic(double s, int period, int& first, int& second, double& fraction) {
    const double base = std::floor(s);
    fraction = s - base;
    first = static_cast<int>(base - period * std::floor(base / period));
    second = first + 1 == period ? 0 : first + 1;
}

/// The stencil around `grid_position` on a box with at least one periodic axis (the others
/// clamped as ClampedTrilinear does).
Stencil gather_periodic_stencil(const Array3<double>& field, FieldLocation location,
                                const Eigen::Vector3d& grid_position, const Periodicity& periodic) {
    const Eigen::Vector3d s = grid_position - field_offset(location);
    Stencil st;
    const std::array<int, 3> n = {field.ni(), field.nj(), field.nk()};
    std::array<int, 3> lo{}, hi{};
    double* fraction[3] = {&st.fx, &st.fy, &st.fz};
    for (int a = 0; a < 3; ++a) {
        const auto ax = static_cast<std::size_t>(a);
        if (periodic[ax]) {
            // A face field along its own axis holds the seam twice (0 and n).
            const int period = location == face_location(a) ? n[ax] - 1 : n[ax];
            split_periodic(s[a], period, lo[ax], hi[ax], *fraction[a]);
        } else {
            split_coordinate(s[a], n[ax], lo[ax], *fraction[a]);
            hi[ax] = n[ax] > 1 ? lo[ax] + 1 : lo[ax];
        }
    }
    for (int corner = 0; corner < 8; ++corner)
        st.c[corner] = field((corner & 1) ? hi[0] : lo[0], (corner & 2) ? hi[1] : lo[1],
                             (corner & 4) ? hi[2] : lo[2]);
    return st;
}

bool any_periodic(const Periodicity& periodic) {
    return periodic[0] || periodic[1] || periodic[2];
}

}  // namespace

double interpolate_trilinear(const Array3<double>& field, FieldLocation location,
                             const Eigen::Vector3d& grid_position, const Periodicity& periodic) {
    if (!any_periodic(periodic))
        return ClampedTrilinear(field, field_offset(location)).value(grid_position);
    const Stencil st = gather_periodic_stencil(field, location, grid_position, periodic);
    return ClampedTrilinear::blend(st.c, st.fx, st.fy, st.fz);
}

TrilinearSample sample_trilinear(const Array3<double>& field, FieldLocation location,
                                 const Eigen::Vector3d& grid_position,
                                 const Periodicity& periodic) {
    if (!any_periodic(periodic))
        return ClampedTrilinear(field, field_offset(location)).sample(grid_position);
    const Stencil st = gather_periodic_stencil(field, location, grid_position, periodic);
    TrilinearSample sample;
    sample.value = ClampedTrilinear::blend(st.c, st.fx, st.fy, st.fz);
    sample.min = *std::min_element(st.c, st.c + 8);
    sample.max = *std::max_element(st.c, st.c + 8);
    return sample;
}

void copy_seam_faces(Array3<double>& faces, int axis) {
    const int last = (axis == 0 ? faces.ni() : (axis == 1 ? faces.nj() : faces.nk())) - 1;
    for (int k = 0; k < (axis == 2 ? 1 : faces.nk()); ++k)
        for (int j = 0; j < (axis == 1 ? 1 : faces.nj()); ++j)
            for (int i = 0; i < (axis == 0 ? 1 : faces.ni()); ++i) {
                std::array<int, 3> copy = {i, j, k};
                copy[static_cast<std::size_t>(axis)] = last;
                faces(copy[0], copy[1], copy[2]) = faces(i, j, k);
            }
}

MacGrid::MacGrid(int nx, int ny, int nz, double dx, const Eigen::Vector3d& origin)
    : m_nx(nx), m_ny(ny), m_nz(nz), m_dx(dx), m_origin(origin) {
    if (nx < 1 || ny < 1 || nz < 1) {
        throw std::invalid_argument("MacGrid: nx, ny and nz must be at least 1");
    }
    if (!(dx > 0.0) || !std::isfinite(dx)) {
        throw std::invalid_argument("MacGrid: dx must be a positive, finite length in metres");
    }
    if (!origin.allFinite()) {
        throw std::invalid_argument("MacGrid: origin must be finite");
    }
    m_velocity[0].resize(nx + 1, ny, nz, 0.0);
    m_velocity[1].resize(nx, ny + 1, nz, 0.0);
    m_velocity[2].resize(nx, ny, nz + 1, 0.0);
}

Eigen::Vector3d MacGrid::cell_centre(int i, int j, int k) const {
    return m_origin + m_dx * Eigen::Vector3d(i + HALF, j + HALF, k + HALF);
}

Eigen::Vector3d MacGrid::face_centre(int axis, int i, int j, int k) const {
    return m_origin + m_dx * (Eigen::Vector3d(i, j, k) + field_offset(face_location(axis)));
}

double MacGrid::sample_component(int axis, const Eigen::Vector3d& x) const {
    return interpolate_trilinear(m_velocity[axis], face_location(axis), to_grid(x), m_periodic);
}

Eigen::Vector3d MacGrid::sample_velocity(const Eigen::Vector3d& x) const {
    const Eigen::Vector3d g = to_grid(x);
    return {interpolate_trilinear(m_velocity[0], FieldLocation::x_face, g, m_periodic),
            interpolate_trilinear(m_velocity[1], FieldLocation::y_face, g, m_periodic),
            interpolate_trilinear(m_velocity[2], FieldLocation::z_face, g, m_periodic)};
}

Eigen::Vector3d MacGrid::max_abs_velocity() const {
    Eigen::Vector3d result = Eigen::Vector3d::Zero();
    for (int axis = 0; axis < 3; ++axis) {
        for (double value : m_velocity[axis].storage()) {
            result[axis] = std::max(result[axis], std::abs(value));
        }
    }
    return result;
}

void MacGrid::zero_wall_normal_velocity() {
    Array3<double>& u_face = m_velocity[0];
    Array3<double>& v_face = m_velocity[1];
    Array3<double>& w_face = m_velocity[2];
    for (int k = 0; k < m_nz; ++k) {
        for (int j = 0; j < m_ny; ++j) {
            u_face(0, j, k) = 0.0;
            u_face(m_nx, j, k) = 0.0;
        }
    }
    for (int k = 0; k < m_nz; ++k) {
        for (int i = 0; i < m_nx; ++i) {
            v_face(i, 0, k) = 0.0;
            v_face(i, m_ny, k) = 0.0;
        }
    }
    for (int j = 0; j < m_ny; ++j) {
        for (int i = 0; i < m_nx; ++i) {
            w_face(i, j, 0) = 0.0;
            w_face(i, j, m_nz) = 0.0;
        }
    }
}

}  // namespace meniscus::fluid
