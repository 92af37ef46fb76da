// docs/scene_format.md is the reference of the scene's fields; the field table in
// engine/scene.cpp reads, writes and checks them. This holds the two to each other: every field
// of the table has its row in the docs' section, with the same type, unit, default and range.
#include <gtest/gtest.h>

#include <fstream>
#include <functional>
#include <nlohmann/json.hpp>
#include <set>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "engine/scene.hpp"

namespace crevasse {
namespace {

std::string trim(const std::string& s) {
  const auto b = s.find_first_not_of(' '), e = s.find_last_not_of(' ');
  return b == std::string::npos ? "" : s.substr(b, e - b + 1);
}

// The cells of a markdown table row ("| a | b |" → {"a", "b"}); escaped bars stay in the cell.
std::vector<std::string> cells(const std::string& line) {
  std::vector<std::string> out;
  std::string cell;
  for (std::size_t i = 1; i < line.size(); ++i) {
    if (line[i] == '|' && line[i - 1] != '\\') {
      out.push_back(trim(cell));
      cell.clear();
    } else {
      cell += line[i];
    }
  }
  return out;
}

// "section.key" → the row's cells, from the docs' "## ice", "### ice.softening", ... tables.
std::map<std::string, std::vector<std::string>> docs_rows() {
  std::ifstream in(std::string(CREVASSE_SOURCE_DIR) + "/docs/scene_format.md");
  EXPECT_TRUE(in.good());
  std::map<std::string, std::vector<std::string>> rows;
  std::string line, section;
  while (std::getline(in, line)) {
    if (line.rfind("## ", 0) == 0 || line.rfind("### ", 0) == 0) {
      section = trim(line.substr(line.find(' ') + 1));
    } else if (line.rfind("| `", 0) == 0) {
      const auto c = cells(line);
      if (c.size() == 5) rows[section + "." + c[0].substr(1, c[0].size() - 2)] = c;
    }
  }
  return rows;
}

TEST(SceneFields, DocsTableMatchesTheFieldTable) {
  const auto rows = docs_rows();
  const auto fields = scene_field_docs();
  ASSERT_GT(fields.size(), 40u);
  for (const auto& f : fields) {
    SCOPED_TRACE(f.path);
    const auto it = rows.find(f.path);
    ASSERT_NE(it, rows.end()) << "no row in docs/scene_format.md";
    const auto& c = it->second;  // key, type, unit, default, allowed
    EXPECT_EQ(c[1], f.type);
    EXPECT_EQ(c[2], f.unit);
    EXPECT_EQ(c[3].rfind(f.default_value, 0), 0u) << "default cell '" << c[3] << "', table: " << f.default_value;
    if (!f.range.empty()) {
      EXPECT_NE(c[4].find(f.range), std::string::npos) << "allowed '" << c[4] << "', table: " << f.range;
    }
  }
}

// Each key reaches its own member. Every number of a shipped scene is moved by its own small
// amount, read back, and compared with the member named here (written independently of the
// field table), so that two keys crossed in the table fail even where their defaults agree.
TEST(SceneFields, EachKeyReachesItsOwnMember) {
  using M = std::function<double(const SceneConfig&)>;
  const std::vector<std::pair<std::string, M>> members = {
      {"ice.density", [](const SceneConfig& s) { return s.density; }},
      {"ice.youngs_modulus", [](const SceneConfig& s) { return s.youngs_modulus; }},
      {"ice.poisson_ratio", [](const SceneConfig& s) { return s.poisson_ratio; }},
      {"ice.tensile_strength", [](const SceneConfig& s) { return s.tensile_strength; }},
      {"ice.shear_strength", [](const SceneConfig& s) { return s.shear_strength; }},
      {"ice.thickness", [](const SceneConfig& s) { return s.ice_thickness; }},
      {"ice.upstream_length", [](const SceneConfig& s) { return s.upstream_length; }},
      {"ice.draped_length", [](const SceneConfig& s) { return s.draped_length; }},
      {"ice.width", [](const SceneConfig& s) { return s.width; }},
      {"ice.settle_time", [](const SceneConfig& s) { return s.settle_time; }},
      {"ice.softening.zeta_ref", [](const SceneConfig& s) { return s.zeta_ref; }},
      {"ice.softening.dx_ref", [](const SceneConfig& s) { return s.dx_ref; }},
      {"ice.softening.residual_friction", [](const SceneConfig& s) { return s.residual_friction; }},
      {"ice.softening.nonlocal_radius", [](const SceneConfig& s) { return s.nonlocal_radius; }},
      {"ice.softening.nonlocal_weight", [](const SceneConfig& s) { return s.nonlocal_weight; }},
      {"ice.softening.cap_relaxation_time", [](const SceneConfig& s) { return s.cap_relaxation_time; }},
      {"ice.creep.rate_factor", [](const SceneConfig& s) { return s.creep_rate_factor; }},
      {"ice.creep.exponent", [](const SceneConfig& s) { return s.creep_exponent; }},
      {"ice.creep.field_speed", [](const SceneConfig& s) { return s.creep_field_speed; }},
      {"bed.step_height", [](const SceneConfig& s) { return s.step_height; }},
      {"bed.step_length", [](const SceneConfig& s) { return s.step_length; }},
      {"bed.lip_radius", [](const SceneConfig& s) { return s.lip_radius; }},
      {"bed.downstream_length", [](const SceneConfig& s) { return s.downstream_length; }},
      {"bed.friction", [](const SceneConfig& s) { return s.bed_friction; }},
      {"drive.speed", [](const SceneConfig& s) { return s.drive_speed; }},
      {"drive.ramp_time", [](const SceneConfig& s) { return s.drive_ramp_time; }},
      {"gravity.g", [](const SceneConfig& s) { return s.gravity; }},
      {"gravity.tilt_deg", [](const SceneConfig& s) { return s.gravity_tilt_deg; }},
      {"numerics.dx", [](const SceneConfig& s) { return s.dx; }},
      {"numerics.cfl", [](const SceneConfig& s) { return s.cfl; }},
      {"numerics.jitter", [](const SceneConfig& s) { return s.jitter; }},
      {"numerics.seed", [](const SceneConfig& s) { return static_cast<double>(s.seed); }},
      {"numerics.top_margin", [](const SceneConfig& s) { return s.top_margin; }},
      {"numerics.average_relaxation_time", [](const SceneConfig& s) { return s.average_relaxation_time; }},
      {"run.end_time", [](const SceneConfig& s) { return s.end_time; }},
      {"run.front_past_step", [](const SceneConfig& s) { return s.front_past_step; }},
      {"run.gate_length", [](const SceneConfig& s) { return s.gate_length; }},
      {"run.gate_offset", [](const SceneConfig& s) { return s.gate_offset; }},
      {"run.max_steps", [](const SceneConfig& s) { return static_cast<double>(s.max_steps); }},
      {"run.wall_time_limit", [](const SceneConfig& s) { return s.wall_time_limit; }},
      {"output.vtu_interval", [](const SceneConfig& s) { return s.vtu_interval; }},
  };
  // Not moved: ζ and G (one may not contradict the other), bed.z (refused on a step bed), and
  // particles_per_cell_axis (an integer of small range, its default differs from every other).
  const std::set<std::string> unmoved = {"ice.softening.zeta", "ice.softening.fracture_energy", "bed.z",
                                         "numerics.particles_per_cell_axis"};
  std::set<std::string> covered = unmoved;
  for (const auto& [path, member] : members) covered.insert(path);
  for (const auto& f : scene_field_docs())
    if (f.type == "number" || f.type == "integer") {
      EXPECT_TRUE(covered.count(f.path)) << f.path << " has no member here";
    }

  std::ifstream in(std::string(CREVASSE_SOURCE_DIR) + "/studies/scenes/glacier_2d.json");
  nlohmann::json j = scene_to_json(scene_from_json(nlohmann::json::parse(in)));
  // A scene without creep writes no creep section (its case hash stays that of the law without it).
  EXPECT_FALSE(j["ice"].contains("creep"));
  j["ice"]["creep"] = {{"rate_factor", 2.4e-24}, {"exponent", 3.0}, {"field_speed", 3.17e-6}};
  j["numerics"]["average_per_cell"] = true;  // written only when set, like the creep section
  j["numerics"]["average_relaxation_time"] = 0.05;
  // Nor the softening's length, its viscous cap or a rounded lip when they are off.
  EXPECT_FALSE(j["ice"]["softening"].contains("nonlocal_radius"));
  EXPECT_FALSE(j["ice"]["softening"].contains("nonlocal_weight"));
  EXPECT_FALSE(j["ice"]["softening"].contains("cap_relaxation_time"));
  EXPECT_FALSE(j["bed"].contains("lip_radius"));
  EXPECT_FALSE(j["ice"]["softening"].contains("brittle_cap"));
  j["ice"]["softening"]["nonlocal_radius"] = 30.0;
  j["ice"]["softening"]["nonlocal_weight"] = 1.5;
  j["ice"]["softening"]["cap_relaxation_time"] = 0.1;
  j["bed"]["lip_radius"] = 20.0;
  const auto pointer = [](std::string path) {
    for (char& c : path)
      if (c == '.') c = '/';
    return nlohmann::json::json_pointer("/" + path);
  };
  std::vector<double> expected;
  for (std::size_t k = 0; k < members.size(); ++k) {
    nlohmann::json& v = j[pointer(members[k].first)];
    if (v.is_number_integer()) v = v.get<std::int64_t>() + static_cast<std::int64_t>(k + 1);
    else v = v.get<double>() + 1e-3 * static_cast<double>(k + 1);
    expected.push_back(v.get<double>());
  }
  const SceneConfig s = scene_from_json(j);
  for (std::size_t k = 0; k < members.size(); ++k) EXPECT_EQ(members[k].second(s), expected[k]) << members[k].first;
}

}  // namespace
}  // namespace crevasse
