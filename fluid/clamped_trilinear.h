#pragma once
/// \file Trilinear interpolation of one field clamped onto its sample lattice, inlined: the inner
/// loop of the semi-Lagrangian back-traces (advection.cpp) and the non-periodic case of
/// interpolate_trilinear()/sample_trilinear() (mac_grid.h), which it computes bit for bit.

#include <algorithm>
#include <cstddef>

#include "fluid/array3.h"
#include "fluid/mac_grid.h"

namespace meniscus::fluid {

/// Samples a field whose sample (0, 0, 0) sits at `offset` (cell units, field_offset()), at
/// points in cell units relative to the grid origin. Points off the lattice are clamped onto it
/// (constant extrapolation); no axis is periodic. Holds a pointer to the field's storage: the
/// field must outlive the sampler and keep its size.
class ClampedTrilinear {
public:
    ClampedTrilinear(const Array3<double>& field, const Eigen::Vector3d& offset)
        : m_data(field.data()),
          m_axes{
              Axis{field.ni(), offset.x(), 1},
              Axis{field.nj(), offset.y(), static_cast<std::size_t>(field.ni())},
              Axis{field.nk(), offset.z(),
                   static_cast<std::size_t>(field.ni()) * static_cast<std::size_t>(field.nj())}} {}

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
        s.min = *std::min_element(c, c + 8);
        s.max = *std::max_element(c, c + 8);
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
    /// One lattice axis: sample count, offset of sample 0 (cells) and flat-index stride.
    struct Axis {
        int n;
        double offset;
        std::size_t stride;
    };

    /// The lower sample's flat-index part, the step to the upper one (0 on a one-sample axis)
    /// and the fraction between them, for coordinate `g` (cells) along `axis`: clamped onto
    /// [0, n−1], the lower index at most n−2.
    static void split(const Axis& axis, double g, std::size_t& base, std::size_t& step,
                      double& fraction) {
        if (axis.n <= 1) {
            base = 0;
            step = 0;
            fraction = 0.0;
            return;
        }
        const double s = std::clamp(g - axis.offset, 0.0, static_cast<double>(axis.n - 1));
        const int lower = std::min(static_cast<int>(s), axis.n - 2);  // s ≥ 0: truncation floors
        fraction = s - lower;
        base = static_cast<std::size_t>(lower) * axis.stride;
        step = axis.stride;
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

}  // namespace meniscus::fluid
