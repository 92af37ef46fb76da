#include "study/field_over_time.hpp"

#include <fstream>

#include "engine/atomic_file.hpp"

namespace crevasse {

FieldOverTime::FieldOverTime(std::filesystem::path file) : file_(std::move(file)) {
  if (file_.empty()) return;
  std::ifstream in(file_);
  if (!in) return;
  const nlohmann::json j = nlohmann::json::parse(in, nullptr, /*allow_exceptions=*/false);
  if (j.is_array()) rows_ = j;
}

nlohmann::json field_row(const ParticleSnapshot& s, const analysis::CrevasseMeasurement& m) {
  const auto q = [](const std::optional<analysis::QuartileSummary>& v, int k) -> nlohmann::json {
    if (!v) return nullptr;
    return k == 0 ? v->q25 : k == 1 ? v->median : v->q75;
  };
  const auto share = [](std::size_t part, std::size_t all) -> nlohmann::json {
    return all > 0 ? nlohmann::json(static_cast<double>(part) / static_cast<double>(all)) : nullptr;
  };
  const double h = m.settings.ice_thickness_m;
  return {{"time_s", s.time_s},
          {"pushed_over_h", h > 0 ? s.gate_passed_length_m / h : 0.0},
          {"window_m", {m.settings.window_min_x_m, m.settings.window_max_x_m}},
          {"crevasse_count", m.crevasses.size()},
          {"spacing_m", {q(m.spacing_m, 0), q(m.spacing_m, 1), q(m.spacing_m, 2)}},
          {"depth_median_m", q(m.depth_m, 1)},
          {"window_damaged_fraction", share(m.window_damaged_count, m.window_particle_count)},
          {"deep_damaged_fraction", share(m.deep_damaged_count, m.deep_particle_count)}};
}

void FieldOverTime::add(const ParticleSnapshot& snapshot, const analysis::MeasureSettings& settings) {
  const analysis::CrevasseMeasurement m = analysis::measure_crevasses(snapshot, settings);
  nlohmann::json kept = nlohmann::json::array();
  for (const auto& r : rows_)
    if (r.at("time_s").get<double>() < snapshot.time_s - 1e-9) kept.push_back(r);
  kept.push_back(field_row(snapshot, m));
  rows_ = std::move(kept);
  if (!file_.empty()) write_file_atomically(file_, rows_.dump() + "\n");
}

}  // namespace crevasse
