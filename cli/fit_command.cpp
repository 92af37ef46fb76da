#include "cli/fit_command.hpp"

#include <cmath>
#include <cstdio>
#include <optional>
#include <set>

#include "cli/cli_common.hpp"
#include "engine/error.hpp"
#include "study/case_results.hpp"
#include "study/fits_table.hpp"
#include "study/store.hpp"
#include "study/study_fit.hpp"

namespace crevasse {
namespace {

std::string num(const std::optional<double>& v, const char* format = "%.3g") {
  return v ? format_number(*v, format) : "-";
}

std::string interval(const std::optional<double>& lo, const std::optional<double>& hi,
                     bool clipped_lo = false, bool clipped_hi = false) {
  std::string text = "[";
  if (clipped_lo) text += "<=";
  text += num(lo) + ", ";
  if (clipped_hi) text += ">=";
  return text + num(hi) + "]";
}

std::string exponent_cell(const FitRecord& r) {
  if (r.exponent_fixed) return num(r.exponent) + " (fixed)";
  if (!r.exponent || !r.exponent_lo || !r.exponent_hi) return num(r.exponent);
  // The Wald interval is symmetric: b ± t·se.
  return num(r.exponent, "%.3f") + " +/- " + num(0.5 * (*r.exponent_hi - *r.exponent_lo), "%.3f");
}

std::string comparison_cell(const FitRecord& r) {
  if (r.model != "single" || !r.two_regimes) return "-";
  std::string p = !r.p_value           ? "F test n/a"
                  : *r.p_value < 0.001 ? "p < 0.001"
                                       : "p = " + num(r.p_value, "%.2g");
  const double daic = r.aic_broken.value_or(NAN) - r.aic_single.value_or(NAN);
  char buf[32];
  std::snprintf(buf, sizeof buf, "%+.1f", daic);
  return std::string(*r.two_regimes ? "two regimes" : "one regime") + " (" + p + ", dAIC " + buf +
         ")";
}

// ASCII symbols keep the columns aligned in any terminal.
const char* ascii_symbol(const FitGroup& g) {
  return std::string(g.name) == "cohesion_ratio" ? "Pi" : g.symbol;
}

void print_table(const std::vector<FitRecord>& records, const FitGroup& group, double level) {
  std::printf("\nagainst %s (%s), %.0f %% intervals:\n", group.name, ascii_symbol(group),
              100.0 * level);
  std::printf("  %-8s %-6s %-6s %4s  %-17s %-26s %-28s %6s  %s\n", "quantity", "model", "regime",
              "n", "exponent b", "prefactor a [CI]", "breakpoint [CI]", "R^2",
              "single vs broken line");
  for (const FitRecord& r : records) {
    const char* symbol = r.quantity.find("spacing") != std::string::npos ? "L_p/H_i" : "D_p/H_i";
    if (!r.ok()) {
      std::printf("  %-8s %-6s %-6s %4lld  NOT ENOUGH DATA: %s\n", symbol, r.model.c_str(),
                  r.regime.c_str(), static_cast<long long>(r.n), r.note.c_str());
      continue;
    }
    const std::string prefactor = num(r.prefactor) + " " + interval(r.prefactor_lo, r.prefactor_hi);
    const std::string breakpoint =
        r.breakpoint ? num(r.breakpoint) + " " +
                           interval(r.breakpoint_lo, r.breakpoint_hi, r.breakpoint_clipped_low,
                                    r.breakpoint_clipped_high)
                     : "-";
    std::printf("  %-8s %-6s %-6s %4lld  %-17s %-26s %-28s %6s  %s\n", symbol, r.model.c_str(),
                r.regime.c_str(), static_cast<long long>(r.n), exponent_cell(r).c_str(),
                prefactor.c_str(), breakpoint.c_str(), num(r.r_squared, "%.3f").c_str(),
                comparison_cell(r).c_str());
  }
}

// Groups that take at least two values among the cases.
std::vector<const FitGroup*> varying_groups(const std::vector<CaseRecord>& cases) {
  std::vector<const FitGroup*> out;
  for (const FitGroup& g : kFitGroups) {
    std::set<double> values;
    for (const CaseRecord& c : cases)
      if (const auto v = c.group(g)) values.insert(*v);
    if (values.size() >= 2) out.push_back(&g);
  }
  return out;
}

}  // namespace

int fit_command(const FitCommandOptions& opt) {
  check_confidence_level(opt.level);
  StudyFitOptions spacing_options, depth_options;
  spacing_options.level = depth_options.level = opt.level;
  spacing_options.exclude_fragmented = depth_options.exclude_fragmented = opt.exclude_fragmented;
  spacing_options.include_under_resolved = depth_options.include_under_resolved =
      opt.include_under_resolved;
  if (!opt.fixed_exponents.empty())
    parse_fixed_exponents(opt.fixed_exponents, "--fixed-exponents", spacing_options);
  if (!opt.fixed_depth_exponents.empty())
    parse_fixed_exponents(opt.fixed_depth_exponents, "--fixed-depth-exponents", depth_options);

  const CaseReading reading = opt.reading;
  std::vector<CaseRecord> cases;
  std::string title;
  {
    Store reader = Store::open_reader(opt.db_path);
    cases = read_case_records(reader, reading);
    title = study_title(reader, reading);
  }
  std::vector<const FitGroup*> groups;
  for (const std::string& name :
       opt.groups.empty() ? std::vector<std::string>{"cohesion_ratio"} : opt.groups) {
    if (name == "all") {
      for (const FitGroup* g : varying_groups(cases)) groups.push_back(g);
    } else {
      groups.push_back(&find_fit_group(name, "--group"));
    }
  }
  if (groups.empty())
    throw InputError("--group all: no group takes two or more values in " + opt.db_path +
                     "; nothing to fit against (try --group cohesion_ratio)");

  std::printf(
      "fits of %s: median L_p/H_i and D_p/H_i per case, log-log least squares "
      "(docs/fits.md)\n",
      title.c_str());
  const std::string now = utc_now_iso8601();
  std::vector<std::pair<const FitGroup*, std::vector<FitRecord>>> all;
  for (const FitGroup* group : groups) {
    std::vector<FitRecord> records;
    std::vector<std::string> notes;
    for (Quantity q : kQuantities) {
      const StudyFit fit =
          fit_study(cases, q, *group, q == Quantity::spacing ? spacing_options : depth_options);
      const auto rows = fit_records(fit, now, reading);
      records.insert(records.end(), rows.begin(), rows.end());
      notes.push_back(std::string(quantity_symbol(q)) + ": " + fit.accounting() +
                      (fit.options.fixed_b1 || fit.options.fixed_b2
                           ? "; broken-line exponents held at " + fixed_exponents_text(fit.options)
                           : ""));
    }
    print_table(records, *group, opt.level);
    for (const std::string& n : notes) std::printf("  %s\n", n.c_str());
    all.emplace_back(group, std::move(records));
  }

  if (opt.no_store) {
    std::printf("\nnot stored (--no-store)\n");
    return 0;
  }
  std::optional<Store> opened;
  try {
    opened.emplace(Store::open_writer(opt.db_path, 10.0, ""));
  } catch (const ResourceError& e) {  // a study writing it: busy, not bad input
    throw ResourceError(opt.db_path + ": cannot store the fits (" + e.what() +
                        "); run crevasse fit again when the study has ended, or add --no-store");
  } catch (const InputError& e) {
    throw InputError(opt.db_path + ": cannot store the fits (" + e.what() + ")");
  }
  Store& writer = *opened;
  std::vector<FitRecord> rows;
  for (const auto& [group, records] : all) rows.insert(rows.end(), records.begin(), records.end());
  replace_fit_records(writer, rows);  // one transaction: never new spacing rows beside old depth rows
  writer.checkpoint();
  std::printf("\nstored %zu row(s) in table 'fits' of %s (sqlite3 %s \"SELECT * FROM fits\")\n",
              rows.size(), opt.db_path.c_str(), opt.db_path.c_str());
  return 0;
}

}  // namespace crevasse
