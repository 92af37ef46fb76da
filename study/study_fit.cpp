#include "study/study_fit.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <set>
#include <stdexcept>

#include "engine/error.hpp"

namespace crevasse {

std::string short_number(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.4g", v);
  return buf;
}

namespace {

std::optional<double> parse_exponent(const std::string& text, const std::string& option) {
  if (text == "free" || text == "-" || text.empty()) return std::nullopt;
  try {
    std::size_t used = 0;
    const double v = std::stod(text, &used);
    // A fitted log-log exponent beyond ±100 would overflow Π^b over any sensible range.
    if (used == text.size() && std::isfinite(v) && std::abs(v) <= 100.0) return v;
  } catch (const std::exception&) {
  }
  throw InputError(option + ": '" + text +
                   "' is not an exponent; give a number in [-100, 100] or 'free'");
}

}  // namespace

double StudyFit::broken_r_squared() const {
  if (!broken || !single) return 0.0;
  // The single law's total sum of squares is the same data's: SS_tot = RSS/(1 − R²).
  const double ss_tot = single->rss / std::max(1.0 - single->r_squared, 1e-300);
  return ss_tot > 0.0 ? 1.0 - broken->rss / ss_tot : 1.0;
}

std::string StudyFit::accounting() const {
  std::string text =
      std::to_string(x.size()) + " of " + std::to_string(case_count) + " cases fitted";
  if (!skipped.empty()) {
    text += "; not fitted:";
    bool first = true;
    for (const auto& [reason, n] : skipped) {
      text += (first ? " " : ", ") + std::to_string(n) + " " + reason;
      first = false;
    }
  }
  if (fragmented_fitted > 0)
    text += "; " + std::to_string(fragmented_fitted) + " fitted case(s) flagged fragmented";
  return text;
}

StudyFit fit_study(const std::vector<CaseRecord>& cases, Quantity quantity, const FitGroup& group,
                   const StudyFitOptions& options) {
  StudyFit fit;
  fit.quantity = quantity;
  fit.group = &group;
  fit.options = options;
  fit.case_count = cases.size();
  for (const CaseRecord& c : cases) {
    const std::optional<double> x = c.group(group);
    const std::optional<double> y = c.median(quantity);
    std::string reason = c.missing_reason(quantity);
    if (reason.empty() && (!x || !std::isfinite(*x) || *x <= 0.0))
      reason = std::string("without a positive ") + group.name;
    if (reason.empty() && !options.include_under_resolved && c.under_resolved)
      reason = kUnderResolvedExcluded;
    if (reason.empty() && options.exclude_fragmented && c.fragmented)
      reason = kFragmentedExcluded;
    if (!reason.empty()) {
      ++fit.skipped[reason];
      continue;
    }
    fit.x.push_back(*x);
    fit.y.push_back(*y);
    fit.case_indexes.push_back(c.case_index);
    if (c.fragmented) ++fit.fragmented_fitted;
  }

  const std::set<double> distinct(fit.x.begin(), fit.x.end());
  if (fit.x.size() < 3) {
    fit.single_problem =
        std::to_string(fit.x.size()) + " case(s) with a value, a power law needs 3";
  } else if (distinct.size() < 2) {
    fit.single_problem = "all " + std::to_string(fit.x.size()) + " cases have " + group.name +
                         " = " + short_number(fit.x.front()) + " (the group does not vary)";
  } else {
    try {
      fit.single = analysis::fit_power_law(fit.x, fit.y, options.level);
    } catch (const std::invalid_argument& e) {
      fit.single_problem = e.what();
    }
  }

  analysis::BrokenLineOptions broken_options;
  broken_options.level = options.level;
  broken_options.fixed_b1 = options.fixed_b1;
  broken_options.fixed_b2 = options.fixed_b2;
  const std::size_t need = 2 * broken_options.min_points_per_side;
  if (fit.x.size() < need || distinct.size() < 4) {
    fit.broken_problem = std::to_string(fit.x.size()) + " case(s) at " +
                         std::to_string(distinct.size()) + " distinct " + group.name +
                         ", a broken line needs " + std::to_string(need) + " at 4 distinct values";
  } else if (!fit.single) {
    fit.broken_problem = fit.single_problem;
  } else {
    try {
      fit.broken = analysis::fit_broken_line(fit.x, fit.y, broken_options);
    } catch (const std::invalid_argument& e) {
      fit.broken_problem = e.what();
    }
  }
  return fit;
}

void parse_fixed_exponents(const std::string& text, const std::string& option,
                           StudyFitOptions& options) {
  const auto comma = text.find(',');
  if (comma == std::string::npos || text.find(',', comma + 1) != std::string::npos)
    throw InputError(option + ": expected B1,B2 (each a number or 'free', e.g. 1,free), got '" +
                     text + "'");
  options.fixed_b1 = parse_exponent(text.substr(0, comma), option);
  options.fixed_b2 = parse_exponent(text.substr(comma + 1), option);
}

std::string fixed_exponents_text(const StudyFitOptions& options) {
  if (!options.fixed_b1 && !options.fixed_b2) return {};
  const auto one = [](const std::optional<double>& b) { return b ? short_number(*b) : "free"; };
  return one(options.fixed_b1) + "," + one(options.fixed_b2);
}

}  // namespace crevasse
