#include "study/case_results.hpp"

#include <cmath>
#include <nlohmann/json.hpp>

#include "analysis/crevasse_measure.hpp"
#include "engine/error.hpp"
#include "engine/json_input.hpp"

namespace crevasse {

const FitGroup& find_fit_group(const std::string& name, const std::string& option) {
  for (const FitGroup& g : kFitGroups)
    if (name == g.name) return g;
  throw InputError(option + ": unknown group '" + name + "'; allowed: " + fit_group_names());
}

std::string fit_group_names() {
  std::string names;
  for (const FitGroup& g : kFitGroups) names += (names.empty() ? "" : ", ") + std::string(g.name);
  return names;
}

const char* quantity_key(Quantity q) {
  return q == Quantity::spacing ? "spacing_over_h" : "depth_over_h";
}
const char* quantity_symbol(Quantity q) { return q == Quantity::spacing ? "L_p/H_i" : "D_p/H_i"; }

namespace {
// Each reading's names, in the order of CaseReading: key and file prefix, title label, flag.
struct ReadingNames {
  const char* prefix;
  const char* label;
  const char* flag;
};
constexpr ReadingNames kReadingNames[] = {
    {"", "", ""},
    {"ramp_ice_", "ramp ice", "--ramp-ice"},
    {"clear_of_front_", "clear of the front", "--clear-of-front"},
};
static_assert(std::size(kReadingNames) == static_cast<std::size_t>(CaseReading::clear_of_front) + 1);
const ReadingNames& names(CaseReading reading) {
  return kReadingNames[static_cast<std::size_t>(reading)];
}
}  // namespace

const char* reading_prefix(CaseReading reading) { return names(reading).prefix; }
const char* reading_label(CaseReading reading) { return names(reading).label; }
const char* reading_flag(CaseReading reading) { return names(reading).flag; }

std::string fit_quantity_key(Quantity q, CaseReading reading) {
  return reading_prefix(reading) + std::string(quantity_key(q));
}

std::optional<double> CaseRecord::group(const FitGroup& g) const {
  for (std::size_t i = 0; i < std::size(kFitGroups); ++i)
    if (std::string(kFitGroups[i].name) == g.name) return groups[i];
  return std::nullopt;
}

std::optional<double> CaseRecord::median(Quantity q) const {
  const std::optional<double> m = quartiles(q)[1];
  if (!m || !std::isfinite(*m) || *m <= 0.0) return std::nullopt;
  return m;
}

std::string CaseRecord::missing_reason(Quantity q) const {
  if (median(q)) return {};
  if (status == "failed") return "failed";
  if (status != "done") return "not run yet";
  if (!has_summary || no_crevasse || crevasse_count == 0) return "no crevasse";
  if (quartiles(q)[1]) return "non-positive value";
  if (q == Quantity::spacing && crevasse_count < 2) return "fewer than 2 crevasses";
  if (q == Quantity::spacing) return "no spacing above the resolution floor";
  return "no value";
}

namespace {

// Re-reads each measured case from its stored crevasses in part of its window: their count,
// depths and the spacings the measurement kept between two of them, with quartiles over H_i.
// Status, groups and flags stay the case's. The part: the window's first L_s (ramp_ice), or the
// window but its last H_i (clear_of_front).
void read_part_of_window(Store& store, const std::string& where, CaseReading reading,
                         std::vector<CaseRecord>& cases) {
  sqlite3* db = store.handle();
  const std::string flag = reading_flag(reading);
  {
    Statement s(db, "SELECT json_extract(measurement_json, '$.frame') FROM study WHERE id = 1");
    const std::string frame = s.step() ? s.text(0) : "";
    const std::string measured_in = (frame.empty() ? std::string("default") : "'" + frame + "'");
    if (reading == CaseReading::ramp_ice && frame != "draped")
      throw InputError(flag + ": " + where + " was measured in the " + measured_in +
                       " frame; the ramp's ice is read in the draped frame only (a study with "
                       "\"protocol\": \"initiation\" or \"measurement\": {\"frame\": \"draped\"})");
    if (reading == CaseReading::clear_of_front && frame != "draped" && frame != "final")
      throw InputError(flag + ": " + where + " was measured in the " + measured_in +
                       " frame; allowed: the 'draped' and 'final' frames, whose windows end at the "
                       "ice front");
  }
  Statement window(db,
                   "SELECT m.window_min_x_m, m.window_max_x_m, "
                   "json_extract(c.scene_json, '$.bed.step_length') "
                   "FROM summaries m JOIN cases c USING (case_id) WHERE case_id = ?");
  Statement cracks(
      db, "SELECT x_m, depth_m, spacing_to_next_m FROM crevasses WHERE case_id = ? ORDER BY x_m");
  for (CaseRecord& r : cases) {
    if (!r.has_summary) continue;
    window.reset();
    window.bind(1, r.case_id);
    if (!window.step()) continue;  // has_summary: the row is there
    const bool no_ramp = window.is_null(2) || !(window.real(2) > 0.0);
    if (reading == CaseReading::ramp_ice && no_ramp)
      throw InputError(flag + ": " + where + ": case " + r.label +
                       " has no ramp (bed.step_length absent or 0: a vertical step); allowed: "
                       "studies whose every step has a ramp");
    const double end = reading == CaseReading::ramp_ice ? window.real(0) + window.real(2)
                                                        : window.real(1) - r.thickness_m();
    std::vector<double> depths, spacings;
    std::optional<double> spacing_before;  // the previous crevasse's spacing to this one
    cracks.reset();
    cracks.bind(1, r.case_id);
    while (cracks.step() && cracks.real(0) <= end) {
      if (spacing_before) spacings.push_back(*spacing_before);
      depths.push_back(cracks.real(1));
      spacing_before = cracks.optional_real(2);
    }
    const double inv_h = 1.0 / r.thickness_m();
    const auto over_h = [inv_h](const std::vector<double>& v) {
      std::array<std::optional<double>, 3> q;
      if (v.empty()) return q;
      const analysis::QuartileSummary s = analysis::quartiles(v);
      q = {s.q25 * inv_h, s.median * inv_h, s.q75 * inv_h};
      return q;
    };
    r.crevasse_count = static_cast<std::int64_t>(depths.size());
    r.spacing_count = static_cast<std::int64_t>(spacings.size());
    r.no_crevasse = depths.empty();
    r.spacing_over_h = over_h(spacings);
    r.depth_over_h = over_h(depths);
    r.spacings_m = std::move(spacings);
    r.depths_m = std::move(depths);
  }
}

}  // namespace

std::vector<CaseRecord> read_case_records(Store& store, CaseReading reading) {
  sqlite3* db = store.handle();
  const std::string where = store.path().string();
  {
    Statement s(db, "SELECT count(*) FROM study");
    s.step();
    if (s.integer(0) == 0)
      throw InputError(where + ": the database holds no study yet; run crevasse study first");
  }
  std::string columns;
  for (const FitGroup& g : kFitGroups) columns += "c." + std::string(g.column) + ", ";
  Statement s(
      db, "SELECT c.case_id, c.case_index, c.label, c.status, coalesce(c.failure_reason, ''), " +
              columns +
              "m.case_id IS NOT NULL, m.crevasse_count, m.spacing_count, m.no_crevasse, "
              "m.fragmented, m.spacing_q25_over_h, m.spacing_median_over_h, "
              "m.spacing_q75_over_h, m.depth_q25_over_h, m.depth_median_over_h, "
              "m.depth_q75_over_h, m.spacings_json, " +
              store.under_resolved_column() +
              ", json_extract(c.result_json, '$.measurement.depths_m'), c.dx_m" +
              " FROM cases c LEFT JOIN summaries m USING (case_id) ORDER BY c.case_index, "
              "c.replica, c.case_id");
  std::vector<CaseRecord> out;
  while (s.step()) {
    CaseRecord r;
    int k = 0;
    r.case_id = s.text(k++);
    r.case_index = s.integer(k++);
    r.label = s.text(k++);
    r.status = s.text(k++);
    r.failure_reason = s.text(k++);
    for (auto& g : r.groups) g = s.optional_real(k++);
    r.has_summary = s.integer(k++) != 0;
    const std::string about = where + ": case " + r.label + " (" + r.case_id.substr(0, 12) + ")";
    const std::string remedy =
        ": the database is inconsistent (edited by hand or by another tool); set the case back "
        "to pending (UPDATE cases SET status = 'pending' WHERE case_id = '" + r.case_id +
        "') and run its study again, or restore the database";
    if (r.status == "done" && !r.has_summary)
      throw InputError(about + " is done but has no summaries row" + remedy);
    for (int c = k; r.has_summary && c < k + 10; ++c)
      if (!s.is_null(c) && !s.is_finite_number(c))
        throw InputError(about + ": summaries." + s.column_name(c) + " holds '" + s.text(c) +
                         "', not a finite number" + remedy);
    r.crevasse_count = s.integer(k++);
    r.spacing_count = s.integer(k++);
    r.no_crevasse = s.integer(k++) != 0;
    r.fragmented = s.integer(k++) != 0;
    for (auto& q : r.spacing_over_h) q = s.optional_real(k++);
    for (auto& q : r.depth_over_h) q = s.optional_real(k++);
    // A stored JSON array of numbers (absent for cases without a measurement).
    const auto numbers = [&](int column, std::vector<double>& into) {
      if (s.is_null(column)) return;
      const auto j = parse_stored_json(s.text(column));
      if (j.is_array())
        for (const auto& v : j)
          if (v.is_number()) into.push_back(v.get<double>());
    };
    numbers(k++, r.spacings_m);
    r.under_resolved = s.integer(k++) != 0;
    numbers(k++, r.depths_m);
    r.dx_m = s.is_null(k) ? 0.0 : s.real(k);
    ++k;
    out.push_back(std::move(r));
  }
  if (out.empty()) throw InputError(where + ": the study has no cases");
  if (reading != CaseReading::window) read_part_of_window(store, where, reading, out);
  return out;
}

std::string study_name(Store& store, const std::string& fallback) {
  Statement s(store.handle(), "SELECT name FROM study WHERE id = 1");
  return s.step() ? s.text(0) : fallback;
}

namespace {
std::string protocol_and_frame(Store& store) {
  Statement s(store.handle(), "SELECT file_text, measurement_json FROM study WHERE id = 1");
  if (!s.step()) return "";
  const auto file = nlohmann::json::parse(s.text(0), nullptr, false);
  const auto measurement = nlohmann::json::parse(s.text(1), nullptr, false);
  std::string frame;
  if (measurement.is_object() && measurement.contains("frame") && measurement.at("frame").is_string())
    frame = measurement.at("frame").get<std::string>();
  if (file.is_object() && file.contains("protocol") && file.at("protocol").is_string())
    return file.at("protocol").get<std::string>() + " protocol, " + frame + " frame";
  return frame.empty() ? "" : frame + " frame";
}
}  // namespace

std::string study_field_label(Store& store, CaseReading reading) {
  const std::string field = protocol_and_frame(store);
  const std::string read = reading_label(reading);
  if (read.empty()) return field;
  return field.empty() ? read : field + ", " + read;
}

std::string study_name_with_field(Store& store, const std::string& fallback, CaseReading reading) {
  const std::string label = study_field_label(store, reading);
  return study_name(store, fallback) + (label.empty() ? std::string() : " (" + label + ")");
}

std::string study_title(Store& store, CaseReading reading) {
  const std::string label = study_field_label(store, reading);
  return "study '" + study_name(store, "?") + "'" + (label.empty() ? "" : ", " + label) + " (" +
         store.path().string() + ")";
}

}  // namespace crevasse
