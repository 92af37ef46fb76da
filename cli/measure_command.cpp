#include "cli/measure_command.hpp"

#include <cstdio>
#include <filesystem>

#include "analysis/crevasse_measure.hpp"
#include "analysis/measurement_io.hpp"
#include "cli/cli_common.hpp"
#include "engine/error.hpp"
#include "engine/groups.hpp"
#include "engine/particle_file.hpp"
#include "engine/vtu_writer.hpp"
#include "study/case_views.hpp"
#include "study/study_file.hpp"

namespace crevasse {
namespace {

// KEY=VALUE onto the measurement object; VALUE is JSON (a number, "drop", null) or, when it
// does not parse as JSON, a bare word taken as a string (frame=passed).
void apply_setting(nlohmann::json& measurement, const std::string& kv) {
  const auto eq = kv.find('=');
  if (eq == std::string::npos || eq == 0)
    throw InputError("--set: '" + kv + "' is not KEY=VALUE (e.g. --set spacing_rule=drop)");
  const std::string key = kv.substr(0, eq), text = kv.substr(eq + 1);
  nlohmann::json value = nlohmann::json::parse(text, nullptr, false);
  if (value.is_discarded()) value = text;
  measurement[key] = value;
}

std::string quartiles(const std::optional<analysis::QuartileSummary>& q, const char* unit) {
  if (!q) return "-";
  char buf[96];
  std::snprintf(buf, sizeof buf, "%.4g %s (quartiles %.4g-%.4g)", q->median, unit, q->q25, q->q75);
  return buf;
}

void print_measurement(const analysis::CrevasseMeasurement& m, const nlohmann::json& meta) {
  const double h = m.settings.ice_thickness_m;
  const std::string id = meta.value("case_id", std::string()), label = meta.value("label", std::string());
  if (!id.empty()) std::printf("case %s  ", id.c_str());
  std::printf("%s\n", label.c_str());
  std::printf("t = %.1f s  H_i = %.4g m  dx = %.3g m  frame %s  window %.0f-%.0f m  rule %s\n", m.time_s, h,
              m.settings.dx_m, m.settings.frame.c_str(), m.settings.window_min_x_m, m.settings.window_max_x_m,
              m.settings.spacing_rule.c_str());
  std::printf("crevasses %zu  (shallower than %.3g m: %zu; spacings dropped under the floor: %zu)\n",
              m.crevasses.size(), m.settings.min_depth_m, m.shallow_count, m.dropped_spacing_count);
  std::printf("spacing %s\ndepth   %s\n", quartiles(m.spacing_m, "m").c_str(), quartiles(m.depth_m, "m").c_str());
  const auto share = [](std::size_t a, std::size_t b) { return b ? 100.0 * a / b : 0.0; };
  std::printf("damaged: %.1f %% of the window's ice, %.1f %% of it deeper than H_i/2%s\n",
              share(m.window_damaged_count, m.window_particle_count),
              share(m.deep_damaged_count, m.deep_particle_count), m.flags.fragmented ? "  (fragmented)" : "");
  if (!m.crevasses.empty()) std::printf("%5s %10s %10s %8s %12s\n", "index", "x [m]", "depth [m]", "D/H_i", "spacing [m]");
  for (std::size_t i = 0; i < m.crevasses.size(); ++i) {
    const analysis::Crevasse& c = m.crevasses[i];
    char spacing[32] = "";
    if (c.spacing_to_next_m) std::snprintf(spacing, sizeof spacing, "%.1f", *c.spacing_to_next_m);
    std::printf("%5zu %10.1f %10.1f %8.3f %12s\n", i, c.x_m, c.depth_m, h > 0 ? c.depth_m / h : 0.0, spacing);
  }
}

}  // namespace

int measure_command(const MeasureCommandOptions& opt) {
  // Every output is checked before the particles are read: none may be the input, and each
  // must be writable (its folder made below a writable one).
  const std::filesystem::path out(opt.out_dir), vtu(opt.vtu_path);
  const std::vector<std::string> out_files = {"crevasses.csv", "measurement.json", "side_view.png", "gate_view.png"};
  std::vector<NamedPath> inputs = {{"the particle file", opt.particle_path}};
  if (!opt.out_dir.empty()) {
    check_output_directory("--out", out, out_files);
    for (const std::string& name : out_files) check_output_is_not_input("--out", out / name, inputs);
  }
  if (!opt.vtu_path.empty()) {
    check_output_file("--vtu", vtu);
    if (!opt.out_dir.empty())
      for (const std::string& name : out_files) inputs.push_back({"--out's " + name, out / name});
    check_output_is_not_input("--vtu", vtu, inputs);
  }
  const ParticleFile file = read_particle_file(opt.particle_path);
  if (!file.header_checked)
    std::fprintf(stderr, "crevasse: warning: %s\n", unchecked_header_warning(opt.particle_path).c_str());
  nlohmann::json measurement = file.metadata.value("measurement", nlohmann::json::object());
  if (!measurement.is_object()) measurement = nlohmann::json::object();
  for (const std::string& kv : opt.settings) apply_setting(measurement, kv);
  const analysis::MeasureSettings settings = measure_settings_from_json(measurement);
  analysis::CrevasseMeasurement m;
  try {
    m = analysis::measure_crevasses(file.snapshot, settings);
  } catch (const std::invalid_argument& e) {
    throw InputError(opt.particle_path + ": cannot be measured (" + e.what() + ")");
  }
  print_measurement(m, file.metadata);
  if (!opt.out_dir.empty()) {
    create_output_directory("--out", out);
    analysis::write_crevasses_csv(m, out / "crevasses.csv");
    analysis::write_measurement_summary(m, out / "measurement.json");
    const double rho = file.metadata.value("density_kg_m3", 0.0), g = file.metadata.value("gravity_m_s2", 0.0);
    const ParticleSnapshot& s = file.snapshot;
    const double pi_group = rho * g * s.ice_thickness_m > 0
                                ? cohesion_ratio(s.tensile_strength_pa, rho, g, s.ice_thickness_m)
                                : 0.0;
    write_case_views(pi_group, s, m, out);
  }
  if (!opt.vtu_path.empty()) {
    if (vtu.has_parent_path()) create_output_directory("--vtu", vtu.parent_path());
    write_vtu(opt.vtu_path, file.snapshot);
  }
  return 0;
}

}  // namespace crevasse
