#pragma once
/// \file Trilinear interpolation of one field clamped onto its sample lattice, inlined: the inner
/// loop of the semi-Lagrangian back-traces (advection.cpp) and the non-periodic case of
/// interpolate_trilinear()/sample_trilinear() (mac_grid.h), which it computes bit for bit.

#include <algorithm>
#include <cstddef>

#include "fluid/array3.h"
#include "fluid/mac_grid.h"

namespace meniscus::fluid {

/// One lattice axis of n samples, sample 0 at `offset` (cells from the grid origin).
struct LatticeAxis {
    LatticeAxis() = default;
    LatticeAxis(int n, double offset_)
        : offset(offset_), last(n > 1 ? n - 1 : 0), lower_max(n > 1 ? n - 2 : 0) {}

    /// Coordinate `g` (cells) clamped onto the samples: the lower sample of the pair around it
    /// (0 on a one-sample axis) and the fraction from it. Branch-free (a vectorisable select).
    void split(double g, int& lower, double& fraction) const {
        const double s = std::min(std::max(g - offset, 0.0), last);
        const int truncated = static_cast<int>(s);  // s ≥ 0: truncation floors
        lower = truncated < lower_max ? truncated : lower_max;
        fraction = s - lower;
    }
    /// More than one sample (an upper sample to blend with).
    bool spans() const { return last > 0.0; }

    double offset = 0.0;
    double last = 0.0;  ///< the last sample's index (0 on a one-sample axis)
    int lower_max = 0;  ///< the largest lower index of a pair (last − 1, or 0)
};

/// Samples a field whose sample (0, 0, 0) sits at `offset` (cell units, field_offset()), at
/// points in cell units relative to the grid origin. Points off the lattice are clamped onto it
/// (constant extrapolation); no axis is periodic. Holds a pointer to the field's storage: the
/// field must outlive the sampler and keep its size.
class ClampedTrilinear {
public:
    ClampedTrilinear(const Array3<double>& field, const Eigen::Vector3d& offset)
        : m_data(field.data()),
          m_axes{Axis(field, 0, offset.x()), Axis(field, 1, offset.y()),
                 Axis(field, 2, offset.z())} {}

    /// The interpolated value at `g` (cell units).
    double value(const Eigen::Vector3d& g) const {
        double c[8];
        double fx, fy, fz;
        gather(g, c, fx, fy, fz);
        return blend(c, fx, fy, fz);
    }

    /// The value and the smallest and largest of the 8 samples it blends.
    TrilinearSample sample(const Eigen::Vector3d& g) const {
        double c[8];
        double fx, fy, fz;
        gather(g, c, fx, fy, fz);
        TrilinearSample s;
        s.value = blend(c, fx, fy, fz);
        // Pairwise, each taking the earlier of equal samples: std::min_element's and
        // std::max_element's choices, in fewer dependent steps.
        const auto lo = [](double a, double b) { return std::min(a, b); };
        const auto hi = [](double a, double b) { return std::max(a, b); };
        s.min = lo(lo(lo(c[0], c[1]), lo(c[2], c[3])), lo(lo(c[4], c[5]), lo(c[6], c[7])));
        s.max = hi(hi(hi(c[0], c[1]), hi(c[2], c[3])), hi(hi(c[4], c[5]), hi(c[6], c[7])));
        return s;
    }

    /// The trilinear blend of 8 corner samples at fractions (fx, fy, fz) in [0, 1]; corners
    /// in the order 000, 100, 010, 110, 001, 101, 011, 111 (x fastest).
    static double blend(const double* c, double fx, double fy, double fz) {
        const double c00 = c[0] + fx * (c[1] - c[0]);
        const double c10 = c[2] + fx * (c[3] - c[2]);
        const double c01 = c[4] + fx * (c[5] - c[4]);
        const double c11 = c[6] + fx * (c[7] - c[6]);
        const double c0 = c00 + fy * (c10 - c00);
        const double c1 = c01 + fy * (c11 - c01);
        return c0 + fz * (c1 - c0);
    }

private:
    /// One lattice axis with the flat-index stride and the step from the lower sample to the
    /// upper one (0 on a one-sample axis).
    struct Axis {
        Axis(const Array3<double>& field, int axis, double offset)
            : lattice(axis == 0 ? field.ni() : (axis == 1 ? field.nj() : field.nk()), offset),
              stride(field.stride(axis)),
              step(lattice.spans() ? stride : 0) {}
        LatticeAxis lattice;
        std::size_t stride;
        std::size_t step;
    };

    /// The lower sample's flat-index part, the step to the upper one and the fraction between
    /// them, for coordinate `g` (cells) along `axis`.
    static void split(const Axis& axis, double g, std::size_t& base, std::size_t& step,
                      double& fraction) {
        int lower;
        axis.lattice.split(g, lower, fraction);
        base = static_cast<std::size_t>(lower) * axis.stride;
        step = axis.step;
    }

    void gather(const Eigen::Vector3d& g, double* c, double& fx, double& fy, double& fz) const {
        std::size_t bx, by, bz, dx, dy, dz;
        split(m_axes[0], g.x(), bx, dx, fx);
        split(m_axes[1], g.y(), by, dy, fy);
        split(m_axes[2], g.z(), bz, dz, fz);
        const double* f = m_data + bx + by + bz;
        c[0] = f[0];
        c[1] = f[dx];
        c[2] = f[dy];
        c[3] = f[dy + dx];
        c[4] = f[dz];
        c[5] = f[dz + dx];
        c[6] = f[dz + dy];
        c[7] = f[dz + dy + dx];
    }

    const double* m_data;
    Axis m_axes[3];
};

/// The three face velocities of a MAC grid (u, v, w of mac_grid.h) sampled at one point, each
/// as ClampedTrilinear samples it (bit for bit). Along each axis the component normal to it has
/// its samples on the faces (offset 0, n + 1 samples) and the other two at the cell centres
/// (offset ½, n samples), so those two share their lower sample and fraction: 6 splits of a
/// coordinate instead of 9. Holds pointers to the arrays' storage (see ClampedTrilinear).
class ClampedVelocity {
public:
    ClampedVelocity(const Array3<double>& u, const Array3<double>& v, const Array3<double>& w)
        : m_components{Component(u), Component(v), Component(w)} {
        const int cells[3] = {v.ni(), u.nj(), u.nk()};
        for (int a = 0; a < 3; ++a) {
            m_face[a] = LatticeAxis(cells[a] + 1, 0.0);
            m_centre[a] = LatticeAxis(cells[a], 0.5);
        }
        for (int c = 0; c < 3; ++c)
            for (int a = 0; a < 3; ++a) {
                const LatticeAxis& l = a == c ? m_face[a] : m_centre[a];
                Component& m = m_components[c];
                m.step[a] = l.spans() ? m.stride[a] : 0;
            }
    }

    /// u, v and w (m/s) at `g` (cell units).
    Eigen::Vector3d value(const Eigen::Vector3d& g) const {
        int face_lower[3], centre_lower[3];
        double face_fraction[3], centre_fraction[3];
        for (int a = 0; a < 3; ++a) {
            m_face[a].split(g[a], face_lower[a], face_fraction[a]);
            m_centre[a].split(g[a], centre_lower[a], centre_fraction[a]);
        }
        return Eigen::Vector3d(
            m_components[0].value(face_lower[0], centre_lower[1], centre_lower[2], face_fraction[0],
                                  centre_fraction[1], centre_fraction[2]),
            m_components[1].value(centre_lower[0], face_lower[1], centre_lower[2],
                                  centre_fraction[0], face_fraction[1], centre_fraction[2]),
            m_components[2].value(centre_lower[0], centre_lower[1], face_lower[2],
                                  centre_fraction[0], centre_fraction[1], face_fraction[2]));
    }

private:
    /// One component's storage, strides and steps to the upper samples.
    struct Component {
        explicit Component(const Array3<double>& f)
            : data(f.data()), stride{f.stride(0), f.stride(1), f.stride(2)} {}
        double value(int i, int j, int k, double fx, double fy, double fz) const {
            const double* p = data + static_cast<std::size_t>(i) +
                              static_cast<std::size_t>(j) * stride[1] +
                              static_cast<std::size_t>(k) * stride[2];
            const std::size_t dx = step[0], dy = step[1], dz = step[2];
            const double c[8] = {p[0],  p[dx],      p[dy],      p[dy + dx],
                                 p[dz], p[dz + dx], p[dz + dy], p[dz + dy + dx]};
            return ClampedTrilinear::blend(c, fx, fy, fz);
        }
        const double* data;
        std::size_t stride[3];
        std::size_t step[3] = {0, 0, 0};
    };

    Component m_components[3];
    LatticeAxis m_face[3], m_centre[3];
};

}  // namespace meniscus::fluid
