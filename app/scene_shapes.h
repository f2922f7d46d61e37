#pragma once
/// \file Shape trees in scene files (/surface/shape, /initial_velocity/N/shape): a JSON object
/// with `type` and that type's keys — sphere, ellipsoid, box, cylinder, perturbed_cylinder,
/// torus, dumbbell, wavy_half_space — or `union`/`intersection` of `shapes`, or `difference`
/// `a` minus `b`; and their tables in the scene reference.

#include "app/json_fields.h"
#include "tracker/implicit_shape.h"

#include <nlohmann/json.hpp>

#include <string>
#include <vector>

namespace meniscus::app {

/// The shape at JSON path `path` (for messages). Throws SceneError naming the path of the first
/// missing, unknown or invalid key.
tracker::ShapePtr parse_shape(const nlohmann::json& j, const std::string& path);

/// Appends the shape tree's tables (one per shape type, with defaults) to the scene reference.
void add_shape_reference(std::vector<ReferenceWriter::Table>& tables);

}  // namespace meniscus::app
