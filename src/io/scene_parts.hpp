// The parts of a scene file, read into a Model (internal to src/io: scene.cpp reads the file
// and its stages, scene_bodies.cpp the walls, balls and clumps, scene_history.cpp the history
// columns). Every error names the file, the key, the value and the allowed range.
#pragma once

#include "io/scene.hpp"

#include <cstdint>
#include <string>

namespace rocklab::scene_detail {

/// DOF names ("x", "y", "z", "rx", "ry", "rz" or "all"; 2D: "x", "y", "rz") under `key`, as
/// fixity bits; 0 if the key is absent.
std::uint8_t parse_dofs(JsonObject& o, const std::string& key, int dim);
/// The DOFs of a "fix" key.
std::uint8_t parse_fixity(JsonObject& o, int dim);
void read_walls(JsonObject& top, Model& m);
/// Balls, generated balls and clumps (ids unique across all three).
void read_balls(JsonObject& top, Model& m);
void read_history(JsonObject& top, Scene& s);

} // namespace rocklab::scene_detail
