#pragma once
// The `fits` table of a study database (docs/database.md): what `crevasse fit` found, one row
// per fitted law and regime, kept next to the cases it came from. Rows carry the full sampling
// distribution of each law (ln a, b, their covariance, s², dof) so that `crevasse calibrate`
// and `predict` use exactly the laws the table shows. Created on first use; writing replaces the
// rows of one (quantity, group) in one transaction and touches no other table.
#include <optional>
#include <string>
#include <vector>

#include "analysis/power_law_fit.hpp"
#include "study/store.hpp"
#include "study/study_fit.hpp"

namespace crevasse {

struct FitRecord {
  std::string quantity;    // spacing_over_h, depth_over_h
  std::string group_name;  // cohesion_ratio, thickness, ...
  std::string model;       // single, broken
  std::string regime;      // all (single), below, above (the broken line's segments)
  std::string status;      // ok, not_enough_data
  std::string note;        // why not_enough_data (empty when ok)
  std::string accounting;  // cases fitted and left out, with the reasons
  std::int64_t n = 0;      // cases fitted (in this segment for a broken line)
  double level = 0.95;
  std::optional<double> exponent, exponent_lo, exponent_hi;
  bool exponent_fixed = false;
  std::optional<double> prefactor, prefactor_lo, prefactor_hi;
  // The law ln y = ln a + b ln x and the covariance of (ln a, b), s² and dof (calibration).
  std::optional<double> log_prefactor, var_log_prefactor, cov_log_prefactor_exponent, var_exponent;
  std::optional<double> residual_variance, dof;
  std::optional<double> x_min, x_max, y_min, y_max;  // data the law (segment) was fitted to
  std::optional<double> breakpoint, breakpoint_lo, breakpoint_hi;
  bool breakpoint_clipped_low = false, breakpoint_clipped_high = false;
  std::optional<double> r_squared, aic;
  // Single law against broken line (on both models' rows).
  std::optional<double> f_statistic, p_value, aic_single, aic_broken;
  std::optional<bool> two_regimes;
  std::string fixed_exponents;  // "1,free" as given to crevasse fit, or ""
  std::string created_at;

  bool ok() const { return status == "ok"; }
  // The law of an ok row, for calibration.
  analysis::PowerLaw law() const;
};

// Rows for one StudyFit: the single law ("all") and the broken line's two segments ("below",
// "above"), or a not_enough_data row in place of a model that could not be fitted.
// Keyed by fit_quantity_key(fit.quantity, reading).
std::vector<FitRecord> fit_records(const StudyFit& fit, const std::string& created_at,
                                   CaseReading reading = CaseReading::window);

// Replaces the rows of (quantity, group_name) by `records` in one transaction, creating the
// table when absent.
void replace_fit_records(Store& store, const std::string& quantity, const std::string& group_name,
                         const std::vector<FitRecord>& records);
// Replaces the rows of every (quantity, group_name) that `records` holds, all in one
// transaction: a fit killed midway leaves the old rows or all the new ones, never a mix.
void replace_fit_records(Store& store, const std::vector<FitRecord>& records);

// Whether `crevasse fit` has created the table (it is not part of the study schema).
bool has_fits_table(Store& store);

// Rows of (quantity, group_name); empty when there are none or the table does not exist.
std::vector<FitRecord> read_fit_records(Store& store, const std::string& quantity,
                                        const std::string& group_name);

}  // namespace crevasse
