#include "engine/groups.hpp"
#include "study/study_file.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <map>
#include <set>
#include <sstream>

#include "analysis/crevasse_measure.hpp"
#include "engine/error.hpp"
#include "engine/json_input.hpp"
#include "study/case_hash.hpp"
#include "study/scene_file.hpp"

namespace crevasse {
namespace {

using nlohmann::json;
using nlohmann::ordered_json;

constexpr std::size_t kMaxCases = 100000;

// Allowed range of each named study parameter.
std::optional<Range> named_range(const std::string& name) {
  static const std::map<std::string, Range> ranges = {
      {"thickness", {0.0, 1e5, true, false}},
      {"cohesion_ratio", {0.0, 1e4, true, false}},
      {"shear_strength_ratio", {0.0, 1e4, true, false}},
      {"shear_to_tensile_ratio", {0.0, 1e4, true, false}},
      {"draped_length_ratio", {0.0, 1e3, false, false}},
      {"gate_offset_ratio", {0.0, 1e3, false, false}},
      {"step_length_ratio", {0.0, 1e3, false, false}},
      {"slope", {0.0, 1e3, true, false}},
      {"step_height_ratio", {0.0, 1e3, false, false}},
      {"width_ratio", {0.0, 1e3, true, false}},
      {"cells_per_thickness", {4.0, 1e4, false, false}},
      {"front_past_step_ratio", {0.0, 1e3, true, false}},
      {"gate_length_ratio", {0.0, 1e3, true, false}},
      {"upstream_length_ratio", {0.0, 1e3, true, false}},
      {"downstream_length_ratio", {0.0, 1e3, true, false}},
  };
  const auto it = ranges.find(name);
  if (it == ranges.end()) return std::nullopt;
  return it->second;
}

// The scene field each named parameter sets: giving both is ambiguous.
const std::map<std::string, std::string>& named_targets() {
  static const std::map<std::string, std::string> t = {
      {"thickness", "/ice/thickness"},
      {"cohesion_ratio", "/ice/tensile_strength"},
      {"shear_strength_ratio", "/ice/shear_strength"},
      {"shear_to_tensile_ratio", "/ice/shear_strength"},
      {"draped_length_ratio", "/ice/draped_length"},
      {"gate_offset_ratio", "/run/gate_offset"},
      {"step_length_ratio", "/bed/step_length"},
      {"slope", "/bed/step_height"},
      {"step_height_ratio", "/bed/step_height"},
      {"width_ratio", "/ice/width"},
      {"cells_per_thickness", "/numerics/dx"},
      {"front_past_step_ratio", "/run/front_past_step"},
      {"gate_length_ratio", "/run/gate_length"},
      {"upstream_length_ratio", "/ice/upstream_length"},
      {"downstream_length_ratio", "/bed/downstream_length"},
  };
  return t;
}

std::string allowed_names() {
  return name_list({std::begin(kStudyParameterNames), std::end(kStudyParameterNames)}) +
         " or a JSON pointer into the scene such as /ice/density";
}

bool is_pointer(const std::string& name) { return !name.empty() && name[0] == '/'; }

// A pointer must name a field of the scene format (docs/scene_format.md): it must exist in the
// canonical form of a default scene, or lie inside an array or one of the optional sections.
void check_pointer(const std::string& field, const std::string& ptr) {
  json::json_pointer p;
  try {
    p = json::json_pointer(ptr);
  } catch (const json::exception& e) {
    fail(field, "'" + ptr + "' is not a valid JSON pointer (" + e.what() + ")");
  }
  static const json reference = scene_reference_json();
  // Array indices: setting element 10^11 would allocate every element before it.
  std::istringstream all(ptr.substr(1));
  for (std::string t; std::getline(all, t, '/');)
    if (!t.empty() &&
        std::all_of(t.begin(), t.end(), [](char c) { return c >= '0' && c <= '9'; }) &&
        (t.size() > 4 || std::stoi(t) > 1000))
      fail(field, "'" + ptr + "': array index " + t + " is outside the allowed range [0, 1000]");
  const json* node = &reference;
  std::string walked;
  std::istringstream tokens(ptr.substr(1));
  std::string token;
  bool first = true;
  while (std::getline(tokens, token, '/')) {
    if (first && (token == "domain" || token == "velocity_boxes")) return;  // checked by the scene
    first = false;
    if (node->is_array()) return;  // array elements are checked by the scene reader
    if (!node->is_object() || !node->contains(token))
      fail(field, "'" + ptr + "' is not a scene parameter (no '" + token + "' under '" +
                      (walked.empty() ? "/" : walked) + "'; see docs/scene_format.md)");
    node = &node->at(token);
    walked += "/" + token;
  }
  if (walked.empty()) fail(field, "the pointer '/' would replace the whole scene; name a field");
}

void check_name(const std::string& field, const std::string& name) {
  if (is_pointer(name)) {
    check_pointer(field, name);
    return;
  }
  if (!named_range(name))
    fail(field, "unknown parameter '" + name + "' (allowed: " + allowed_names() + ")");
}

// A value given for a named parameter must be a number in its range.
void check_value(const std::string& field, const std::string& name, const json& v) {
  if (is_pointer(name)) return;  // the scene reader checks type and range
  if (!v.is_number()) fail(field, "must be a number, got " + v.dump());
  check_range(field, v.get<double>(), *named_range(name));
}

double round_12(double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.12g", v);
  return std::strtod(buf, nullptr);
}

std::string value_label(const json& v) {
  if (v.is_number_integer()) return std::to_string(v.get<std::int64_t>());
  if (v.is_number()) {
    char buf[64];
    std::snprintf(buf, sizeof buf, "%.6g", v.get<double>());
    return buf;
  }
  if (v.is_string()) return v.get<std::string>();
  return v.dump();
}

double number_at(const json& j, const std::string& ptr, double fallback) {
  const json::json_pointer p(ptr);
  if (j.contains(p) && j.at(p).is_number()) return j.at(p).get<double>();
  return fallback;
}

json read_json_text(const std::string& text, const std::string& source) {
  return parse_json_input<json>(text, source);
}

std::string read_text(const std::filesystem::path& path, const std::string& field) {
  return read_input_file(path, field);
}

int integer_in(const ordered_json& v, const std::string& field, int lo, int hi) {
  if (!v.is_number_integer()) fail(field, "must be an integer, got " + v.dump());
  const auto x = v.get<std::int64_t>();
  if (x < lo || x > hi)
    fail(field, "value " + std::to_string(x) + " is outside the allowed range [" +
                    std::to_string(lo) + ", " + std::to_string(hi) + "]");
  return static_cast<int>(x);
}

double number_in(const ordered_json& v, const std::string& field, const Range& r) {
  if (!v.is_number()) fail(field, "must be a number, got " + v.dump());
  const double x = v.get<double>();
  check_range(field, x, r);
  return x;
}

// The groups of a resolved scene (docs/model.md).
CaseGroups groups_of(const SceneConfig& s) {
  CaseGroups g;
  g.thickness_m = s.ice_thickness;
  const double pi = cohesion_ratio(s.tensile_strength, s.density, s.gravity, s.ice_thickness);
  g.cohesion_ratio = std::isfinite(pi) ? pi : 0.0;  // no overburden (g = 0): no Π
  g.step_length_ratio = s.step_length / s.ice_thickness;
  g.step_height_ratio = s.step_height / s.ice_thickness;
  if (s.step_length > 0) g.slope = s.step_height / s.step_length;
  if (s.dim == 3) g.width_ratio = s.width / s.ice_thickness;
  return g;
}

}  // namespace

std::vector<json> expand_axis(const json& spec, const std::string& field) {
  if (spec.is_array()) {
    if (spec.empty()) fail(field, "an empty list gives no cases; list at least one value");
    return std::vector<json>(spec.begin(), spec.end());
  }
  if (!spec.is_object() || spec.size() != 1 || !(spec.contains("linear") || spec.contains("log")))
    fail(field, "must be a list of values, {\"linear\": [a, b, n]} or {\"log\": [a, b, n]}, got " +
                    spec.dump());
  const bool log = spec.contains("log");
  const std::string kind = log ? "log" : "linear";
  const json& r = spec.at(kind);
  const std::string f = field + "." + kind;
  if (!r.is_array() || r.size() != 3 || !r[0].is_number() || !r[1].is_number())
    fail(f, "must be [first, last, count] with two numbers and an integer, got " + r.dump());
  if (!r[2].is_number_integer()) fail(f, "count must be an integer, got " + r[2].dump());
  const double a = r[0].get<double>(), b = r[1].get<double>();
  const auto n = r[2].get<std::int64_t>();
  if (!std::isfinite(a) || !std::isfinite(b)) fail(f, "bounds must be finite");
  if (n < 1 || n > 10000)
    fail(f, "count " + std::to_string(n) + " is outside the allowed range [1, 10000]");
  if (n == 1 && a != b) fail(f, "count 1 needs first == last (" + input_number(a) + " ≠ " + input_number(b) + ")");
  if (log && (a <= 0 || b <= 0))
    fail(f, "bound " + input_number(a <= 0 ? a : b) +
                " is not allowed: log ranges need both bounds in (0, inf)");
  std::vector<json> out;
  for (std::int64_t i = 0; i < n; ++i) {
    const double t = n == 1 ? 0.0 : static_cast<double>(i) / static_cast<double>(n - 1);
    double v = log ? std::exp(std::log(a) + t * (std::log(b) - std::log(a))) : a + t * (b - a);
    if (i == 0) v = a;
    if (i == n - 1) v = b;
    out.emplace_back(round_12(v));
  }
  return out;
}

analysis::MeasureSettings measure_settings_from_json(const json& j) {
  analysis::MeasureSettings s;
  if (j.is_null()) return s;
  if (!j.is_object()) fail("measurement", "must be an object");
  const ordered_json o = j;
  refuse_unknown_keys(o, "measurement",
                 {"frame", "damage_threshold", "eps_v_p_threshold", "window_min_x_m", "window_max_x_m",
                  "window_margin_over_h", "resolution_floor_over_dx", "spacing_rule", "count_gaps", "split_under_skin", "min_depth_over_dx", "link_distance_over_spacing",
                  "surface_reach_over_dx", "surface_smoothing_bins",
                  "surface_bridge_half_width_over_h", "fragmented_fraction", "y_band_width_over_dx",
                  "y_band_center_m", "dx_m", "ice_thickness_m", "particle_spacing_m"});
  auto num = [&](const char* key, double& out, const Range& r) {
    if (o.contains(key)) out = number_in(o.at(key), std::string("measurement.") + key, r);
  };
  auto opt = [&](const char* key, std::optional<double>& out, const Range& r) {
    if (o.contains(key) && !o.at(key).is_null())
      out = number_in(o.at(key), std::string("measurement.") + key, r);
  };
  if (o.contains("frame")) {
    const auto& f = o.at("frame");
    if (!f.is_string() || !analysis::is_measure_frame(f.get<std::string>()))
      fail("measurement.frame", "value " + f.dump() + " is not " + analysis::measure_frame_names());
    s.frame = f.get<std::string>();
  }
  num("damage_threshold", s.damage_threshold, {0.0, 1.0, true, true});
  num("eps_v_p_threshold", s.eps_v_p_threshold, {0.0, 10.0, true, false});
  opt("window_min_x_m", s.window_min_x_m, {-1e9, 1e9, false, false});
  opt("window_max_x_m", s.window_max_x_m, {-1e9, 1e9, false, false});
  if (s.window_min_x_m && s.window_max_x_m && *s.window_max_x_m <= *s.window_min_x_m)
    fail("measurement.window_max_x_m", "value " + input_number(*s.window_max_x_m) +
                                           " must exceed window_min_x_m " + input_number(*s.window_min_x_m));
  num("window_margin_over_h", s.window_margin_over_h, {0.0, 100.0, false, false});
  num("resolution_floor_over_dx", s.resolution_floor_over_dx, {0.0, 100.0, false, false});
  if (o.contains("spacing_rule")) {
    const auto& f = o.at("spacing_rule");
    if (!f.is_string() || (f != "merge" && f != "drop"))
      fail("measurement.spacing_rule", "value " + f.dump() + " is not \"merge\" or \"drop\"");
    s.spacing_rule = f.get<std::string>();
  }
  if (o.contains("count_gaps")) {
    if (!o.at("count_gaps").is_boolean())
      fail("measurement.count_gaps", "value " + o.at("count_gaps").dump() + " is not true or false");
    s.count_gaps = o.at("count_gaps").get<bool>();
  }
  if (o.contains("split_under_skin")) {
    if (!o.at("split_under_skin").is_boolean())
      fail("measurement.split_under_skin",
           "value " + o.at("split_under_skin").dump() + " is not true or false");
    s.split_under_skin = o.at("split_under_skin").get<bool>();
  }
  num("min_depth_over_dx", s.min_depth_over_dx, {0.0, 100.0, false, false});
  num("link_distance_over_spacing", s.link_distance_over_spacing, {0.0, 10.0, true, false});
  num("surface_reach_over_dx", s.surface_reach_over_dx, {0.0, 100.0, true, false});
  if (o.contains("surface_smoothing_bins")) {
    s.surface_smoothing_bins =
        integer_in(o.at("surface_smoothing_bins"), "measurement.surface_smoothing_bins", 1, 101);
    if (s.surface_smoothing_bins % 2 == 0)
      fail("measurement.surface_smoothing_bins",
           "value " + std::to_string(s.surface_smoothing_bins) + " must be odd");
  }
  num("surface_bridge_half_width_over_h", s.surface_bridge_half_width_over_h,
      {0.0, 1.0, false, false});
  num("fragmented_fraction", s.fragmented_fraction, {0.0, 1.0, true, false});
  num("y_band_width_over_dx", s.y_band_width_over_dx, {0.0, 1e4, true, false});
  opt("y_band_center_m", s.y_band_center_m, {-1e9, 1e9, false, false});
  opt("dx_m", s.dx_m, {0.0, 1e4, true, false});
  opt("ice_thickness_m", s.ice_thickness_m, {0.0, 1e5, true, false});
  opt("particle_spacing_m", s.particle_spacing_m, {0.0, 1e4, true, false});
  return s;
}

json measure_settings_to_json(const analysis::MeasureSettings& s) {
  auto opt = [](const std::optional<double>& v) { return v ? json(*v) : json(nullptr); };
  json j = {
      {"frame", s.frame},
      {"damage_threshold", s.damage_threshold},
      {"eps_v_p_threshold", s.eps_v_p_threshold},
      {"window_min_x_m", opt(s.window_min_x_m)},
      {"window_max_x_m", opt(s.window_max_x_m)},
      {"window_margin_over_h", s.window_margin_over_h},
      {"resolution_floor_over_dx", s.resolution_floor_over_dx},
      {"min_depth_over_dx", s.min_depth_over_dx},
      {"link_distance_over_spacing", s.link_distance_over_spacing},
      {"surface_reach_over_dx", s.surface_reach_over_dx},
      {"surface_smoothing_bins", s.surface_smoothing_bins},
      {"surface_bridge_half_width_over_h", s.surface_bridge_half_width_over_h},
      {"fragmented_fraction", s.fragmented_fraction},
      {"y_band_width_over_dx", s.y_band_width_over_dx},
      {"y_band_center_m", opt(s.y_band_center_m)},
      {"dx_m", opt(s.dx_m)},
      {"ice_thickness_m", opt(s.ice_thickness_m)},
      {"particle_spacing_m", opt(s.particle_spacing_m)},
  };
  // Written only when not the default, so that the case hashes of every stored study stay.
  if (s.spacing_rule != "merge") j["spacing_rule"] = s.spacing_rule;
  if (s.count_gaps) j["count_gaps"] = true;
  if (s.split_under_skin) j["split_under_skin"] = true;
  return j;
}

namespace {

// The study's name, description and base scene (a path relative to the study file, or inline).
void parse_name_and_base(const ordered_json& doc, const std::filesystem::path& base_dir, Study& st) {
  if (!doc.contains("name") || !doc.at("name").is_string())
    fail("name", "required: a string naming the study");
  st.name = doc.at("name").get<std::string>();
  if (st.name.empty() || st.name.size() > 64 ||
      !std::all_of(st.name.begin(), st.name.end(), [](char c) {
        return std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-' || c == '.';
      }))
    fail("name", "'" + printable(st.name.substr(0, 64)) + "' must be 1 to 64 characters from A-Z a-z 0-9 _ - .");
  // It names files (results/<name>.db): no hidden file, no "." or "..".
  if (st.name.front() == '.')
    fail("name", "'" + st.name + "' must not start with '.' (it names the database file)");
  if (doc.contains("description")) {
    if (!doc.at("description").is_string()) fail("description", "must be a string");
    st.description = doc.at("description").get<std::string>();
  }

  // Base scene: a path (relative to the study file) or an inline object.
  if (!doc.contains("base_scene"))
    fail("base_scene", "required: a scene file path or an inline scene object");
  const ordered_json& base = doc.at("base_scene");
  if (base.is_string()) {
    std::filesystem::path p = base.get<std::string>();
    if (p.is_relative()) p = base_dir / p;
    st.base_scene = read_json_text(read_text(p, "base_scene"), "base_scene " + p.string());
  } else if (base.is_object()) {
    st.base_scene = json(base);
  } else {
    fail("base_scene", "must be a scene file path or an inline scene object, got " + base.dump());
  }
  if (!st.base_scene.is_object()) fail("base_scene", "the scene must be a JSON object");
}

// fixed, sweep and replicas.
void parse_parameters(const ordered_json& doc, Study& st) {
  std::set<std::string> seen;  // parameters set by fixed or sweep
  if (doc.contains("fixed")) {
    const ordered_json& f = doc.at("fixed");
    if (!f.is_object()) fail("fixed", "must be an object of parameter: value");
    for (auto it = f.begin(); it != f.end(); ++it) {
      const std::string field = "fixed." + it.key();
      check_name(field, it.key());
      check_value(field, it.key(), json(it.value()));
      st.fixed.emplace_back(it.key(), json(it.value()));
      seen.insert(it.key());
    }
  }
  if (doc.contains("sweep")) {
    const ordered_json& s = doc.at("sweep");
    if (!s.is_object()) fail("sweep", "must be an object of parameter: values");
    for (auto it = s.begin(); it != s.end(); ++it) {
      const std::string field = "sweep." + it.key();
      check_name(field, it.key());
      if (seen.count(it.key())) fail(field, "also set in fixed; set it in one place");
      SweepAxis axis{it.key(), expand_axis(json(it.value()), field)};
      for (const json& v : axis.values) check_value(field, it.key(), v);
      seen.insert(it.key());
      st.axes.push_back(std::move(axis));
    }
  }
  for (const auto& [name, target] : named_targets())
    if (seen.count(name) && seen.count(target))
      fail(name, "and " + target + " both set the same scene field; give only one of them");
  if (seen.count("slope") && seen.count("step_height_ratio"))
    fail("slope", "and step_height_ratio both set the step height; give only one of them");
  if (seen.count("shear_strength_ratio") && seen.count("shear_to_tensile_ratio"))
    fail("shear_to_tensile_ratio",
         "and shear_strength_ratio both set the shear strength; give only one of them");

  if (doc.contains("replicas")) {
    const ordered_json& r = doc.at("replicas");
    if (r.is_object()) {
      refuse_unknown_keys(r, "replicas", {"count", "first_seed"});
      if (r.contains("count")) st.replicas = integer_in(r.at("count"), "replicas.count", 1, 1000);
      if (r.contains("first_seed"))
        st.first_seed = static_cast<std::uint64_t>(
            integer_in(r.at("first_seed"), "replicas.first_seed", 0, 1000000000));
    } else {
      st.replicas = integer_in(r, "replicas", 1, 1000);
    }
    if (st.replicas > 1 && seen.count("/numerics/seed"))
      fail("replicas",
           "set /numerics/seed per replica; remove /numerics/seed from fixed and sweep");
  }
}

void parse_resources(const ordered_json& doc, Study& st) {
  if (doc.contains("resources")) {
    const ordered_json& r = doc.at("resources");
    if (!r.is_object()) fail("resources", "must be an object");
    refuse_unknown_keys(r, "resources",
                   {"jobs", "threads_per_case", "case_time_limit_s", "checkpoint_interval_s"});
    if (r.contains("checkpoint_interval_s"))
      st.resources.checkpoint_interval_s = number_in(
          r.at("checkpoint_interval_s"), "resources.checkpoint_interval_s", {0.0, 1e8, false, false});
    if (r.contains("jobs")) st.resources.jobs = integer_in(r.at("jobs"), "resources.jobs", 0, 1024);
    if (r.contains("threads_per_case"))
      st.resources.threads_per_case =
          integer_in(r.at("threads_per_case"), "resources.threads_per_case", 0, 1024);
    if (r.contains("case_time_limit_s"))
      st.resources.case_time_limit_s = number_in(
          r.at("case_time_limit_s"), "resources.case_time_limit_s", {0.0, 1e8, false, false});
  }
}

// "protocol" names the field a study measures and so its frame (docs/model.md, "Two
// protocols"); "measure_interval_s" asks for the field over time as well.
void parse_protocol(const ordered_json& doc, json& measurement, Study& st) {
  if (doc.contains("measure_interval_s"))
    st.measure_interval_s =
        number_in(doc.at("measure_interval_s"), "measure_interval_s", {0.0, 1e6, false, false});
  // One run serving a shorter protocol too: its particles kept when this much ice (in H_i) has
  // passed the gate, as the case stopped there would keep them (docs/study_format.md).
  const std::string marks = "keep_particles_at_gate_length_ratios";
  if (doc.contains(marks)) {
    const ordered_json& a = doc.at(marks);
    if (!a.is_array() || a.empty() || a.size() > 100 ||
        std::any_of(a.begin(), a.end(), [](const ordered_json& x) { return !x.is_number(); }))
      fail(marks, "must be a list of 1 to 100 lengths of ice through the gate in H_i, each in (0, 1000], got " + a.dump());
    for (std::size_t i = 0; i < a.size(); ++i)
      st.gate_mark_ratios.push_back(number_in(a[i], marks + "[" + std::to_string(i) + "]", {0.0, 1e3, true, false}));
  }
  if (!doc.contains("protocol")) return;
  const ordered_json& p = doc.at("protocol");
  static const std::map<std::string, std::string> frame_of = {{"initiation", "draped"},
                                                              {"steady", "passed"}};
  const auto it = p.is_string() ? frame_of.find(p.get<std::string>()) : frame_of.end();
  if (it == frame_of.end())
    fail("protocol", "value " + p.dump() + R"( is not "initiation" or "steady")");
  st.protocol = it->first;
  if (!measurement.is_null() && !measurement.is_object()) return;  // refused as measurement below
  if (!measurement.contains("frame")) {
    measurement["frame"] = it->second;
  } else if (measurement.at("frame") != it->second) {
    fail("measurement.frame", "value " + measurement.at("frame").dump() + " is not the " + it->first +
                                  " protocol's frame \"" + it->second + "\"; leave it out or set it so");
  }
}

// The named parameters of a case (groups, ratios to H_i) written into its scene as the fields
// they set (docs/study_format.md).
void apply_named_parameters(json& scene, std::map<std::string, double>& named, const std::string& where,
                            const SceneConfig& defaults) {
  // Derived dimensional parameters (docs/model.md), written into these sections.
  for (const char* section : {"ice", "bed", "numerics", "run"})
    if (scene.contains(section) && !scene.at(section).is_object())
      fail(where,
           std::string(section) + ": must be a JSON object, got " + scene.at(section).dump());
  const auto has = [&](const char* n) { return named.count(n) > 0; };
  double h_i = number_at(scene, "/ice/thickness", defaults.ice_thickness);
  if (has("thickness")) h_i = named["thickness"];
  scene["ice"]["thickness"] = h_i;
  if (has("cells_per_thickness")) scene["numerics"]["dx"] = h_i / named["cells_per_thickness"];
  // Strengths given relative to the overburden ρ_i g H_i.
  for (const auto& [name, field] : {std::pair{"cohesion_ratio", "tensile_strength"},
                                    std::pair{"shear_strength_ratio", "shear_strength"}}) {
    if (!has(name)) continue;
    const double rho = number_at(scene, "/ice/density", defaults.density);
    const double g = number_at(scene, "/gravity/g", defaults.gravity);
    if (!(g > 0))
      fail(where, std::string(name) + " needs gravity.g > 0 (it is relative to ρ_i g H_i), got g = " + input_number(g));
    scene["ice"][field] = stress_from_overburden_ratio(named[name], rho, g, h_i);
  }
  // q_y = k·c: a material constant k keeps Π the only strength group (docs/model.md), where a
  // q_y relative to ρ_i g H_i would add a second one.
  if (has("shear_to_tensile_ratio"))
    scene["ice"]["shear_strength"] =
        named["shear_to_tensile_ratio"] *
        number_at(scene, "/ice/tensile_strength", defaults.tensile_strength);
  if (has("draped_length_ratio")) scene["ice"]["draped_length"] = named["draped_length_ratio"] * h_i;
  if (has("step_length_ratio")) scene["bed"]["step_length"] = named["step_length_ratio"] * h_i;
  if (has("slope")) {
    const double l_s = number_at(scene, "/bed/step_length", defaults.step_length);
    if (!(l_s > 0))
      fail(
          where,
          "slope needs a step of non-zero length; this step is vertical (step_length 0), so give "
          "step_height_ratio instead");
    scene["bed"]["step_height"] = named["slope"] * l_s;
  }
  if (has("step_height_ratio")) scene["bed"]["step_height"] = named["step_height_ratio"] * h_i;
  if (has("width_ratio")) {
    const double dim = number_at(scene, "/dim", defaults.dim);
    if (dim != 3)
      fail(where, "width_ratio applies to 3D scenes only; this case has dim " + input_number(dim));
    scene["ice"]["width"] = named["width_ratio"] * h_i;
  }
  if (has("front_past_step_ratio"))
    scene["run"]["front_past_step"] = named["front_past_step_ratio"] * h_i;
  if (has("gate_length_ratio")) scene["run"]["gate_length"] = named["gate_length_ratio"] * h_i;
  if (has("gate_offset_ratio")) scene["run"]["gate_offset"] = named["gate_offset_ratio"] * h_i;
  if (has("upstream_length_ratio"))
    scene["ice"]["upstream_length"] = named["upstream_length_ratio"] * h_i;
  if (has("downstream_length_ratio"))
    scene["bed"]["downstream_length"] = named["downstream_length_ratio"] * h_i;
}

// Case `index` of the Cartesian product (last axis fastest, replicas innermost), resolved and
// hashed.
StudyCase make_case(const Study& st, std::size_t index, const SceneConfig& defaults) {
  StudyCase c;
  c.index = index;
  c.replica = static_cast<int>(index % static_cast<std::size_t>(st.replicas));
  std::vector<std::size_t> digit(st.axes.size(), 0);  // the case's value index on each axis
  std::size_t rest = index / static_cast<std::size_t>(st.replicas);
  for (std::size_t k = st.axes.size(); k-- > 0;) {
    digit[k] = rest % st.axes[k].values.size();
    rest /= st.axes[k].values.size();
  }
  json scene = st.base_scene;
  std::map<std::string, double> named;
  auto apply = [&](const std::string& field, const std::string& name, const json& v) {
    if (!is_pointer(name)) {
      named[name] = v.get<double>();
      return;
    }
    try {
      scene[json::json_pointer(name)] = v;
    } catch (const json::exception& e) {  // a non-numeric array index, a path through a value
      fail(field, "cannot set '" + name + "' in this base scene (" + e.what() + ")");
    }
  };
  for (const auto& [name, v] : st.fixed) apply("fixed." + name, name, v);
  c.axes = json::object();
  for (std::size_t k = 0; k < st.axes.size(); ++k) {
    const json& v = st.axes[k].values[digit[k]];
    apply("sweep." + st.axes[k].name, st.axes[k].name, v);
    c.axes[st.axes[k].name] = v;
    c.label += (c.label.empty() ? "" : " ") + st.axes[k].name + "=" + value_label(v);
  }
  if (st.replicas > 1) {
    scene["numerics"]["seed"] = st.first_seed + static_cast<std::uint64_t>(c.replica);
    c.axes["replica"] = c.replica;
    c.label += (c.label.empty() ? "" : " ") + std::string("replica=") + std::to_string(c.replica);
  }
  if (c.label.empty()) c.label = "base";
  const std::string where = "case " + std::to_string(index) + " (" + c.label + ")";
  apply_named_parameters(scene, named, where, defaults);
  try {
    c.scene = scene_from_json(scene);
  } catch (const InputError& e) {
    throw InputError(where + ": " + e.what());
  }
  if (st.replicas > 1 && c.scene.jitter <= 0)
    fail("replicas",
         "replicas differ only by /numerics/seed, which has no effect while /numerics/jitter is "
         "0; "
         "set /numerics/jitter in (0, 0.5]");
  // The measurement's lengths against this case's own scales, before anything is simulated.
  try {
    analysis::check_measure_scales(st.measurement, {c.scene.dx, c.scene.ice_thickness,
                                                    c.scene.dx / c.scene.particles_per_cell_axis});
  } catch (const std::invalid_argument& e) {
    throw InputError("measurement." + std::string(e.what()) + ", in " + where);
  }
  c.scene_json = scene_to_json(c.scene);
  c.groups = groups_of(c.scene);
  c.case_id = case_hash(c.scene, st.measurement_json);
  return c;
}

}  // namespace

Study parse_study(const std::string& text, const std::filesystem::path& base_dir,
                  const std::string& source) {
  Study st;
  st.source_text = text;
  const ordered_json doc = parse_json_input<ordered_json>(text, source);
  if (!doc.is_object()) fail(source, "a study file must be a JSON object");
  refuse_unknown_keys(doc, "",
                 {"name", "description", "base_scene", "fixed", "sweep", "replicas", "measurement",
                  "resources", "protocol", "measure_interval_s", "keep_particles_at_gate_length_ratios"});
  parse_name_and_base(doc, base_dir, st);
  parse_parameters(doc, st);
  json measurement = doc.contains("measurement") ? json(doc.at("measurement")) : json();
  parse_protocol(doc, measurement, st);
  st.measurement = measure_settings_from_json(measurement);
  st.measurement_json = measure_settings_to_json(st.measurement);
  parse_resources(doc, st);

  std::size_t total = static_cast<std::size_t>(st.replicas);
  for (const auto& a : st.axes) {
    total *= a.values.size();
    if (total > kMaxCases)
      fail("sweep",
           "more than " + std::to_string(kMaxCases) + " cases; split the study into smaller ones");
  }
  const SceneConfig defaults;
  std::map<std::string, std::size_t> by_id;
  for (std::size_t index = 0; index < total; ++index) {
    StudyCase c = make_case(st, index, defaults);
    const auto [it, inserted] = by_id.emplace(c.case_id, index);
    if (!inserted)
      fail("sweep", "cases " + std::to_string(it->second) + " (" + st.cases[it->second].label +
                        ") and " + std::to_string(index) + " (" + c.label +
                        ") resolve to the same parameters; remove the repeated value");
    st.cases.push_back(std::move(c));
  }

  std::vector<std::string> ids;
  for (const auto& c : st.cases) ids.push_back(c.case_id);
  std::sort(ids.begin(), ids.end());
  std::string all;
  for (const auto& id : ids) all += id + "\n";
  st.study_hash = sha256_hex(all);
  return st;
}

Study load_study_file(const std::filesystem::path& path) {
  const std::string text = read_text(path, "study file");
  return parse_study(text, path.parent_path(), path.string());
}

}  // namespace crevasse
