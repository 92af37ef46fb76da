#include "study/field_observations.hpp"

#include <cmath>
#include <set>

#include <nlohmann/json.hpp>

#include "engine/error.hpp"
#include "engine/json_input.hpp"
#include "study/scene_file.hpp"
#include "study/study_fit.hpp"

namespace crevasse {
namespace {

using nlohmann::json;

std::string where(const std::string& path, std::size_t k, const std::string& field) {
  return path + ": observations[" + std::to_string(k) + "]." + field;
}

double positive_number(const json& e, const std::string& key, const std::string& at) {
  const Range allowed{0.0, 1e6, true, false};
  if (!e.contains(key) || !e[key].is_number()) fail(at, "needs a number in " + allowed.text());
  const double v = e[key].get<double>();
  check_range(at, v, allowed);
  return v;
}

std::string text(const json& e, const std::string& key, const std::string& at, bool required) {
  if (!e.contains(key)) {
    if (required) throw InputError(at + ": missing (a non-empty string is required)");
    return "";
  }
  if (!e[key].is_string() || (required && e[key].get<std::string>().empty()))
    throw InputError(at + ": must be a non-empty string");
  return e[key].get<std::string>();
}

std::optional<std::pair<double, double>> pair_around(const json& e, const std::string& key,
                                                     const std::string& at, double spacing) {
  if (!e.contains(key)) return std::nullopt;
  const json& v = e[key];
  if (!v.is_array() || v.size() != 2 || !v[0].is_number() || !v[1].is_number())
    throw InputError(at + ": must be [low, high] in metres");
  const double lo = v[0].get<double>(), hi = v[1].get<double>();
  if (!(lo > 0.0 && lo <= spacing && spacing <= hi && hi <= 1e6))
    throw InputError(at + ": need 0 < low <= spacing_median_m <= high, got [" + short_number(lo) +
                     ", " + short_number(hi) + "] around " + short_number(spacing));
  return std::make_pair(lo, hi);
}

std::vector<LiteratureStrength> literature_strengths(const json& doc, const std::string& path) {
  std::vector<LiteratureStrength> out;
  if (!doc.contains("tensile_strength_literature")) return out;
  const json& list = doc["tensile_strength_literature"];
  const std::string name = path + ": tensile_strength_literature";
  if (!list.is_array()) throw InputError(name + ": must be an array of entries");
  std::set<std::string> ids;
  for (std::size_t k = 0; k < list.size(); ++k) {
    const std::string entry = name + "[" + std::to_string(k) + "]";
    const json& e = list[k];
    if (!e.is_object()) throw InputError(entry + " must be an object");
    refuse_unknown_keys(e, entry,
                        {"id", "value_kpa_low", "value_kpa_high", "method", "reference",
                         "where_in_reference", "read_at", "notes"});
    LiteratureStrength s;
    s.id = text(e, "id", entry + ".id", true);
    if (!ids.insert(s.id).second) throw InputError(entry + ".id: '" + s.id + "' is repeated");
    s.low_kpa = positive_number(e, "value_kpa_low", entry + ".value_kpa_low");
    s.high_kpa = positive_number(e, "value_kpa_high", entry + ".value_kpa_high");
    if (s.high_kpa < s.low_kpa)
      throw InputError(entry + ".value_kpa_high: " + short_number(s.high_kpa) + " is below value_kpa_low " +
                       short_number(s.low_kpa) + " (need low <= high)");
    s.method = text(e, "method", entry + ".method", true);
    s.reference = text(e, "reference", entry + ".reference", true);
    out.push_back(std::move(s));
  }
  return out;
}

}  // namespace

FieldObservationFile load_field_observations(const std::string& path) {
  const json doc = parse_json_input<json>(read_input_file(path, "--observations"), path);
  if (!doc.is_object() || !doc.contains("observations") || !doc["observations"].is_array() ||
      doc["observations"].empty())
    throw InputError(path + ": observations: needs a non-empty array of sites");
  refuse_unknown_keys(doc, path, {"description", "observations", "tensile_strength_literature"});
  FieldObservationFile file;
  std::vector<FieldObservation>& out = file.sites;
  std::set<std::string> ids;
  const json& list = doc["observations"];
  for (std::size_t k = 0; k < list.size(); ++k) {
    const json& e = list[k];
    if (!e.is_object()) throw InputError(where(path, k, "") + " must be an object");
    refuse_unknown_keys(e, path + ": observations[" + std::to_string(k) + "]",
                        {"id", "site", "setting", "spacing_median_m", "spacing_statistic",
                         "spacing_quartiles_m", "spacing_range_m", "spacing_sd_m", "thickness_m",
                         "thickness_note", "reference", "where_in_reference", "read_at", "notes"});
    FieldObservation o;
    o.id = text(e, "id", where(path, k, "id"), true);
    if (!ids.insert(o.id).second) throw InputError(where(path, k, "id") + ": '" + o.id + "' is repeated");
    o.site = text(e, "site", where(path, k, "site"), true);
    o.setting = text(e, "setting", where(path, k, "setting"), false);
    o.reference = text(e, "reference", where(path, k, "reference"), true);
    o.spacing_m = positive_number(e, "spacing_median_m", where(path, k, "spacing_median_m"));
    o.statistic = text(e, "spacing_statistic", where(path, k, "spacing_statistic"), true);
    if (o.statistic != "median" && o.statistic != "mean" && o.statistic != "typical" &&
        o.statistic != "mode")
      throw InputError(where(path, k, "spacing_statistic") + ": '" + o.statistic +
                       "' is not one of median, mean, typical, mode");
    o.quartiles_m = pair_around(e, "spacing_quartiles_m", where(path, k, "spacing_quartiles_m"), o.spacing_m);
    o.range_m = pair_around(e, "spacing_range_m", where(path, k, "spacing_range_m"), o.spacing_m);
    if (e.contains("spacing_sd_m")) o.sd_m = positive_number(e, "spacing_sd_m", where(path, k, "spacing_sd_m"));
    if (!e.contains("thickness_m"))
      throw InputError(where(path, k, "thickness_m") + ": missing (a number in (0, 1e6], or null when unknown)");
    if (!e["thickness_m"].is_null())
      o.thickness_m = positive_number(e, "thickness_m", where(path, k, "thickness_m"));
    out.push_back(std::move(o));
  }
  file.literature = literature_strengths(doc, path);
  return file;
}

analysis::SpacingObservation to_spacing_observation(const FieldObservation& o, std::string* spread) {
  analysis::SpacingObservation s;
  s.spacing_m = o.spacing_m;
  s.thickness_m = o.thickness_m;
  std::string used = "none given";
  if (o.quartiles_m) {
    s.spacing_q25_m = o.quartiles_m->first;
    s.spacing_q75_m = o.quartiles_m->second;
    used = "quartiles";
  } else if (o.sd_m) {
    const double half = std::max(0.674 * *o.sd_m, 0.05 * o.spacing_m);
    s.spacing_q25_m = std::max(o.spacing_m - half, 0.05 * o.spacing_m);
    s.spacing_q75_m = o.spacing_m + half;
    used = "±0.674 sd";
  } else if (o.range_m) {
    s.spacing_q25_m = o.range_m->first;
    s.spacing_q75_m = o.range_m->second;
    used = "range as quartiles";
  }
  if (spread) *spread = used;
  return s;
}

}  // namespace crevasse
