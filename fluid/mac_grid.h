#pragma once
/// \file Staggered MAC grid: geometry, face velocities and staggered interpolation.
///
/// Conventions (used by every file in fluid/):
/// - The box is [origin, origin + (nx, ny, nz)·dx], cubic cells of edge dx (metres).
/// - Cell (i, j, k) has its centre at origin + ((i+½), (j+½), (k+½))·dx; pressure p and the level
///   set φ live there (arrays nx × ny × nz).
/// - u(i, j, k) is the x-velocity (m/s) on the x-face at origin + (i, j+½, k+½)·dx, array
///   (nx+1) × ny × nz; the face separates cell (i−1, j, k) from cell (i, j, k).
///   v(i, j, k) at origin + (i+½, j, k+½)·dx, array nx × (ny+1) × nz;
///   w(i, j, k) at origin + (i+½, j+½, k)·dx, array nx × ny × (nz+1).
/// - Faces with i = 0 or i = nx (resp. j, k) lie on the domain walls; the velocity stored there is
///   the normal velocity of the box face (boundary.h: zero on walls, the inflow's, or the
///   projection's on an outflow).
/// - Axes are numbered 0 = x, 1 = y, 2 = z; sides 0 = min wall, 1 = max wall.
/// - Along a periodic axis (MacGrid::periodic(), boundary.h) the box repeats: cell n−1 neighbours
///   cell 0, the face samples at 0 and n are the same face (the one at n a copy), and samples
///   wrap around instead of being clamped.

#include <array>

#include <Eigen/Core>

#include "fluid/array3.h"

namespace meniscus::fluid {

/// Per axis: does the box repeat along it (see the file comment)?
using Periodicity = std::array<bool, 3>;

/// Where the samples of a grid field live (see the file comment).
enum class FieldLocation { x_face, y_face, z_face, cell_centre };

/// Position of sample (0, 0, 0) of a field at `location`, in cell units relative to the origin:
/// u → (0, ½, ½), v → (½, 0, ½), w → (½, ½, 0), cell centre → (½, ½, ½).
Eigen::Vector3d field_offset(FieldLocation location);

/// The face location of velocity component `axis` (0 → x_face, 1 → y_face, 2 → z_face).
FieldLocation face_location(int axis);

/// A trilinear sample and the minimum and maximum of the 8 samples it interpolated (for clamping).
struct TrilinearSample {
    double value = 0.0;  ///< interpolated value
    double min = 0.0;    ///< smallest of the 8 samples used
    double max = 0.0;    ///< largest of the 8 samples used
};

/// Trilinear interpolation of `field` (stored at `location`) at `grid_position`, a point in cell
/// units relative to the grid origin ((x − origin)/dx). Points outside the sample lattice are
/// clamped onto it (constant extrapolation), except along the `periodic` axes, where the lattice
/// repeats with the period of the box (its last face sample, a copy of the first, is not read).
/// Exact for fields linear in each coordinate.
TrilinearSample sample_trilinear(const Array3<double>& field, FieldLocation location,
                                 const Eigen::Vector3d& grid_position,
                                 const Periodicity& periodic = {});

/// Sets the samples of `faces` (a face field along `axis`, n+1 samples along it) at index n to
/// those at 0: along a periodic axis the face at n is the copy of the seam's face at 0.
void copy_seam_faces(Array3<double>& faces, int axis);

/// The value of sample_trilinear() alone (cheaper: no stencil bounds).
double interpolate_trilinear(const Array3<double>& field, FieldLocation location,
                             const Eigen::Vector3d& grid_position,
                             const Periodicity& periodic = {});

/// Staggered MAC grid holding the face velocities (m/s). See the file comment for the layout.
class MacGrid {
public:
    /// A grid of nx × ny × nz cubic cells of edge `dx` (m) whose min corner is `origin` (m).
    /// All velocities start at zero. Throws std::invalid_argument if a size is < 1 or dx ≤ 0.
    MacGrid(int nx, int ny, int nz, double dx,
            const Eigen::Vector3d& origin = Eigen::Vector3d::Zero());

    /// Cell counts along x, y and z.
    int nx() const { return m_nx; }
    int ny() const { return m_ny; }
    int nz() const { return m_nz; }
    /// Cell count along `axis`.
    int cells(int axis) const { return axis == 0 ? m_nx : (axis == 1 ? m_ny : m_nz); }
    /// Cell edge length (m).
    double dx() const { return m_dx; }
    /// Min corner of the box (m).
    const Eigen::Vector3d& origin() const { return m_origin; }

    /// x-velocity on x-faces, (nx+1) × ny × nz, m/s.
    Array3<double>& u() { return m_velocity[0]; }
    const Array3<double>& u() const { return m_velocity[0]; }
    /// y-velocity on y-faces, nx × (ny+1) × nz, m/s.
    Array3<double>& v() { return m_velocity[1]; }
    const Array3<double>& v() const { return m_velocity[1]; }
    /// z-velocity on z-faces, nx × ny × (nz+1), m/s.
    Array3<double>& w() { return m_velocity[2]; }
    const Array3<double>& w() const { return m_velocity[2]; }
    /// Velocity component `axis` (0 = u, 1 = v, 2 = w).
    Array3<double>& velocity(int axis) { return m_velocity[axis]; }
    const Array3<double>& velocity(int axis) const { return m_velocity[axis]; }

    /// Centre of cell (i, j, k) in metres.
    Eigen::Vector3d cell_centre(int i, int j, int k) const;
    /// Centre of face (i, j, k) of velocity component `axis`, in metres.
    Eigen::Vector3d face_centre(int axis, int i, int j, int k) const;
    /// The axes along which the box repeats (default none); set from the boundaries by the
    /// solver. Sampling wraps along them.
    const Periodicity& periodic() const { return m_periodic; }
    void set_periodic(const Periodicity& periodic) { m_periodic = periodic; }

    /// (x − origin)/dx: a position in cell units.
    Eigen::Vector3d to_grid(const Eigen::Vector3d& x) const { return (x - m_origin) / m_dx; }

    /// Trilinear interpolation of velocity component `axis` at position `x` (m), m/s.
    double sample_component(int axis, const Eigen::Vector3d& x) const;
    /// Velocity (m/s) at position `x` (m), each component interpolated on its own faces.
    Eigen::Vector3d sample_velocity(const Eigen::Vector3d& x) const;

    /// Discrete divergence of cell (i, j, k): Σ outward face velocity / dx, in 1/s. Inline, by
    /// flat index with one bounds check: the projection's loops call it for every cell.
    double divergence(int i, int j, int k) const {
        MENISCUS_ASSERT(i >= 0 && j >= 0 && k >= 0 && i < m_nx && j < m_ny && k < m_nz,
                        "MacGrid::divergence: cell out of range");
        const Array3<double>& u_face = m_velocity[0];
        const Array3<double>& v_face = m_velocity[1];
        const Array3<double>& w_face = m_velocity[2];
        const std::size_t u = u_face.index(i, j, k);
        const std::size_t v = v_face.index(i, j, k);
        const std::size_t w = w_face.index(i, j, k);
        const std::size_t v_step = static_cast<std::size_t>(v_face.ni());
        const std::size_t w_step = static_cast<std::size_t>(w_face.ni()) * w_face.nj();
        return (u_face[u + 1] - u_face[u] + v_face[v + v_step] - v_face[v] + w_face[w + w_step] -
                w_face[w]) /
               m_dx;
    }
    /// Largest |u|, |v|, |w| over all faces, per component (m/s).
    Eigen::Vector3d max_abs_velocity() const;
    /// Sets the velocity on every wall face (normal component on the box boundary) to zero.
    void zero_wall_normal_velocity();

private:
    int m_nx;
    int m_ny;
    int m_nz;
    double m_dx;
    Eigen::Vector3d m_origin;
    Periodicity m_periodic = {false, false, false};
    std::array<Array3<double>, 3> m_velocity;
};

}  // namespace meniscus::fluid
