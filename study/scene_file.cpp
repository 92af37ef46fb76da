#include "study/scene_file.hpp"

#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "engine/error.hpp"
#include "study/json_checks.hpp"

namespace crevasse {
namespace {

std::string fmt(double v) {
  std::ostringstream o;
  o << v;
  return o.str();
}

[[noreturn]] void refuse(const std::string& field, const std::string& what) {
  throw InputError(field + ": " + what + " (see docs/scene_format.md)");
}

void check_range(const std::string& field, double v, double lo, double hi) {
  if (!(v >= lo && v <= hi))
    refuse(field, "value " + fmt(v) + " is outside the allowed range [" + fmt(lo) + ", " + fmt(hi) + "]");
}

// "[a]": built by appending, because g++ 12 warns falsely (-Wrestrict) on "[" + to_string(a).
std::string index_suffix(long a) {
  std::string out = "[";
  out += std::to_string(a);
  out += ']';
  return out;
}

// A key given with a non-null value (ObjectReader treats null as absent).
bool given(const nlohmann::json& j, const char* section, const char* key) {
  if (!j.is_object() || !j.contains(section)) return false;
  const auto& o = j.at(section);
  return o.is_object() && o.contains(key) && !o.at(key).is_null();
}

}  // namespace

void check_scene_json(const nlohmann::json& j, const SceneConfig& s) {
  const int z = s.dim - 1;
  const std::string axis_z = index_suffix(z);
  // Fields the engine would ignore without a word.
  if (!s.velocity_boxes.empty() && !s.has(Effect::velocity_boundaries))
    refuse("velocity_boxes", std::to_string(s.velocity_boxes.size()) +
                                 " box(es) given but effects does not list 'velocity_boundaries', so "
                                 "they would be ignored; add the effect or remove the boxes");
  if (s.has(Effect::velocity_boundaries) && s.velocity_boxes.empty())
    refuse("effects", "'velocity_boundaries' needs at least one entry in velocity_boxes");
  if (s.body == Body::slab) {
    for (const char* key : {"min", "max"})
      if (given(j, "domain", key))
        refuse(std::string("domain.") + key,
               "allowed with ice.body 'box' only; a slab's domain is derived from ice and bed "
               "(remove domain.min and domain.max)");
  }
  if (!s.wall_axes.empty() && !s.has(Effect::box_walls))
    refuse("domain.wall_axes", "given but effects does not list 'box_walls', so the walls would be "
                               "ignored; add the effect or remove wall_axes");
  if (s.has(Effect::box_walls) && s.wall_axes.empty())
    refuse("effects", "'box_walls' needs at least one axis in domain.wall_axes");
  if (s.bed_shape != BedShape::flat && given(j, "bed", "z") && s.flat_bed_z != 0.0)
    refuse("bed.z", "value " + fmt(s.flat_bed_z) + " given for bed.shape '" + kind_name(s.bed_shape) +
                        "'; bed.z applies to bed.shape 'flat' only (remove it)");

  // Coordinates without a range check in the engine's loader. Lattice indices are ints: every
  // coordinate stays within 1e6 cells of 0, the limit resolve() puts on a domain's extent.
  const double reach = 1e6 * s.dx;
  if (s.body == Body::box) {
    for (int a = 0; a < s.dim; ++a) {
      check_range("domain.min[" + std::to_string(a) + "]", s.domain_min[a], -reach, reach);
      check_range("domain.max[" + std::to_string(a) + "]", s.domain_max[a], -reach, reach);
    }
  }
  if (s.bed_shape == BedShape::flat) {
    // The flat bed lies inside the domain and under the ice, not through it.
    const double top = s.body == Body::box ? s.box_min[z] : s.domain_max[z];
    check_range("bed.z", s.flat_bed_z, s.domain_min[z], top);
  }
  for (std::size_t i = 0; i < s.velocity_boxes.size(); ++i) {
    const auto& b = s.velocity_boxes[i];
    const std::string f = "velocity_boxes[" + std::to_string(i) + "].";
    for (int a = 0; a < s.dim; ++a) {
      const std::string ax = index_suffix(a);
      check_range(f + "min" + ax, b.min[a], -reach, reach);
      check_range(f + "max" + ax, b.max[a], -reach, reach);
      check_range(f + "velocity" + ax, b.velocity[a], -1e3, 1e3);
    }
  }
}

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
  SceneConfig scene = scene_from_json(j);
  check_scene_json(j, scene);
  return scene;
}

SceneConfig load_scene_file(const std::filesystem::path& path) {
  return parse_scene_text(read_input_file(path, "scene"), path.string());
}

}  // namespace crevasse
