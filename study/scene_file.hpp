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

// JSON text → resolved scene (scene_from_json, with all its checks); `source` names
// the text in messages.
SceneConfig parse_scene_text(const std::string& text, const std::string& source);
SceneConfig load_scene_file(const std::filesystem::path& path);

}  // namespace crevasse
