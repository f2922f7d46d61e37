#include "fluid/advection.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <stdexcept>

#include "fluid/clamped_trilinear.h"

namespace meniscus::fluid {

namespace {

constexpr double HALF = 0.5;

/// Samples per chunk of a row in semi_lagrangian().
constexpr int TRACE_CHUNK = 16;

/// The axis whose faces hold a field at `location` (−1 for cell centres).
int face_axis(FieldLocation location) {
    switch (location) {
        case FieldLocation::x_face:
            return 0;
        case FieldLocation::y_face:
            return 1;
        case FieldLocation::z_face:
            return 2;
        case FieldLocation::cell_centre:
            return -1;
    }
    return -1;
}

/// The samplers of a box without periodic axes: the inlined ClampedTrilinear.
class ClampedSamplers {
public:
    ClampedSamplers(const std::array<const Array3<double>*, 3>& velocity, double inverse_dx)
        : m_fields(velocity),
          m_velocity(*velocity[0], *velocity[1], *velocity[2]),
          m_inverse_dx(inverse_dx) {}

    /// Velocity in cell units per second (m/s ÷ dx) at a point given in cell units.
    Eigen::Vector3d velocity(const Eigen::Vector3d& g) const {
        return m_inverse_dx * m_velocity.value(g);
    }

    /// The velocities at the samples of row (j, k) of a field at `location` (velocity_at()).
    class Row {
    public:
        Row(const ClampedSamplers& samplers, FieldLocation location, int j, int k)
            : m_samplers(samplers), m_axis(face_axis(location)) {
            if (m_axis < 0)
                return;
            for (int b = 0; b < 3; ++b) {
                const Array3<double>& f = *samplers.m_fields[static_cast<std::size_t>(b)];
                m_data[b] = f.data();
                m_row[b] = f.index(0, j, k);
                m_step_a[b] = f.stride(m_axis);
                m_step_b[b] = f.stride(b);
            }
        }

        /// velocity() at sample i of the row, `g` its position, for a sample that is not on a
        /// wall normal to its axis: a face's own component is its sample, each other the mean
        /// of the 4 around it (trilinear interpolation there, one fraction 0 and two ½, with
        /// fewer operations).
        Eigen::Vector3d velocity_at(int i, const Eigen::Vector3d& g) const {
            if (m_axis < 0)
                return m_samplers.velocity(g);
            Eigen::Vector3d result;
            for (int b = 0; b < 3; ++b) {
                const double* f = m_data[b];
                const std::size_t c = m_row[b] + static_cast<std::size_t>(i);
                if (b == m_axis) {
                    result[b] = f[c];
                    continue;
                }
                // Component b's lattice: the face lies between samples at_a − 1 and at_a along
                // a, and at_b and at_b + 1 along b.
                const std::size_t step_a = m_step_a[b], step_b = m_step_b[b];
                const std::size_t first = c - step_a;
                result[b] = 0.25 * (f[first] + f[first + step_a] + f[first + step_b] +
                                    f[first + step_a + step_b]);
            }
            return m_samplers.m_inverse_dx * result;
        }

    private:
        const ClampedSamplers& m_samplers;
        int m_axis;
        const double* m_data[3] = {nullptr, nullptr, nullptr};
        std::size_t m_row[3] = {0, 0, 0};
        std::size_t m_step_a[3] = {0, 0, 0};
        std::size_t m_step_b[3] = {0, 0, 0};
    };

    Row row(FieldLocation location, int j, int k) const { return Row(*this, location, j, k); }

    /// A sampler of one advected field.
    class Field {
    public:
        Field(const Array3<double>& field, FieldLocation location)
            : m_sampler(field, field_offset(location)) {}
        double value(const Eigen::Vector3d& g) const { return m_sampler.value(g); }
        TrilinearSample sample(const Eigen::Vector3d& g) const { return m_sampler.sample(g); }

    private:
        ClampedTrilinear m_sampler;
    };

    Field field(const Array3<double>& in, FieldLocation location) const {
        return Field(in, location);
    }

private:
    std::array<const Array3<double>*, 3> m_fields;
    ClampedVelocity m_velocity;
    double m_inverse_dx;
};

/// The samplers of a box with periodic axes: mac_grid.h's wrapping interpolation.
class PeriodicSamplers {
public:
    PeriodicSamplers(const std::array<const Array3<double>*, 3>& velocity, double inverse_dx,
                     const Periodicity& periodic)
        : m_velocity(velocity), m_inverse_dx(inverse_dx), m_periodic(periodic) {}

    /// The velocities at the samples of a row: velocity() at their positions.
    class Row {
    public:
        explicit Row(const PeriodicSamplers& samplers) : m_samplers(samplers) {}
        Eigen::Vector3d velocity_at(int, const Eigen::Vector3d& g) const {
            return m_samplers.velocity(g);
        }

    private:
        const PeriodicSamplers& m_samplers;
    };

    Row row(FieldLocation, int, int) const { return Row(*this); }

    Eigen::Vector3d velocity(const Eigen::Vector3d& g) const {
        return m_inverse_dx *
               Eigen::Vector3d(
                   interpolate_trilinear(*m_velocity[0], FieldLocation::x_face, g, m_periodic),
                   interpolate_trilinear(*m_velocity[1], FieldLocation::y_face, g, m_periodic),
                   interpolate_trilinear(*m_velocity[2], FieldLocation::z_face, g, m_periodic));
    }

    class Field {
    public:
        Field(const Array3<double>& field, FieldLocation location, const Periodicity& periodic)
            : m_field(field), m_location(location), m_periodic(periodic) {}
        double value(const Eigen::Vector3d& g) const {
            return interpolate_trilinear(m_field, m_location, g, m_periodic);
        }
        TrilinearSample sample(const Eigen::Vector3d& g) const {
            return sample_trilinear(m_field, m_location, g, m_periodic);
        }

    private:
        const Array3<double>& m_field;
        FieldLocation m_location;
        const Periodicity& m_periodic;
    };

    Field field(const Array3<double>& in, FieldLocation location) const {
        return Field(in, location, m_periodic);
    }

private:
    std::array<const Array3<double>*, 3> m_velocity;
    double m_inverse_dx;
    const Periodicity& m_periodic;
};

/// The samples of row (j, k) of a field at `location` that are not on wall-normal faces (kept
/// fixed): [first, end), empty when the whole row lies on such a face. Along a periodic axis the
/// face at 0 is advected like an interior one and the one at n is its copy (also kept during the
/// pass, set afterwards by copy_seam()).
struct FreeSamples {
    int first = 0;
    int end = 0;
};

FreeSamples free_samples(FieldLocation location, const Array3<double>& field, int j, int k,
                         const Periodicity& periodic) {
    const int axis = face_axis(location);
    const auto fixed = [&](int along, int count) {
        return (along == 0 && !periodic[static_cast<std::size_t>(axis)]) || along == count - 1;
    };
    if ((axis == 1 && fixed(j, field.nj())) || (axis == 2 && fixed(k, field.nk())))
        return {0, 0};
    if (axis == 0)
        return {periodic[0] ? 0 : 1, field.ni() - 1};
    return {0, field.ni()};
}

/// Along a periodic axis, the face samples at n of a face field of that axis repeat those at 0.
void copy_seam(FieldLocation location, const Periodicity& periodic, Array3<double>& field) {
    const int axis = face_axis(location);
    if (axis >= 0 && periodic[static_cast<std::size_t>(axis)])
        copy_seam_faces(field, axis);
}

/// The inflow faces across which a component's samples are tangential: for each, the axis, the
/// side and the box's cell count along the axis.
struct TangentialInflow {
    int axis = 0;
    int side = 0;
    int cells = 0;
};

std::vector<TangentialInflow> tangential_inflows(const MacGrid& grid, FieldLocation location,
                                                 const BoundaryOptions* boundaries) {
    std::vector<TangentialInflow> faces;
    if (!boundaries || location == FieldLocation::cell_centre)
        return faces;
    const int component = face_axis(location);
    for (int axis = 0; axis < 3; ++axis)
        for (int side = 0; side < 2; ++side)
            if (axis != component && boundaries->at(axis, side) == BoundaryType::inflow)
                faces.push_back({axis, side, grid.cells(axis)});
    return faces;
}

/// A departure point `g` (cell units) of a tangential component near an inflow face: the
/// inflowing fluid has no tangential velocity, so between the face and the first sample half a
/// cell inside the value falls linearly to 0, and beyond the face it is 0. Scales the sample
/// and widens its bounds to 0.
void apply_tangential_inflows(const std::vector<TangentialInflow>& faces, const Eigen::Vector3d& g,
                              TrilinearSample& sample) {
    for (const TangentialInflow& f : faces) {
        const double from_face = f.side == 0 ? g[f.axis] : f.cells - g[f.axis];
        if (from_face >= HALF)
            continue;
        sample.value *= std::max(0.0, from_face) / HALF;
        sample.min = std::min(sample.min, 0.0);
        sample.max = std::max(sample.max, 0.0);
    }
}

/// One semi-Lagrangian pass: the value of `in` at x − dt·u for every sample x, with RK2
/// back-tracing; `dt` may be negative (forward trace). Calls emit(c, sample) for each flat index
/// c, with the min/max of the interpolation stencil when `Bounds` (else only sample.value is
/// set); wall-normal face samples (kept fixed) pass their own value. `inflows`: the inflow faces
/// to which the field's samples are tangential.
template <bool Bounds, class Samplers, class Emit>
void semi_lagrangian(const Samplers& samplers, double dt, FieldLocation location,
                     const Array3<double>& in, const std::vector<TangentialInflow>& inflows,
                     const Periodicity& periodic, Emit&& emit) {
    const Eigen::Vector3d offset = field_offset(location);
    tbb::parallel_for(tbb::blocked_range<int>(0, in.nk()), [&](const tbb::blocked_range<int>& r) {
        // Local copies: the samplers' parameters stay in registers instead of being reloaded
        // after every store of emit() (which could alias them).
        const Samplers local = samplers;
        const auto field = local.field(in, location);
        std::array<Eigen::Vector3d, TRACE_CHUNK> mid, departure;
        for (int k = r.begin(); k != r.end(); ++k) {
            for (int j = 0; j < in.nj(); ++j) {
                const std::size_t row = in.index(0, j, k);
                const FreeSamples free = free_samples(location, in, j, k, periodic);
                const auto velocities = local.row(location, j, k);
                // A row in chunks, each step of the trace for the whole chunk before the next:
                // one sample's chain of dependent loads and interpolations is longer than the
                // processor looks ahead, the chunk's chains overlap (~20 % less time).
                for (int first = 0; first < in.ni(); first += TRACE_CHUNK) {
                    const int count = std::min(TRACE_CHUNK, in.ni() - first);
                    const auto start = [&](int s) -> Eigen::Vector3d {
                        return Eigen::Vector3d(first + s, j, k) + offset;
                    };
                    const auto is_free = [&](int s) {
                        return first + s >= free.first && first + s < free.end;
                    };
                    for (int s = 0; s < count; ++s)  // fixed samples: traced, not used
                        mid[s] = is_free(s)
                                     ? Eigen::Vector3d(
                                           start(s) -
                                           HALF * dt * velocities.velocity_at(first + s, start(s)))
                                     : start(s);
                    for (int s = 0; s < count; ++s)
                        departure[s] = start(s) - dt * local.velocity(mid[s]);
                    for (int s = 0; s < count; ++s) {
                        const std::size_t c = row + static_cast<std::size_t>(first + s);
                        if (!is_free(s)) {
                            emit(c, TrilinearSample{in[c], in[c], in[c]});
                            continue;
                        }
                        TrilinearSample sample;
                        if (Bounds || !inflows.empty()) {
                            sample = field.sample(departure[s]);
                            apply_tangential_inflows(inflows, departure[s], sample);
                        } else {
                            sample.value = field.value(departure[s]);
                        }
                        emit(c, sample);
                    }
                }
            }
        }
    });
}

/// advect_field() with the samplers of the grid's boundaries.
template <class Samplers>
void advect_with(const Samplers& samplers, double dt, FieldLocation location,
                 const AdvectionOptions& options, Array3<double>& field,
                 const std::vector<TangentialInflow>& inflows, const Periodicity& periodic) {
    const int ni = field.ni(), nj = field.nj(), nk = field.nk();
    Array3<double> forward(ni, nj, nk);
    Array3<double> lower(ni, nj, nk), upper(ni, nj, nk);
    semi_lagrangian<true>(samplers, dt, location, field, inflows, periodic,
                          [&](std::size_t c, const TrilinearSample& s) {
                              forward[c] = s.value;
                              lower[c] = s.min;
                              upper[c] = s.max;
                          });
    // A corrected value outside the forward stencil's range falls back to the forward one.
    const auto limited = [&](std::size_t c, double corrected) {
        return (corrected < lower[c] || corrected > upper[c]) ? forward[c] : corrected;
    };
    switch (options.scheme) {
        case AdvectionScheme::semi_lagrangian:
            field = std::move(forward);
            break;
        case AdvectionScheme::maccormack:
            // φ1 + (φ0 − φ̂0)/2, φ̂0 the forward result traced back: each sample reads φ0 at its
            // own index only, so the result overwrites φ0 in place.
            semi_lagrangian<false>(samplers, -dt, location, forward, inflows, periodic,
                                   [&](std::size_t c, const TrilinearSample& s) {
                                       field[c] =
                                           limited(c, forward[c] + HALF * (field[c] - s.value));
                                   });
            break;
        case AdvectionScheme::bfecc: {
            // Advect φ0 + (φ0 − φ̂0)/2 forward again.
            Array3<double> compensated(ni, nj, nk);
            semi_lagrangian<false>(samplers, -dt, location, forward, inflows, periodic,
                                   [&](std::size_t c, const TrilinearSample& s) {
                                       compensated[c] = field[c] + HALF * (field[c] - s.value);
                                   });
            semi_lagrangian<false>(
                samplers, dt, location, compensated, inflows, periodic,
                [&](std::size_t c, const TrilinearSample& s) { field[c] = limited(c, s.value); });
            break;
        }
    }
    copy_seam(location, periodic, field);
}

}  // namespace

void AdvectionOptions::validate() const {
    if (scheme != AdvectionScheme::semi_lagrangian && scheme != AdvectionScheme::bfecc &&
        scheme != AdvectionScheme::maccormack) {
        throw std::invalid_argument("AdvectionOptions.scheme: unknown advection scheme");
    }
}

void advect_field(const MacGrid& grid, double dt, FieldLocation location,
                  const AdvectionOptions& options, Array3<double>& field,
                  const BoundaryOptions* boundaries) {
    options.validate();
    for (int axis = 0; axis < 3; ++axis)
        if (&field == &grid.velocity(axis))
            throw std::invalid_argument(
                "advect_field: the field must not be one of the grid's velocity arrays (it is "
                "overwritten while they are sampled); advect a copy");
    const std::vector<TangentialInflow> inflows = tangential_inflows(grid, location, boundaries);
    const std::array<const Array3<double>*, 3> velocity = {&grid.u(), &grid.v(), &grid.w()};
    const double inverse_dx = 1.0 / grid.dx();
    const Periodicity& periodic = grid.periodic();
    if (periodic[0] || periodic[1] || periodic[2])
        advect_with(PeriodicSamplers(velocity, inverse_dx, periodic), dt, location, options, field,
                    inflows, periodic);
    else
        advect_with(ClampedSamplers(velocity, inverse_dx), dt, location, options, field, inflows,
                    periodic);
}

void advect_velocity(MacGrid& grid, double dt, const AdvectionOptions& options,
                     const BoundaryOptions* boundaries) {
    const MacGrid start = grid;
    for (int axis = 0; axis < 3; ++axis) {
        Array3<double> component = start.velocity(axis);
        advect_field(start, dt, face_location(axis), options, component, boundaries);
        grid.velocity(axis) = std::move(component);
    }
}

}  // namespace meniscus::fluid
