#pragma once
/// \file Boundary conditions of the six faces of the fluid box.
///
/// Each face of the box is one of
/// - a wall: `free_slip` (no normal flow, no shear stress) or `no_slip` (no normal flow, the fluid
///   sticks to it; the wall may slide along itself with FaceBoundary::velocity: a moving wall);
/// - an `inflow`: a normal velocity prescribed over a region of the face (the whole face or a
///   disc: a nozzle), uniform or parabolic; the fluid sticks to the face (no tangential velocity)
///   and the rest of the face is a no-slip wall;
/// - an `outflow`: the pressure fixed on the face (FaceBoundary::pressure), the velocity of zero
///   normal gradient (the normal face velocity is an unknown of the projection; the tangential
///   velocity feels no shear from the face);
/// - `periodic`, on both faces of an axis: what leaves through one face enters through the other.
///   The grid face on the min side is the unknown and the one on the max side its copy
///   (apply_boundary_velocity() keeps them equal); cell n−1 and cell 0 are neighbours across it.
///   Every grid operator wraps around them: the pressure projection (PoissonMatrix::periodic and
///   its MIC(0), multigrid and Eigen solvers), viscosity, gravity, advection, sampling and
///   extrapolation (MacGrid::periodic()). The surface mesh does not wrap yet, so a coupled
///   Simulation refuses them (issue 39).
/// On the MAC grid the normal velocity of a face lives on the boundary faces of the grid (see
/// mac_grid.h); walls and inflows set it, outflows leave it to the pressure projection.

#include <Eigen/Core>

#include "fluid/mac_grid.h"

namespace meniscus::fluid {

/// What a face of the box is (see the file comment).
enum class BoundaryType { free_slip, no_slip, inflow, outflow, periodic };

/// The scene name of `type` ("free_slip", ...).
const char* boundary_type_name(BoundaryType type);

/// Profile of an inflow's normal speed over its region.
enum class InflowProfile {
    uniform,  ///< the same speed everywhere in the region
    /// zero on the region's rim where it meets a wall or inflow and maximal in its middle (the
    /// developed laminar profile): over a disc 2U(1 − r²/R²); over the whole face the product of
    /// 3/2 (1 − s²) across each in-plane axis bounded by walls on both sides (s ∈ [−1, 1] across
    /// it), uniform across an axis with a free-slip or outflow face. U is the mean speed.
    parabolic
};

/// Which part of the face an inflow covers.
enum class InflowRegion {
    face,  ///< the whole face
    disc   ///< a disc of InflowOptions::radius around InflowOptions::centre (a nozzle)
};

/// What enters through an inflow (for the interface; the fluid step does not depend on it).
enum class InflowPhase { liquid, gas };

/// An inflow's region and speed.
struct InflowOptions {
    double speed = 0.0;  ///< mean normal speed into the box over the region, m/s (≥ 0)
    /// Relative amplitude ε of a sinusoidal modulation of the speed, speed·(1 + ε sin 2πft), in
    /// [0, 1) (0: steady): a forced jet, as Rayleigh's and most breakup experiments are run.
    double pulse = 0.0;
    double pulse_frequency = 0.0;  ///< f, Hz (> 0 when pulse > 0)
    InflowProfile profile = InflowProfile::uniform;
    InflowRegion region = InflowRegion::face;
    /// disc: centre (m); its coordinate along the face's normal is ignored.
    Eigen::Vector3d centre = Eigen::Vector3d::Zero();
    double radius = 0.0;  ///< disc: radius (m, > 0)
    InflowPhase phase = InflowPhase::liquid;

    /// The mean speed over the region at `time` (s): speed·(1 + pulse·sin 2π pulse_frequency t).
    double speed_at(double time) const;
};

/// The condition on one face of the box.
struct FaceBoundary {
    BoundaryType type = BoundaryType::free_slip;
    /// no_slip: the wall's velocity along itself (m/s; its normal component must be 0).
    Eigen::Vector3d velocity = Eigen::Vector3d::Zero();
    InflowOptions inflow;   ///< inflow: region, profile and speed
    double pressure = 0.0;  ///< outflow: the pressure on the face (Pa)
};

/// The six faces of the box.
struct BoundaryOptions {
    FaceBoundary x_min;
    FaceBoundary x_max;
    FaceBoundary y_min;
    FaceBoundary y_max;
    FaceBoundary z_min;
    FaceBoundary z_max;

    /// Face on `axis` (0..2) at `side` (0 = min, 1 = max). Throws std::invalid_argument otherwise.
    FaceBoundary& face(int axis, int side);
    const FaceBoundary& face(int axis, int side) const;
    /// The type of face(axis, side).
    BoundaryType at(int axis, int side) const { return face(axis, side).type; }
    /// True if any wall slides along itself.
    bool moving() const;
    /// True if any face is of `type`.
    bool has(BoundaryType type) const;
    /// True if any face is an outflow (the pressure is then fixed somewhere: no null space).
    bool open() const { return has(BoundaryType::outflow); }
    /// True if any face is an inflow.
    bool inflow() const { return has(BoundaryType::inflow); }
    /// True if the faces of `axis` are periodic (validate() checks that both are).
    bool periodic(int axis) const { return at(axis, 0) == BoundaryType::periodic; }
    /// The same faces with homogeneous data: walls at rest, inflows at zero speed, outflows at
    /// zero pressure (for the solves of velocity and pressure increments).
    BoundaryOptions at_rest() const;
    /// All six faces of `type` (a wall type), at rest.
    static BoundaryOptions all(BoundaryType type);
    /// Throws std::invalid_argument naming the field ("x_min/inflow/radius", ...) if an enum
    /// holds an unknown value, a number is not finite or out of range, a velocity has a normal
    /// component or belongs to a face that is not a no-slip wall, a periodic face is paired with
    /// a face that is not periodic, or liquid flows in through an inflow of a box with no outflow
    /// face (it would have nowhere to go).
    void validate() const;
};

/// Normal velocity (m/s, along +axis) that face (axis, side) prescribes at `point` (m) on it, for
/// a box [box_min, box_max]: the inflow profile inside an inflow's region (into the box), 0 on
/// walls and outside the region. Undefined (0) for an outflow face, whose velocity is not
/// prescribed.
double boundary_normal_velocity(const BoundaryOptions& boundaries, int axis, int side,
                                const Eigen::Vector3d& point, const Eigen::Vector3d& box_min,
                                const Eigen::Vector3d& box_max, double time = 0.0);

/// The velocity (m/s, along +axis) of the grid face of edge `dx` centred at `face_centre` on face
/// (axis, side): the mean of boundary_normal_velocity() over the face — in closed form where the
/// profile is smooth there, of 8 × 8 sub-samples where a disc inflow's rim crosses the face — so
/// the faces carry the inflow's flux speed × area, not that of the staircase of face centres
/// inside a disc (+13 % at R = 3 cells) or of the parabola's midpoint rule.
double face_inflow_velocity(const BoundaryOptions& boundaries, int axis, int side,
                            const Eigen::Vector3d& face_centre, double dx,
                            const Eigen::Vector3d& box_min, const Eigen::Vector3d& box_max,
                            double time = 0.0);

/// Sets the normal velocity on every boundary face of `grid`: walls 0, inflows their profile
/// (face_inflow_velocity()), outflows the velocity of the interior face next to them (zero
/// normal gradient), the max face of a periodic pair that of the min face (the same face).
/// `time` (s) is that of the velocities (a pulsed inflow's phase).
void apply_boundary_velocity(MacGrid& grid, const BoundaryOptions& boundaries, double time = 0.0);

/// Volume flux (m³/s) into the box through the inflow faces of `grid` as apply_boundary_velocity()
/// sets them (the sum of face velocity × face area over the inflow faces).
double inflow_volume_rate(const MacGrid& grid, const BoundaryOptions& boundaries,
                          double time = 0.0);
/// The same through face (axis, side) alone (0 unless it is an inflow).
double inflow_volume_rate(const MacGrid& grid, const BoundaryOptions& boundaries, int axis,
                          int side, double time = 0.0);

}  // namespace meniscus::fluid
