#include "analysis/measurement_io.hpp"

#include <cerrno>
#include <cstring>
#include <sstream>
#include <stdexcept>
#include <string>

#include "engine/atomic_file.hpp"

namespace crevasse::analysis {

namespace {

// Built in memory, then written whole or not at all (engine/atomic_file.hpp).
std::ostringstream open_for_writing() {
  std::ostringstream out;
  // 10 significant digits: sub-millimetre at glacier scales, and stable across platforms.
  out.precision(10);
  return out;
}

void finish(const std::ostringstream& out, const std::filesystem::path& path, const char* what) {
  const std::filesystem::path dir = path.has_parent_path() ? path.parent_path() : ".";
  if (!std::filesystem::is_directory(dir))
    throw std::runtime_error(std::string("cannot write ") + what + " to '" + path.string() +
                             "': no such directory (does the directory exist?)");
  try {
    write_file_atomically(path, out.str());
  } catch (const std::runtime_error& e) {
    throw std::runtime_error(std::string("writing ") + what + " to '" + path.string() + "' failed: " + e.what());
  }
}

nlohmann::json quartiles_json(const std::optional<QuartileSummary>& q) {
  if (!q) return nullptr;
  return {{"q25", q->q25}, {"median", q->median}, {"q75", q->q75}};
}

}  // namespace

void write_crevasses_csv(const CrevasseMeasurement& m, const std::filesystem::path& path) {
  std::ostringstream out = open_for_writing();
  out << "index,x_m,depth_m,width_m,depth_over_H,spacing_to_next_m\n";
  const double h = m.settings.ice_thickness_m;
  for (std::size_t i = 0; i < m.crevasses.size(); ++i) {
    const Crevasse& c = m.crevasses[i];
    out << i << ',' << c.x_m << ',' << c.depth_m << ',' << c.width_m << ','
        << (h > 0.0 ? c.depth_m / h : 0.0) << ',';
    if (c.spacing_to_next_m) out << *c.spacing_to_next_m;
    out << '\n';
  }
  finish(out, path, "crevasses CSV");
}

nlohmann::json settings_to_json(const ResolvedMeasureSettings& s) {
  nlohmann::json j = {
      {"frame", s.frame},
      {"damage_threshold", s.damage_threshold},
      {"eps_v_p_threshold", s.eps_v_p_threshold},
      {"threshold_from_softening", s.threshold_from_softening},
      {"window_min_x_m", s.window_min_x_m},
      {"window_max_x_m", s.window_max_x_m},
      {"window_explicit", s.window_explicit},
      {"dx_m", s.dx_m},
      {"ice_thickness_m", s.ice_thickness_m},
      {"particle_spacing_m", s.particle_spacing_m},
      {"resolution_floor_m", s.resolution_floor_m},
      {"spacing_rule", s.spacing_rule},
      {"min_depth_m", s.min_depth_m},
      {"link_distance_m", s.link_distance_m},
      {"surface_reach_m", s.surface_reach_m},
      {"surface_smoothing_bins", s.surface_smoothing_bins},
      {"surface_bridge_half_width_m", s.surface_bridge_half_width_m},
      {"lip_offset_m", s.lip_offset_m},
      {"fragmented_fraction", s.fragmented_fraction},
      {"dim", s.dim},
  };
  if (s.count_gaps) j["count_gaps"] = true;  // absent when off, so stored results stay as they were
  if (s.split_under_skin) j["split_under_skin"] = true;
  if (s.dim == 3) {
    j["y_band_center_m"] = s.y_band_center_m;
    j["y_band_width_m"] = s.y_band_width_m;
  }
  return j;
}

namespace {
// A share, or null when there is nothing to take it of.
nlohmann::json share(std::size_t part, std::size_t whole) {
  if (whole == 0) return nullptr;
  return static_cast<double>(part) / static_cast<double>(whole);
}
}  // namespace

nlohmann::json measurement_summary_json(const CrevasseMeasurement& m) {
  nlohmann::json positions = nlohmann::json::array(), depths = nlohmann::json::array(),
                 widths = nlohmann::json::array();
  for (const Crevasse& c : m.crevasses) {
    positions.push_back(c.x_m);
    depths.push_back(c.depth_m);
    widths.push_back(c.width_m);
  }
  return {
      {"time_s", m.time_s},
      {"crevasse_count", m.crevasses.size()},
      {"dropped_spacing_count", m.dropped_spacing_count},
      {"shallow_count", m.shallow_count},
      {"spacing_count", m.spacings_m.size()},
      {"spacing_m", quartiles_json(m.spacing_m)},
      {"spacing_over_h", quartiles_json(m.spacing_over_h)},
      {"depth_m", quartiles_json(m.depth_m)},
      {"depth_over_h", quartiles_json(m.depth_over_h)},
      {"flags",
       {{"empty_snapshot", m.flags.empty_snapshot},
        {"empty_window", m.flags.empty_window},
        {"no_crevasse", m.flags.no_crevasse},
        {"fragmented", m.flags.fragmented},
        {"has_spacing", m.flags.has_spacing}}},
      {"counts",
       {{"particles", m.particle_count},
        {"window_particles", m.window_particle_count},
        {"damaged_particles", m.damaged_particle_count},
        {"damage_clusters", m.cluster_count}}},
      {"damage",
       {{"window_damaged_particles", m.window_damaged_count},
        {"deep_particles", m.deep_particle_count},
        {"deep_damaged_particles", m.deep_damaged_count},
        {"window_damaged_fraction", share(m.window_damaged_count, m.window_particle_count)},
        {"deep_damaged_fraction", share(m.deep_damaged_count, m.deep_particle_count)}}},
      {"positions_m", positions},
      {"depths_m", depths},
      {"widths_m", widths},
      {"spacings_m", m.spacings_m},
      {"settings", settings_to_json(m.settings)},
  };
}

void write_measurement_summary(const CrevasseMeasurement& m, const std::filesystem::path& path) {
  std::ostringstream out = open_for_writing();
  out << measurement_summary_json(m).dump(2) << '\n';
  finish(out, path, "measurement summary JSON");
}

}  // namespace crevasse::analysis
