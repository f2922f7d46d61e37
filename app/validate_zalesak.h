#pragma once
/// \file `meniscus validate` case A6: Zalesak's notched sphere turned once by a rigid rotation
/// (the 3-D version of Zalesak's slotted disk, Enright, Fedkiw, Ferziger & Mitchell, J. Comput.
/// Phys. 183, 2002, scaled to the unit cube), through the collision-safe tracker. After one
/// turn the exact surface is the initial one, so the case measures what the tracker's steps
/// (remeshing, collision handling, RK4) do to a shape with sharp edges: the volume change and
/// the symmetric Hausdorff distance between the final and the initial mesh, at several ξ, with
/// the observed order.

#include "app/validate_run.h"

#include <nlohmann/json.hpp>

#include <functional>
#include <string>
#include <vector>

namespace meniscus::app::flow_validation {

/// The notched sphere: a ball of radius 0.15 centred at (0.5, 0.75, 0.5) minus a slot 0.05
/// wide (in x, centred on the ball) cut from the bottom of the ball (y = 0.6, the side facing
/// the rotation axis) up to a depth of 0.125 (y = 0.725), through the whole ball along z.
inline constexpr double ZALESAK_CENTER[] = {0.5, 0.75, 0.5};
inline constexpr double ZALESAK_RADIUS = 0.15;
inline constexpr double ZALESAK_SLOT_WIDTH = 0.05;
inline constexpr double ZALESAK_SLOT_DEPTH = 0.125;
/// Rigid rotation about the z-parallel axis through (0.5, 0.5): u = −ω(y − 0.5),
/// v = ω(x − 0.5), w = 0, ω = 2π / period: one turn in one period.
inline constexpr double ZALESAK_AXIS_POINT[] = {0.5, 0.5, 0.5};
inline constexpr double ZALESAK_PERIOD = 1.0;  ///< s
/// Time step as a fraction of ξ (s per m): Δt = ξ/2. The farthest point moves 2π·0.4 m per
/// turn, 1.26ξ per step. RK4 turns a point by θ = ωΔt with a phase error of θ⁵/120 of its
/// radius per step: over the turn 8e-7 of the radius at ξ = 0.02 (100 steps), 5e-8 at ξ =
/// 0.005, far below what the remeshing moves.
inline constexpr double ZALESAK_DT_PER_XI = 0.5;
/// The initial mesh has its vertices and edges put onto the slot's sharp edges
/// (CreaseRefinementOptions::snap): meshed without, its triangles cut across them and leave the
/// exact surface by up to 0.39ξ (ξ = 0.02), and what the tracker's first steps do to those
/// chamfers is most of the distance after the turn.
inline constexpr bool ZALESAK_SNAP_CREASES = true;
/// Resolutions ξ (m): the slot is 2.5, 5 and 10 edges wide in full mode.
inline constexpr double ZALESAK_QUICK_XI[] = {0.04, 0.02};
inline constexpr double ZALESAK_FULL_XI[] = {0.02, 0.01, 0.005};

/// The resolutions A6 runs in quick or full mode.
std::vector<double> zalesak_xis(bool full);

/// The notched sphere (ZALESAK_* above) as an implicit shape.
tracker::ShapePtr zalesak_shape();

/// Runs A6 at each ξ of zalesak_xis(full) for which `runs_xi(ξ)` holds and hands each run's
/// JSON (run_json plus "period", "volume_change_percent", "hausdorff" …) and result to `add`.
void run_zalesak(bool full, bool quiet, const std::function<bool(double)>& runs_xi,
                 const std::function<void(nlohmann::json, const RunResult&)>& add);

/// The report's A6 section from results["runs"]; adds the observed orders to
/// results["orders"]["A6 …"].
std::string zalesak_report(nlohmann::json& results);

}  // namespace meniscus::app::flow_validation
