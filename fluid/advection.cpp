#include "fluid/advection.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <stdexcept>

namespace meniscus::fluid {

namespace {

constexpr double HALF = 0.5;

/// Velocity in cell units per second (m/s ÷ dx) at a point given in cell units.
Eigen::Vector3d grid_velocity(const std::array<const Array3<double>*, 3>& velocity,
                              const Eigen::Vector3d& g, double inverse_dx,
                              const Periodicity& periodic) {
    return inverse_dx *
           Eigen::Vector3d(interpolate_trilinear(*velocity[0], FieldLocation::x_face, g, periodic),
                           interpolate_trilinear(*velocity[1], FieldLocation::y_face, g, periodic),
                           interpolate_trilinear(*velocity[2], FieldLocation::z_face, g, periodic));
}

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

/// Is sample (i, j, k) of a field at `location` on a wall-normal face (kept fixed)? Along a
/// periodic axis the face at 0 is advected like an interior one and the one at n is its copy
/// (also kept during the pass, set afterwards by copy_seam()).
bool is_fixed_sample(FieldLocation location, const Array3<double>& field, int i, int j, int k,
                     const Periodicity& periodic) {
    const int axis = face_axis(location);
    if (axis < 0)
        return false;
    const int along = axis == 0 ? i : (axis == 1 ? j : k);
    const int last = (axis == 0 ? field.ni() : (axis == 1 ? field.nj() : field.nk())) - 1;
    return (along == 0 && !periodic[static_cast<std::size_t>(axis)]) || along == last;
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

/// One semi-Lagrangian pass: out(x) = in(x − dt·u) with RK2 back-tracing; `dt` may be negative
/// (forward trace). When bounds are requested, the min/max of the interpolation stencil is stored.
/// `inflows`: the inflow faces to which the field's samples are tangential.
void semi_lagrangian(const std::array<const Array3<double>*, 3>& velocity, double inverse_dx,
                     double dt, FieldLocation location, const Array3<double>& in,
                     Array3<double>& out, Array3<double>* lower, Array3<double>* upper,
                     const std::vector<TangentialInflow>& inflows, const Periodicity& periodic) {
    const Eigen::Vector3d offset = field_offset(location);
    tbb::parallel_for(tbb::blocked_range<int>(0, in.nk()), [&](const tbb::blocked_range<int>& r) {
        for (int k = r.begin(); k != r.end(); ++k) {
            for (int j = 0; j < in.nj(); ++j) {
                for (int i = 0; i < in.ni(); ++i) {
                    const std::size_t c = in.index(i, j, k);
                    if (is_fixed_sample(location, in, i, j, k, periodic)) {
                        out[c] = in[c];
                        if (lower != nullptr) {
                            (*lower)[c] = in[c];
                            (*upper)[c] = in[c];
                        }
                        continue;
                    }
                    const Eigen::Vector3d start = Eigen::Vector3d(i, j, k) + offset;
                    const Eigen::Vector3d mid =
                        start - HALF * dt * grid_velocity(velocity, start, inverse_dx, periodic);
                    const Eigen::Vector3d departure =
                        start - dt * grid_velocity(velocity, mid, inverse_dx, periodic);
                    if (lower != nullptr || !inflows.empty()) {
                        TrilinearSample sample =
                            sample_trilinear(in, location, departure, periodic);
                        apply_tangential_inflows(inflows, departure, sample);
                        out[c] = sample.value;
                        if (lower != nullptr) {
                            (*lower)[c] = sample.min;
                            (*upper)[c] = sample.max;
                        }
                    } else {
                        out[c] = interpolate_trilinear(in, location, departure, periodic);
                    }
                }
            }
        }
    });
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
    const std::vector<TangentialInflow> inflows = tangential_inflows(grid, location, boundaries);
    const std::array<const Array3<double>*, 3> velocity = {&grid.u(), &grid.v(), &grid.w()};
    const double inverse_dx = 1.0 / grid.dx();
    const Periodicity& periodic = grid.periodic();
    const int ni = field.ni(), nj = field.nj(), nk = field.nk();
    Array3<double> forward(ni, nj, nk);
    Array3<double> lower(ni, nj, nk), upper(ni, nj, nk);
    semi_lagrangian(velocity, inverse_dx, dt, location, field, forward, &lower, &upper, inflows,
                    periodic);
    if (options.scheme == AdvectionScheme::semi_lagrangian) {
        field = std::move(forward);
        copy_seam(location, periodic, field);
        return;
    }
    Array3<double> backward(ni, nj, nk);
    semi_lagrangian(velocity, inverse_dx, -dt, location, forward, backward, nullptr, nullptr,
                    inflows, periodic);
    Array3<double> corrected(ni, nj, nk);
    if (options.scheme == AdvectionScheme::bfecc) {
        // Advect φ0 + (φ0 − φ̂0)/2 forward again.
        Array3<double> compensated(ni, nj, nk);
        for (std::size_t c = 0; c < field.size(); ++c) {
            compensated[c] = field[c] + HALF * (field[c] - backward[c]);
        }
        semi_lagrangian(velocity, inverse_dx, dt, location, compensated, corrected, nullptr,
                        nullptr, inflows, periodic);
    } else {
        // MacCormack: φ1 + (φ0 − φ̂0)/2.
        for (std::size_t c = 0; c < field.size(); ++c) {
            corrected[c] = forward[c] + HALF * (field[c] - backward[c]);
        }
    }
    for (std::size_t c = 0; c < field.size(); ++c) {
        const double value = corrected[c];
        field[c] = (value < lower[c] || value > upper[c]) ? forward[c] : value;
    }
    copy_seam(location, periodic, field);
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
