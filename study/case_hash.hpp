#pragma once
// Identity of a case: a SHA-256 of its canonical resolved parameters plus the engine version
// (docs/study_format.md). Two cases that would compute the same thing get the same hash however their study
// files were written (key order, defaults spelled out or left implicit, group or dimensional
// form), and any change that can alter a result gives a new hash.
#include <nlohmann/json.hpp>
#include <string>

#include "engine/scene.hpp"

namespace crevasse {

// Lower-case hex SHA-256 (FIPS 180-4) of the bytes of `text`.
std::string sha256_hex(const std::string& text);

// What identifies a case: the parts of the resolved scene that decide the result
// (scene_results_json: all but the name and the output part), the resolved measurement
// settings, and the engine version. nlohmann::json keeps object keys sorted, so the dump is
// canonical.
nlohmann::json case_identity(const SceneConfig& scene, const nlohmann::json& measurement_settings,
                             const std::string& engine_version = CREVASSE_ENGINE_VERSION);

// sha256_hex of case_identity(...).dump().
std::string case_hash(const SceneConfig& scene, const nlohmann::json& measurement_settings,
                      const std::string& engine_version = CREVASSE_ENGINE_VERSION);

}  // namespace crevasse
