#pragma once
/// \file Part B of `meniscus validate`, the viscosity-dominated cases: B6, the damped l = 2
/// oscillation of a free viscous drop against its exact normal mode, and B7, the creeping rise of
/// a bubble in a free-slip box against Hadamard–Rybczynski with the walls' image correction
/// (references in app/fluid_references.h; derivations in docs/validation.md).

#include "app/validate_fluid_common.h"

#include <sstream>

namespace meniscus::app::validate_fluid {

/// B6: runs, results.json entry "B6" and the report section.
void viscous_drop_case(CaseContext& context, std::ostringstream& md);
/// B7: runs, results.json entry "B7" and the report section.
void creeping_bubble_case(CaseContext& context, std::ostringstream& md);

}  // namespace meniscus::app::validate_fluid
