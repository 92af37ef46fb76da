#pragma once
// The field a case measures, taken again every so many simulated seconds while it runs
// (Study::measure_interval_s): one compact row per time, stored with the case's result as
// result_json.extra.over_time. It shows when a field has settled, which is how a protocol's
// stop rule is chosen (docs/model.md, "Two protocols"). With a file, each row is also written
// there as it is taken, and a case resumed from its checkpoint starts from those rows.
#include <filesystem>
#include <nlohmann/json.hpp>

#include "analysis/crevasse_measure.hpp"
#include "engine/snapshot.hpp"

namespace crevasse {

class FieldOverTime {
 public:
  // `file` empty: rows are kept in memory only. Otherwise the rows already in it are loaded
  // (a missing or unreadable file counts as none).
  explicit FieldOverTime(std::filesystem::path file = {});
  // Measures `snapshot` with `settings` and appends its row; rows at or after its time (written
  // after the checkpoint the case resumed from) are replaced.
  void add(const ParticleSnapshot& snapshot, const analysis::MeasureSettings& settings);
  const nlohmann::json& rows() const { return rows_; }

 private:
  std::filesystem::path file_;
  nlohmann::json rows_ = nlohmann::json::array();
};

// One row: time, how far the back has been pushed (ice through the gate, in H_i), the count,
// spacing quartiles, median depth, the window and the damaged shares.
nlohmann::json field_row(const ParticleSnapshot& snapshot, const analysis::CrevasseMeasurement& m);

}  // namespace crevasse
