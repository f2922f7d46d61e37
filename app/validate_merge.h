#pragma once
/// \file Part B of `meniscus validate`, B5: the shipped merge and pinch scenes (drops and bubbles
/// merging, a jet pinching off) — no intersecting triangles, each phase's volume kept, the
/// expected topology change — and the convergence of that change's time in Δt and in Δx.

#include "app/validate_fluid_common.h"

#include <sstream>

namespace meniscus::app::validate_fluid {

/// B5: runs, results.json entry "B5" and the report section.
void merge_scenes_case(CaseContext& context, std::ostringstream& md);

}  // namespace meniscus::app::validate_fluid
