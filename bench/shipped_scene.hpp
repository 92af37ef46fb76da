#pragma once
// A shipped scene file (studies/scenes/) as JSON, VTU output off, so a benchmark can run a real
// glacier. The source folder comes from the CREVASSE_SOURCE_DIR compile definition
// (bench/CMakeLists.txt).
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

namespace crevasse::bench {

inline nlohmann::json shipped_scene_json(const std::string& file) {
  std::ifstream f(std::string(CREVASSE_SOURCE_DIR) + "/studies/scenes/" + file);
  nlohmann::json j = nlohmann::json::parse(f);
  j["output"]["vtu_interval"] = 0.0;
  return j;
}

}  // namespace crevasse::bench
