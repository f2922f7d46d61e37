#pragma once
/// \file The scene file's schema: every plain field of every section (name, type, range, unit,
/// meaning, and its default in the options struct it fills), written once as a visitor over the
/// Scene, read by JsonReader (parse_scene()) and described by ReferenceWriter
/// (`meniscus scene-reference`). The surface's shape tree and /initial_velocity are parsed apart
/// (scene_shapes.h, scene.cpp); the checks that compare fields are parse_scene()'s.

#include "app/json_fields.h"
#include "app/scene.h"

namespace meniscus::app {

/// Reads every plain field of `scene` that the JSON under `reader` gives (SceneError naming the
/// JSON path for a wrong type or a value out of range). Unknown keys are reported by
/// reader.finish().
void read_scene_fields(JsonReader& reader, Scene& scene);

/// Describes the same fields into `writer`, with the values of `defaults` as the defaults.
void describe_scene_fields(ReferenceWriter& writer, Scene& defaults);

}  // namespace meniscus::app
