#pragma once
// Field observations of crevasse spacing (studies/field/observations.json,
// docs/field_observations.md), read for `crevasse calibrate --observations`. Each entry is one
// site: the published spacing (median, mean or typical value), whatever spread the source gives
// (quartiles, range or standard deviation), the ice thickness when known, and the reference.
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "analysis/calibration.hpp"

namespace crevasse {

struct FieldObservation {
  std::string id;
  std::string site;
  std::string setting;
  double spacing_m = 0.0;
  std::string statistic;  // median | mean | typical | mode
  std::optional<std::pair<double, double>> quartiles_m;
  std::optional<std::pair<double, double>> range_m;
  std::optional<double> sd_m;
  std::optional<double> thickness_m;
  std::string reference;
};

// A published tensile strength of ice (the file's `tensile_strength_literature`), shown beside
// the calibrated strengths. A single value has low == high.
struct LiteratureStrength {
  std::string id;
  double low_kpa = 0.0, high_kpa = 0.0;
  std::string method;
  std::string reference;
};

struct FieldObservationFile {
  std::vector<FieldObservation> sites;
  std::vector<LiteratureStrength> literature;  // empty when the file has none
};

// Reads and checks the file. Throws InputError naming the entry and field (one line) for a
// missing or malformed value, a non-positive spacing or thickness, a spread that does not hold
// the spacing, a literature strength outside (0, 1e6] kPa or with its low above its high, or a
// repeated id.
FieldObservationFile load_field_observations(const std::string& path);

// The observation as the calibration takes it. The spread becomes quartiles: given quartiles
// as they are; else a standard deviation as spacing ± 0.674·sd (the quartiles of a normal
// distribution), floored at 5 % of the spacing; else a published min–max range used as if it
// were the quartiles (wider than the true quartiles, so the interval errs wide); else none.
// `spread` says which was used.
analysis::SpacingObservation to_spacing_observation(const FieldObservation& o, std::string* spread);

}  // namespace crevasse
