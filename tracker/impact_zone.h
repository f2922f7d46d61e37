#pragma once
/// \file One impact zone's inelastic projection (Harmon et al. 2008, paper §3.8), the inner
/// solve of collision resolution (collision_resolution.h): contacts between groups of four
/// vertices, each a linear constraint on the displacements, and the smallest mass-weighted
/// change of the displacements that meets them all.

#include "tracker/collision_resolution.h"
#include "tracker/mesh.h"

#include <array>
#include <vector>

namespace meniscus::tracker {

/// One possible contact between four vertices with weights ā (Σ āᵢ xᵢ = separation vector) and
/// a unit normal n: the constraint row is āᵢ nᵀ per vertex.
struct Contact {
    std::array<int, 4> vertices;
    std::array<double, 4> weights;
    Vec3 normal;
    double target = 0.0;     ///< desired n · Σ āᵢ dᵢ (relative normal displacement), metres
    bool edge_edge = false;  ///< edge–edge (vertices a0, a1, b0, b1), else point–triangle
};

/// n · Σ āᵢ dᵢ: the contact's relative normal displacement under displacements `d`.
double relative_normal_displacement(const Contact& c, const std::vector<Vec3>& d);

/// Projects the displacements `d` (one per vertex slot) of the zone made of the contacts
/// `rows` (indices into `constraints`): min ½‖Δd‖²_M subject to every row's relative normal
/// displacement reaching its target, with inverse masses `inv_mass` (0: pinned). Updates
/// report.largest_impact_zone, and report.oversized_zone_solves when the zone's matrix would
/// exceed `max_zone_matrix_entries` (the zone is then left for the caller's fallback).
/// Rows may stay unmet when the solve runs out of rounds; the caller detects again.
void project_impact_zone(const std::vector<Contact>& constraints, const std::vector<int>& rows,
                         const std::vector<double>& inv_mass, int max_zone_matrix_entries,
                         std::vector<Vec3>& d, CollisionReport& report);

}  // namespace meniscus::tracker
