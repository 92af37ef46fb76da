#pragma once
// Reading a scene file for `crevasse run` (and the scene fuzzer): whatever the bytes, the result
// is a resolved scene or an InputError naming the file or the field, never another exception.
#include <cstdint>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>

#include "engine/scene.hpp"

namespace crevasse {

// Scene files larger than this are refused before they are read (a scene is a few kB).
inline constexpr std::uintmax_t kMaxInputFileBytes = 16u << 20;

// The text of a regular input file of at most kMaxInputFileBytes; `field` names it in messages
// ("scene", "base_scene", "study file"). Devices, FIFOs and directories are refused, so that a
// path such as /dev/zero cannot make a loader read forever.
std::string read_input_file(const std::filesystem::path& path, const std::string& field);

// Refusals beyond scene_from_json (which has validated types and ranges): fields the engine
// would silently ignore (velocity_boxes without the 'velocity_boundaries' effect and the
// effect without boxes, domain.min/max for a slab, domain.wall_axes without 'box_walls' and the
// effect without axes, a non-zero bed.z for a bed that is not flat) and coordinates without a
// range of their own (domain and velocity-box corners within 1e6 cells of 0, velocity-box
// velocities within ±1000 m/s, a flat bed.z between the domain's bottom and the ice box's
// bottom). `j` is the scene's JSON, `s` what scene_from_json made of it. Throws InputError.
void check_scene_json(const nlohmann::json& j, const SceneConfig& s);

// JSON text → resolved scene, checked by scene_from_json and check_scene_json; `source` names
// the text in messages.
SceneConfig parse_scene_text(const std::string& text, const std::string& source);
SceneConfig load_scene_file(const std::filesystem::path& path);

}  // namespace crevasse
