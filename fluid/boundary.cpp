#include "fluid/boundary.h"

#include <cmath>
#include <stdexcept>
#include <string>

namespace meniscus::fluid {

namespace {

constexpr const char* FACE_NAMES[3][2] = {
    {"x_min", "x_max"}, {"y_min", "y_max"}, {"z_min", "z_max"}};
/// Mean of 1 − s² over s ∈ [−1, 1] is 2/3: a parabola of mean 1 peaks at 3/2.
constexpr double PLANE_PARABOLA_PEAK = 1.5;
/// Mean of 1 − r²/R² over a disc is 1/2: a paraboloid of mean 1 peaks at 2.
constexpr double DISC_PARABOLA_PEAK = 2.0;
/// Sub-samples per side of a face that a disc's rim crosses (its velocity is their mean).
constexpr int RIM_SUBSAMPLES = 8;

void check_side(int axis, int side) {
    if (side != 0 && side != 1)
        throw std::invalid_argument("BoundaryOptions::face: side must be 0 (min) or 1 (max)");
    if (axis < 0 || axis > 2)
        throw std::invalid_argument("BoundaryOptions::face: axis must be 0, 1 or 2");
}

/// Is axis b bounded by walls or inflows on both sides (so a parabolic profile vanishes there)?
bool walled_axis(const BoundaryOptions& boundaries, int b) {
    for (int side = 0; side < 2; ++side) {
        const BoundaryType type = boundaries.at(b, side);
        if (type == BoundaryType::free_slip || type == BoundaryType::outflow ||
            type == BoundaryType::periodic)
            return false;
    }
    return true;
}

/// Calls visit(i, j, k) for every sample of velocity component `axis` on the box face `side`.
template <class Visit>
void for_each_boundary_face(const MacGrid& grid, int axis, int side, Visit&& visit) {
    const Array3<double>& faces = grid.velocity(axis);
    const int along = side == 0 ? 0 : grid.cells(axis);
    int index[3];
    int& i = index[0];
    int& j = index[1];
    int& k = index[2];
    const int ni = axis == 0 ? 1 : faces.ni();
    const int nj = axis == 1 ? 1 : faces.nj();
    const int nk = axis == 2 ? 1 : faces.nk();
    for (k = 0; k < nk; ++k)
        for (j = 0; j < nj; ++j)
            for (i = 0; i < ni; ++i) {
                int at[3] = {i, j, k};
                at[axis] = along;
                visit(at[0], at[1], at[2]);
            }
}

/// The inflow's normal velocity (m/s, along +axis) averaged over a square of edge `width` (m;
/// 0 for the value at `point`) centred at `point` on face (axis, side), a region containing it
/// whole, at `time` (s): the parabolas are quadratic, so their mean takes each coordinate's mean
/// square, t_c² + width²/12.
double profile_velocity(const BoundaryOptions& boundaries, int axis, int side,
                        const Eigen::Vector3d& point, const Eigen::Vector3d& box_min,
                        const Eigen::Vector3d& box_max, double width, double time) {
    const FaceBoundary& f = boundaries.face(axis, side);
    if (f.type != BoundaryType::inflow || f.inflow.speed == 0.0)
        return 0.0;
    const InflowOptions& in = f.inflow;
    const double spread = width * width / 12.0;  // variance of a coordinate over the square
    double shape = 1.0;
    if (in.region == InflowRegion::disc) {
        double r2 = 0.0;
        for (int b = 0; b < 3; ++b)
            if (b != axis)
                r2 += (point[b] - in.centre[b]) * (point[b] - in.centre[b]);
        if (r2 >= in.radius * in.radius)
            return 0.0;
        if (in.profile == InflowProfile::parabolic)
            shape = DISC_PARABOLA_PEAK *
                    std::max(0.0, 1.0 - (r2 + 2.0 * spread) / (in.radius * in.radius));
    } else if (in.profile == InflowProfile::parabolic) {
        for (int b = 0; b < 3; ++b) {
            if (b == axis || !walled_axis(boundaries, b))
                continue;
            const double half = 0.5 * (box_max[b] - box_min[b]);
            const double s = (point[b] - 0.5 * (box_min[b] + box_max[b])) / half;
            shape *= PLANE_PARABOLA_PEAK * std::max(0.0, 1.0 - s * s - spread / (half * half));
        }
    }
    const double into_box = side == 0 ? 1.0 : -1.0;
    return into_box * in.speed_at(time) * shape;
}

}  // namespace

FaceBoundary& BoundaryOptions::face(int axis, int side) {
    return const_cast<FaceBoundary&>(static_cast<const BoundaryOptions&>(*this).face(axis, side));
}

const FaceBoundary& BoundaryOptions::face(int axis, int side) const {
    check_side(axis, side);
    const FaceBoundary* faces[3][2] = {{&x_min, &x_max}, {&y_min, &y_max}, {&z_min, &z_max}};
    return *faces[axis][side];
}

const char* boundary_type_name(BoundaryType type) {
    switch (type) {
        case BoundaryType::free_slip:
            return "free_slip";
        case BoundaryType::no_slip:
            return "no_slip";
        case BoundaryType::inflow:
            return "inflow";
        case BoundaryType::outflow:
            return "outflow";
        case BoundaryType::periodic:
            return "periodic";
    }
    return "unknown";
}

bool BoundaryOptions::moving() const {
    for (int axis = 0; axis < 3; ++axis)
        for (int side = 0; side < 2; ++side)
            if (face(axis, side).velocity != Eigen::Vector3d::Zero())
                return true;
    return false;
}

bool BoundaryOptions::has(BoundaryType type) const {
    for (int axis = 0; axis < 3; ++axis)
        for (int side = 0; side < 2; ++side)
            if (at(axis, side) == type)
                return true;
    return false;
}

BoundaryOptions BoundaryOptions::at_rest() const {
    BoundaryOptions rest = *this;
    for (int axis = 0; axis < 3; ++axis)
        for (int side = 0; side < 2; ++side) {
            FaceBoundary& f = rest.face(axis, side);
            f.velocity = Eigen::Vector3d::Zero();
            f.inflow.speed = 0.0;
            f.pressure = 0.0;
        }
    return rest;
}

BoundaryOptions BoundaryOptions::all(BoundaryType type) {
    BoundaryOptions boundaries;
    for (int axis = 0; axis < 3; ++axis)
        for (int side = 0; side < 2; ++side)
            boundaries.face(axis, side).type = type;
    return boundaries;
}

void BoundaryOptions::validate() const {
    std::string inflow_face;  // the first inflow with a speed
    for (int axis = 0; axis < 3; ++axis)
        for (int side = 0; side < 2; ++side) {
            const FaceBoundary& f = face(axis, side);
            const std::string name = FACE_NAMES[axis][side];
            if (f.type != BoundaryType::free_slip && f.type != BoundaryType::no_slip &&
                f.type != BoundaryType::inflow && f.type != BoundaryType::outflow &&
                f.type != BoundaryType::periodic)
                throw std::invalid_argument(
                    name +
                    "/type: unknown boundary type (use free_slip, no_slip, inflow, outflow or "
                    "periodic)");
            const BoundaryType opposite = at(axis, 1 - side);
            if ((f.type == BoundaryType::periodic) != (opposite == BoundaryType::periodic))
                throw std::invalid_argument(
                    std::string(FACE_NAMES[axis][1]) + ": " + FACE_NAMES[axis][0] + " is " +
                    boundary_type_name(at(axis, 0)) + " and " + FACE_NAMES[axis][1] + " " +
                    boundary_type_name(at(axis, 1)) +
                    ": a periodic face is paired with the opposite face, which must be periodic "
                    "too");
            if (!f.velocity.allFinite())
                throw std::invalid_argument(name + "/velocity: expected finite numbers (m/s)");
            if (f.velocity[axis] != 0.0)
                throw std::invalid_argument(
                    name +
                    "/velocity: the component along the face's normal must be 0 (a wall slides "
                    "along itself; fluid through a face is an inflow, not a wall)");
            if (f.velocity != Eigen::Vector3d::Zero() && f.type != BoundaryType::no_slip)
                throw std::invalid_argument(
                    name + "/velocity: only a no_slip wall drags the fluid along itself; " + name +
                    " is " + boundary_type_name(f.type));
            if (!std::isfinite(f.pressure))
                throw std::invalid_argument(name + "/pressure: expected a finite number (Pa)");
            const InflowOptions& in = f.inflow;
            if (!(std::isfinite(in.speed) && in.speed >= 0.0))
                throw std::invalid_argument(name +
                                            "/inflow/speed: expected a finite speed >= 0 (m/s)");
            if (!(in.pulse >= 0.0 && in.pulse < 1.0))
                throw std::invalid_argument(name + "/inflow/pulse: expected a number in [0, 1)");
            if (!(std::isfinite(in.pulse_frequency) && in.pulse_frequency >= 0.0))
                throw std::invalid_argument(
                    name + "/inflow/pulse_frequency: expected a finite number >= 0 (Hz)");
            if (in.pulse > 0.0 && in.pulse_frequency == 0.0)
                throw std::invalid_argument(
                    name + "/inflow/pulse_frequency: a pulsed inflow needs a frequency > 0 (Hz)");
            if (in.profile != InflowProfile::uniform && in.profile != InflowProfile::parabolic)
                throw std::invalid_argument(name + "/inflow/profile: unknown profile");
            if (in.region != InflowRegion::face && in.region != InflowRegion::disc)
                throw std::invalid_argument(name + "/inflow/region: unknown region");
            if (in.phase != InflowPhase::liquid && in.phase != InflowPhase::gas)
                throw std::invalid_argument(name + "/inflow/phase: unknown phase");
            if (!in.centre.allFinite())
                throw std::invalid_argument(name + "/inflow/centre: expected finite numbers (m)");
            if (f.type == BoundaryType::inflow && in.region == InflowRegion::disc &&
                !(std::isfinite(in.radius) && in.radius > 0.0))
                throw std::invalid_argument(name +
                                            "/inflow/radius: a disc inflow needs a radius > 0 (m)");
            if (f.type == BoundaryType::inflow && in.speed > 0.0 && inflow_face.empty())
                inflow_face = name;
        }
    if (!inflow_face.empty() && !open())
        throw std::invalid_argument(
            inflow_face +
            "/inflow/speed: an inflow without an outflow face: the fluid flowing in would have "
            "nowhere to go in a closed box; make another face outflow");
}

double InflowOptions::speed_at(double time) const {
    return pulse == 0.0 ? speed
                        : speed * (1.0 + pulse * std::sin(2.0 * M_PI * pulse_frequency * time));
}

double boundary_normal_velocity(const BoundaryOptions& boundaries, int axis, int side,
                                const Eigen::Vector3d& point, const Eigen::Vector3d& box_min,
                                const Eigen::Vector3d& box_max, double time) {
    return profile_velocity(boundaries, axis, side, point, box_min, box_max, 0.0, time);
}

double face_inflow_velocity(const BoundaryOptions& boundaries, int axis, int side,
                            const Eigen::Vector3d& face_centre, double dx,
                            const Eigen::Vector3d& box_min, const Eigen::Vector3d& box_max,
                            double time) {
    const FaceBoundary& f = boundaries.face(axis, side);
    if (f.type != BoundaryType::inflow || f.inflow.speed == 0.0)
        return 0.0;
    // Where the profile is smooth over the face, its mean over the face in closed form.
    if (f.inflow.region != InflowRegion::disc)
        return profile_velocity(boundaries, axis, side, face_centre, box_min, box_max, dx, time);
    double r2 = 0.0;
    for (int b = 0; b < 3; ++b)
        if (b != axis)
            r2 += (face_centre[b] - f.inflow.centre[b]) * (face_centre[b] - f.inflow.centre[b]);
    const double reach = std::sqrt(0.5) * dx;  // half the face's diagonal
    if (std::abs(std::sqrt(r2) - f.inflow.radius) > reach)
        return profile_velocity(boundaries, axis, side, face_centre, box_min, box_max, dx, time);
    // The disc's rim crosses the face: the mean of sub-samples.
    const int b = (axis + 1) % 3, c = (axis + 2) % 3;
    const double sub = dx / RIM_SUBSAMPLES;
    double sum = 0.0;
    for (int sb = 0; sb < RIM_SUBSAMPLES; ++sb)
        for (int sc = 0; sc < RIM_SUBSAMPLES; ++sc) {
            Eigen::Vector3d x = face_centre;
            x[b] += dx * ((sb + 0.5) / RIM_SUBSAMPLES - 0.5);
            x[c] += dx * ((sc + 0.5) / RIM_SUBSAMPLES - 0.5);
            sum += profile_velocity(boundaries, axis, side, x, box_min, box_max, sub, time);
        }
    return sum / (RIM_SUBSAMPLES * RIM_SUBSAMPLES);
}

void apply_boundary_velocity(MacGrid& grid, const BoundaryOptions& boundaries, double time) {
    const Eigen::Vector3d box_min = grid.origin();
    const Eigen::Vector3d box_max =
        grid.origin() + grid.dx() * Eigen::Vector3d(grid.nx(), grid.ny(), grid.nz());
    for (int axis = 0; axis < 3; ++axis) {
        Array3<double>& faces = grid.velocity(axis);
        for (int side = 0; side < 2; ++side) {
            const BoundaryType type = boundaries.at(axis, side);
            const int inward = side == 0 ? 1 : -1;
            if (type == BoundaryType::periodic) {
                if (side == 1)  // the max face is the min face's copy
                    copy_seam_faces(faces, axis);
                continue;
            }
            for_each_boundary_face(grid, axis, side, [&](int i, int j, int k) {
                if (type == BoundaryType::outflow) {
                    int next[3] = {i, j, k};
                    next[axis] += inward;
                    faces(i, j, k) =
                        grid.cells(axis) > 1 ? faces(next[0], next[1], next[2]) : faces(i, j, k);
                    return;
                }
                faces(i, j, k) = type == BoundaryType::inflow
                                     ? face_inflow_velocity(boundaries, axis, side,
                                                            grid.face_centre(axis, i, j, k),
                                                            grid.dx(), box_min, box_max, time)
                                     : 0.0;
            });
        }
    }
}

double inflow_volume_rate(const MacGrid& grid, const BoundaryOptions& boundaries, int axis,
                          int side, double time) {
    if (boundaries.at(axis, side) != BoundaryType::inflow)
        return 0.0;
    const double area = grid.dx() * grid.dx();
    const Eigen::Vector3d box_min = grid.origin();
    const Eigen::Vector3d box_max =
        grid.origin() + grid.dx() * Eigen::Vector3d(grid.nx(), grid.ny(), grid.nz());
    const double into_box = side == 0 ? 1.0 : -1.0;
    double rate = 0.0;
    for_each_boundary_face(grid, axis, side, [&](int i, int j, int k) {
        rate += into_box * area *
                face_inflow_velocity(boundaries, axis, side, grid.face_centre(axis, i, j, k),
                                     grid.dx(), box_min, box_max, time);
    });
    return rate;
}

double inflow_volume_rate(const MacGrid& grid, const BoundaryOptions& boundaries, double time) {
    double rate = 0.0;
    for (int axis = 0; axis < 3; ++axis)
        for (int side = 0; side < 2; ++side)
            rate += inflow_volume_rate(grid, boundaries, axis, side, time);
    return rate;
}

}  // namespace meniscus::fluid
