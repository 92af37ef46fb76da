#pragma once
// The per-case results of a study database as the analysis reads them (docs/study_format.md): each case's
// groups (docs/model.md), status, the quartiles of L_p/H_i and D_p/H_i, its spacings, and why a case
// has no value when it has none. Shared by `crevasse fit`, `plot`, `calibrate` and `predict`.
#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "study/store.hpp"

namespace crevasse {

// A dimensionless group (or H_i) that a fit or figure can put on its horizontal axis.
struct FitGroup {
  const char* name;    // as on the command line and in the fits table: "cohesion_ratio"
  const char* column;  // column of the cases table
  const char* symbol;  // figure/table markup: "Π"
  const char* axis_label;
};

inline constexpr FitGroup kFitGroups[] = {
    {"cohesion_ratio", "cohesion_ratio", "Π", "Π = c/(ρ_i g H_i)"},
    {"thickness", "thickness_m", "H_i", "H_i [m]"},
    {"step_length_ratio", "step_length_ratio", "r", "r = L_s/H_i"},
    {"step_height_ratio", "step_height_ratio", "h", "h = H_s/H_i"},
    {"slope", "slope", "S", "S = H_s/L_s"},
    {"width_ratio", "width_ratio", "w", "w = W_i/H_i"},
};

// The group called `name`; throws InputError naming `option` and the allowed names.
const FitGroup& find_fit_group(const std::string& name, const std::string& option);
// "cohesion_ratio, thickness, ...".
std::string fit_group_names();

// The responses fitted against a group: median L_p/H_i and median D_p/H_i per case.
enum class Quantity { spacing, depth };
inline constexpr Quantity kQuantities[] = {Quantity::spacing, Quantity::depth};
const char* quantity_key(Quantity q);     // "spacing_over_h", "depth_over_h" (fits table)
const char* quantity_symbol(Quantity q);  // "L_p/H_i", "D_p/H_i"

// Which crevasses of each case are read (docs/measurement.md, "The ramp's ice", "Clear of the front").
enum class CaseReading {
  window,          // the measurement's whole window: the stored summary
  ramp_ice,        // draped frame: the window's first L_s, the ice that lay over the ramp at the start
  clear_of_front,  // draped or final frame: the window but its last H_i, next to the outflow's face
};
// What the reading's fits keys and figure files start with: "", "ramp_ice_", "clear_of_front_".
const char* reading_prefix(CaseReading reading);
// The fits table's key of `q` read so: "spacing_over_h", "ramp_ice_spacing_over_h", ...
std::string fit_quantity_key(Quantity q, CaseReading reading);
// "", "ramp ice" or "clear of the front": what a table or figure adds to its field's label.
const char* reading_label(CaseReading reading);
// The command-line flag that selects it: "", "--ramp-ice" or "--clear-of-front".
const char* reading_flag(CaseReading reading);

struct CaseRecord {
  std::string case_id;
  std::int64_t case_index = 0;
  std::string label;
  std::string status;  // pending, running, done, failed
  std::string failure_reason;
  // Group values in the order of kFitGroups; empty where the group does not apply (slope of a
  // vertical step, width in 2D).
  std::array<std::optional<double>, std::size(kFitGroups)> groups;
  bool has_summary = false;  // done cases with a measurement
  std::int64_t crevasse_count = 0;
  std::int64_t spacing_count = 0;
  bool no_crevasse = false;
  bool fragmented = false;
  bool under_resolved = false;  // c/(ρ_i g) < 3 dx: the strength regime cannot show
  // q25, median, q75 of L_p/H_i and of D_p/H_i (empty when nothing was measured).
  std::array<std::optional<double>, 3> spacing_over_h, depth_over_h;
  std::vector<double> spacings_m;  // every spacing kept [m]
  std::vector<double> depths_m;    // every crevasse's depth [m]
  double dx_m = 0.0;               // the case's grid spacing [m]

  double thickness_m() const { return groups[1].value_or(0.0); }
  double cohesion_ratio() const { return groups[0].value_or(0.0); }
  std::optional<double> group(const FitGroup& g) const;
  const std::array<std::optional<double>, 3>& quartiles(Quantity q) const {
    return q == Quantity::spacing ? spacing_over_h : depth_over_h;
  }
  // The median of `q`, present only when it is finite and positive (fit- and log-axis-ready).
  std::optional<double> median(Quantity q) const;
  // Why median(q) is empty: "failed", "not run yet", "no crevasse", "fewer than 2 crevasses",
  // "no spacing above the resolution floor", "non-positive value". Empty when it has a value.
  std::string missing_reason(Quantity q) const;
};

// Every case of the database, by case_index. Throws InputError when the database holds no
// study or no cases, and for a reading the study's frame does not allow (ramp_ice: draped only;
// clear_of_front: draped or final, the windows that end at the front).
std::vector<CaseRecord> read_case_records(Store& store, CaseReading reading = CaseReading::window);

// The study's name, or `fallback` when the database holds no study.
std::string study_name(Store& store, const std::string& fallback);
// What a figure or fit says it shows: "initiation protocol, draped frame" (a study that names its
// protocol), "passed frame" (one that does not), or "" (no study row); a reading other than the
// window's follows: "initiation protocol, draped frame, clear of the front".
std::string study_field_label(Store& store, CaseReading reading = CaseReading::window);
// The name with its field: "regime_steady (steady protocol, passed frame)", as figures label a study.
std::string study_name_with_field(Store& store, const std::string& fallback,
                                  CaseReading reading = CaseReading::window);

// "study 'quick', initiation protocol, draped frame (results/quick.db)".
std::string study_title(Store& store, CaseReading reading = CaseReading::window);

}  // namespace crevasse
