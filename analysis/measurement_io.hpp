#pragma once
// Files written for one measured snapshot: crevasses.csv (one row per crevasse) and a JSON
// summary with the statistics, flags, full lists and the settings used (docs/measurement.md: every
// result carries its threshold, window and timing).
#include <filesystem>
#include <nlohmann/json.hpp>

#include "analysis/crevasse_measure.hpp"

namespace crevasse::analysis {

// Header: index,x_m,depth_m,width_m,depth_over_H,spacing_to_next_m. The last crevasse has an
// empty spacing field (there is no next one); no field is ever NaN.
void write_crevasses_csv(const CrevasseMeasurement& measurement, const std::filesystem::path& path);

nlohmann::json settings_to_json(const ResolvedMeasureSettings& settings);
// Absent statistics are JSON null, alongside the explicit flags (has_spacing, no_crevasse, …).
nlohmann::json measurement_summary_json(const CrevasseMeasurement& measurement);
void write_measurement_summary(const CrevasseMeasurement& measurement,
                               const std::filesystem::path& path);

}  // namespace crevasse::analysis
