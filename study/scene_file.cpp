#include "study/scene_file.hpp"

#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "engine/error.hpp"
#include "engine/json_input.hpp"

namespace crevasse {

std::string read_input_file(const std::filesystem::path& path, const std::string& field) {
  namespace fs = std::filesystem;
  std::error_code ec;
  const fs::file_status st = fs::status(path, ec);
  if (ec || !fs::exists(st))
    throw InputError(field + ": cannot open '" + path.string() + "' (no such file)");
  if (!fs::is_regular_file(st))
    throw InputError(field + ": '" + path.string() + "' is not a regular file");
  const std::uintmax_t size = fs::file_size(path, ec);
  if (ec || size > kMaxInputFileBytes)
    throw InputError(field + ": '" + path.string() + "' is larger than " +
                     std::to_string(kMaxInputFileBytes >> 20) + " MiB; not an input file");
  std::ifstream f(path, std::ios::binary);
  if (!f) throw InputError(field + ": cannot open '" + path.string() + "'");
  std::ostringstream s;
  s << f.rdbuf();
  return s.str();
}

SceneConfig parse_scene_text(const std::string& text, const std::string& source) {
  const nlohmann::json j = parse_json_input<nlohmann::json>(text, source);
  return scene_from_json(j);
}

SceneConfig load_scene_file(const std::filesystem::path& path) {
  return parse_scene_text(read_input_file(path, "scene"), path.string());
}

}  // namespace crevasse
