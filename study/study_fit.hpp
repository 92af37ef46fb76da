#pragma once
// Fits of one study's per-case medians (L_p/H_i or D_p/H_i) against one group (docs/fits.md §7): a
// single power law and a continuous broken line with its comparison (docs/fits.md), with an
// account of every case that was not fitted and why. Too little data is not an error here: the
// fit is absent and `*_problem` says why, so that the table can show a "not enough data" row.
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "analysis/broken_line_fit.hpp"
#include "analysis/power_law_fit.hpp"
#include "study/case_results.hpp"

namespace crevasse {

// A number for messages and tables: %.4g.
std::string short_number(double v);


// The reason a fit gives for a fragmented case it left out; it is in the fits table's
// `accounting`, which is how `crevasse plot` knows the stored fits left such cases out.
inline constexpr const char* kFragmentedExcluded = "fragmented (excluded)";
inline constexpr const char* kUnderResolvedExcluded = "under-resolved (excluded)";

struct StudyFitOptions {
  double level = 0.95;
  // Exponents of the broken line's segments held at a value (below, above Π*); empty = free.
  std::optional<double> fixed_b1, fixed_b2;
  bool exclude_fragmented = false;  // leave out cases flagged fragmented (kFragmentedExcluded)
  // Fit cases flagged under_resolved too (by default they are left out: kUnderResolvedExcluded).
  bool include_under_resolved = false;
};

struct StudyFit {
  Quantity quantity = Quantity::spacing;
  const FitGroup* group = &kFitGroups[0];
  StudyFitOptions options;
  std::vector<double> x, y;                    // the rows fitted
  std::vector<std::int64_t> case_indexes;      // of those rows
  std::size_t case_count = 0;                  // cases in the database
  std::map<std::string, std::size_t> skipped;  // reason → number of cases not fitted
  std::size_t fragmented_fitted = 0;           // fitted cases flagged fragmented

  std::optional<analysis::PowerLawFit> single;
  std::string single_problem;  // why `single` is empty
  std::optional<analysis::BrokenLineFit> broken;
  std::string broken_problem;  // why `broken` is empty

  // R² of the broken line in log space (same data as the single law).
  double broken_r_squared() const;
  // The broken line when it was fitted and two regimes are warranted.
  bool two_regimes() const { return broken && broken->comparison.two_regimes_warranted; }
  // "12 fitted; not fitted: 2 failed, 3 no crevasse".
  std::string accounting() const;
};

StudyFit fit_study(const std::vector<CaseRecord>& cases, Quantity quantity, const FitGroup& group,
                   const StudyFitOptions& options = {});

// Parses "--fixed-exponents B1,B2" where each is a number or "free"; throws InputError naming
// `option`.
void parse_fixed_exponents(const std::string& text, const std::string& option,
                           StudyFitOptions& options);
std::string fixed_exponents_text(const StudyFitOptions& options);  // "1,free" or ""

}  // namespace crevasse
