#pragma once
// The resolution study's scene of issue 36, shared by bench_coupling and bench_distributed: two
// 1.5 mm air bubbles in water (density ratio 1000, μ and σ of water, gravity), 0.3 mm apart and
// pushed towards each other as in bubble_merge, in a 1 cm cube of `cells`³ cells.

#include <string>

#include "app/scene.h"

namespace meniscus::bench {

/// `fluid_extra`: more keys of /fluid, as JSON members (e.g. `"pressure_solver": "..."`).
inline app::Scene bubble_pair_cube(int cells, const std::string& fluid_extra = "") {
    const std::string json = R"({
      "name": "bench_bubble_pair_cube",
      "flow": {"type": "fluid"},
      "domain": {"min": [0, 0, 0], "size": [0.01, 0.01, 0.01], "cells": )" +
                             std::to_string(cells) + R"(},
      "fluid": {"gravity": [0, 0, -9.81], "mode": "two_phase")" +
                             (fluid_extra.empty() ? "" : ", " + fluid_extra) + R"(},
      "coupling": {"edge_length_cells": 1.0, "volume_correction": true, "curvature_smoothing": 1},
      "tracker": {"topology": {"merge_distance_fraction": 0.5}},
      "surface": {"inside": "gas", "shape": {"type": "union", "shapes": [
        {"type": "sphere", "center": [0.00335, 0.005, 0.004], "radius": 0.0015},
        {"type": "sphere", "center": [0.00665, 0.005, 0.004], "radius": 0.0015}]}},
      "initial_velocity": [
        {"shape": {"type": "sphere", "center": [0.00335, 0.005, 0.004], "radius": 0.0015},
         "velocity": [0.05, 0, 0]},
        {"shape": {"type": "sphere", "center": [0.00665, 0.005, 0.004], "radius": 0.0015},
         "velocity": [-0.05, 0, 0]}],
      "time": {"end": 0.01, "frames": 1}
    })";
    return app::parse_scene(json, "bench/bubble_pair_cube.h", ".");
}

}  // namespace meniscus::bench
