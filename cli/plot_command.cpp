#include "cli/plot_command.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <set>

#include "analysis/regime_diagram.hpp"
#include "cli/cli_common.hpp"
#include "engine/error.hpp"
#include "study/case_results.hpp"
#include "study/fits_table.hpp"
#include "study/store.hpp"
#include "study/study_fit.hpp"

namespace crevasse {
namespace fs = std::filesystem;

namespace {

std::string group_value_label(const FitGroup& g, const std::optional<double>& v) {
  if (!v) return std::string(g.symbol) + " n/a";
  if (std::string(g.name) == "thickness") return "H_i = " + format_number(*v) + " m";
  return std::string(g.symbol) + " = " + format_number(*v);
}

// The fixed exponents given on the command line, else those the fits table was made with.
StudyFitOptions fit_options(Store& store, const std::string& quantity, const FitGroup& group,
                            const std::string& given, const std::string& option) {
  StudyFitOptions options;
  if (!given.empty()) {
    parse_fixed_exponents(given, option, options);
    return options;
  }
  for (const FitRecord& r : read_fit_records(store, quantity, group.name)) {
    if (!r.fixed_exponents.empty()) {
      parse_fixed_exponents(r.fixed_exponents, "fits table", options);
      break;
    }
  }
  return options;
}

analysis::RegimeFit chosen_fit(const StudyFit& fit, const std::string& model) {
  if (model == "none") return {};
  if (model == "broken" || (model == "auto" && fit.two_regimes())) {
    if (fit.broken) return *fit.broken;
    if (model == "broken") return {};
  }
  if (fit.single) return *fit.single;
  return {};
}

std::string fit_summary(const analysis::RegimeFit& fit, const StudyFit& study_fit) {
  if (std::holds_alternative<analysis::BrokenLineFit>(fit)) return "broken line";
  if (std::holds_alternative<analysis::PowerLawFit>(fit)) return "single power law";
  return "no fit (" +
         (study_fit.single_problem.empty() ? std::string("--model none")
                                           : study_fit.single_problem) +
         ")";
}

// Up to four cases with spacings, spread evenly over the group's range.
std::vector<const CaseRecord*> default_cdf_cases(const std::vector<CaseRecord>& cases,
                                                 const FitGroup& group) {
  std::vector<const CaseRecord*> eligible;
  for (const CaseRecord& c : cases)
    if (!c.spacings_m.empty()) eligible.push_back(&c);
  std::stable_sort(eligible.begin(), eligible.end(), [&](const CaseRecord* a, const CaseRecord* b) {
    return a->group(group).value_or(0.0) < b->group(group).value_or(0.0);
  });
  constexpr std::size_t kMax = 4;
  if (eligible.size() <= kMax) return eligible;
  std::vector<const CaseRecord*> chosen;
  for (std::size_t i = 0; i < kMax; ++i)
    chosen.push_back(eligible[(i * (eligible.size() - 1) + (kMax - 1) / 2) / (kMax - 1)]);
  return chosen;
}

// Against Π: each H_i's resolution floor Π = 3 dx/H_i shaded, and on the depth diagram Nye's
// zero-stress depth D = 2c/(ρ_i g), D/H_i = 2Π up to the bed (docs/fits.md, "Nye's depth").
void add_references(analysis::RegimeDiagramOptions& options, Quantity q,
                    const std::vector<std::pair<const CaseRecord*, std::string>>& cases,
                    const std::vector<analysis::RegimePoint>& points) {
  std::set<double> floors;
  for (const auto& [c, prefix] : cases)
    if (c->dx_m > 0.0 && c->thickness_m() > 0.0) floors.insert(3.0 * c->dx_m / c->thickness_m());
  options.shade_below.assign(floors.begin(), floors.end());
  if (q != Quantity::depth) return;
  double lo = HUGE_VAL, hi = 0.0;
  for (const analysis::RegimePoint& p : points) {
    lo = std::min(lo, p.pi);
    hi = std::max(hi, p.pi);
  }
  if (hi <= 0.0) return;
  analysis::ReferenceCurve nye = analysis::nye_zero_stress_depth(lo, hi);
  options.references.push_back(std::move(nye));
}

// The median of a non-empty sample.
double median_of(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

}  // namespace

std::vector<fs::path> plot_study(const PlotCommandOptions& opt) {
  check_output_directory("--out", opt.out_dir);
  const FitGroup& group = find_fit_group(opt.group, "--group");
  const FitGroup& colour_by = find_fit_group(opt.colour_by, "--colour-by");
  if (opt.model != "auto" && opt.model != "single" && opt.model != "broken" && opt.model != "none")
    throw InputError("--model: '" + opt.model + "' is not one of auto, single, broken, none");
  if (opt.cdf_normalise != "median" && opt.cdf_normalise != "thickness" && opt.cdf_normalise != "bending" &&
      opt.cdf_normalise != "strength" && opt.cdf_normalise != "none")
    throw InputError("--cdf-normalise: '" + opt.cdf_normalise +
                     "' is not one of median, thickness, bending, strength, none");

  Store store = Store::open_reader(opt.db_path);
  const CaseReading reading = opt.reading;
  const std::vector<CaseRecord> cases = read_case_records(store, reading);
  const std::string own_name = study_name_with_field(store, "study", reading);
  // Every reading's figures can share a folder.
  const std::string file_prefix = reading_prefix(reading);
  std::vector<const CaseRecord*> cdf_cases;
  for (std::int64_t index : opt.cdf_cases) {
    const auto it = std::find_if(cases.begin(), cases.end(),
                                 [&](const CaseRecord& c) { return c.case_index == index; });
    if (it == cases.end())
      throw InputError("--cdf-cases: no case with index " + std::to_string(index) + " in " +
                       opt.db_path + " (crevasse status " + opt.db_path + " --all lists them)");
    if (it->spacings_m.empty())
      throw InputError("--cdf-cases: case " + std::to_string(index) + " (" + it->label +
                       ") has no spacings (" + it->missing_reason(Quantity::spacing) + ")");
    cdf_cases.push_back(&*it);
  }

  // The cases drawn: the study's own, then those of --add-cases (label prefix, not fitted).
  std::vector<std::vector<CaseRecord>> added;
  std::vector<std::string> added_names;   // in the title
  std::vector<std::string> added_legend;  // before each added case's legend entry: which field it is
  for (const std::string& path : opt.add_cases) {
    Store other = Store::open_reader(path);
    added_names.push_back(study_name(other, path));
    added_legend.push_back(study_name_with_field(other, path));
    added.push_back(read_case_records(other, reading));
  }
  // The fits table is read while drawing; an inconsistent row is refused here, before the folder.
  for (Quantity q : kQuantities) read_fit_records(store, fit_quantity_key(q, reading), group.name);
  // Only once every input has been read: a refusal leaves no folder behind.
  create_output_directory("--out", opt.out_dir);
  std::vector<std::pair<const CaseRecord*, std::string>> drawn_cases;
  for (const CaseRecord& c : cases) drawn_cases.emplace_back(&c, "");
  for (std::size_t k = 0; k < added.size(); ++k)
    for (const CaseRecord& c : added[k])
      drawn_cases.emplace_back(&c, analysis::escape_markup(added_legend[k]) + ": ");

  std::vector<fs::path> written;
  for (Quantity q : kQuantities) {
    const std::string option =
        q == Quantity::spacing ? "--fixed-exponents" : "--fixed-depth-exponents";
    const std::string key = fit_quantity_key(q, reading);
    StudyFitOptions fit_opts =
        fit_options(store, key, group,
                    q == Quantity::spacing ? opt.fixed_exponents : opt.fixed_depth_exponents,
                    option);
    // Leave fragmented cases out of the fit when asked, or when the stored fits did.
    fit_opts.exclude_fragmented = opt.exclude_fragmented;
    fit_opts.include_under_resolved = opt.include_under_resolved;
    for (const FitRecord& r : read_fit_records(store, key, group.name))
      if (r.accounting.find(kFragmentedExcluded) != std::string::npos)
        fit_opts.exclude_fragmented = true;
    const StudyFit fit = fit_study(cases, q, group, fit_opts);
    std::vector<std::pair<double, analysis::RegimePoint>> keyed;  // colour group value, point
    std::map<std::string, std::size_t> missing;
    std::size_t skipped = 0;
    for (const auto& [case_ptr, prefix] : drawn_cases) {
      const CaseRecord& c = *case_ptr;
      const std::optional<double> x = c.group(group);
      if (c.status == "pending" || c.status == "running" || !x || !(*x > 0.0)) {
        ++skipped;
        continue;
      }
      analysis::RegimePoint p;
      p.pi = *x;
      p.group = prefix + group_value_label(colour_by, c.group(colour_by));
      if (fit_opts.exclude_fragmented && c.fragmented && c.median(q)) {
        p.failed = true;
        p.missing_reason = "fragmented (not fitted)";
        ++missing[p.missing_reason];
      } else if (const auto y = c.median(q)) {
        p.y = *y;
        p.hollow = c.under_resolved && !fit_opts.include_under_resolved;
        p.hollow_reason = "under-resolved: c/(ρ_i g) < 3 dx, not fitted";
        set_quartile_bar(p, c.quartiles(q));
      } else {
        p.failed = true;
        p.missing_reason = c.missing_reason(q);
        ++missing[p.missing_reason];
      }
      keyed.emplace_back(c.group(colour_by).value_or(HUGE_VAL), p);
    }
    // Colours follow the colour group's numeric order.
    std::stable_sort(keyed.begin(), keyed.end(),
                     [](const auto& a, const auto& b) { return a.first < b.first; });
    std::vector<analysis::RegimePoint> points;
    for (auto& [key, p] : keyed) points.push_back(std::move(p));
    if (points.empty())
      throw InputError(opt.db_path + ": no finished case has a positive " + group.name +
                       "; nothing to plot");

    const analysis::RegimeFit drawn = chosen_fit(fit, opt.model);
    analysis::RegimeDiagramOptions options;
    const std::size_t measured = points.size() - [&] {
      std::size_t n = 0;
      for (const auto& [reason, k] : missing) n += k;
      return n;
    }();
    std::string shown = analysis::escape_markup(own_name);
    for (const std::string& name : added_names) shown += " + " + analysis::escape_markup(name);
    options.title = shown + ": median " +
                    (q == Quantity::spacing ? std::string("spacing") : std::string("depth")) +
                    ", " + std::to_string(measured) + " of " + std::to_string(points.size()) +
                    (added_names.empty() ? " cases measured" : " cases");
    options.y_label = quantity_symbol(q);
    options.x_label = group.axis_label;
    options.x_symbol = group.symbol;
    if (std::string(group.name) == "cohesion_ratio") add_references(options, q, drawn_cases, points);
    const analysis::Figure figure = analysis::regime_diagram(points, drawn, options);
    const std::string stem = file_prefix + (q == Quantity::spacing ? "spacing" : "depth") +
                             "_vs_" + group.name;
    const auto files = write_png_and_svg(figure, fs::path(opt.out_dir) / stem);
    written.insert(written.end(), files.begin(), files.end());
    std::string missing_text;
    for (const auto& [reason, k] : missing)
      missing_text += (missing_text.empty() ? "" : ", ") + std::to_string(k) + " " + reason;
    std::printf("%s: %zu case(s) drawn (%s), fit: %s%s\n", files.front().c_str(), points.size(),
                missing_text.empty() ? "all measured" : ("no value: " + missing_text).c_str(),
                fit_summary(drawn, fit).c_str(),
                skipped
                    ? (", " + std::to_string(skipped) + " not drawn (not run yet, or no value of " +
                       std::string(group.name) + ")")
                          .c_str()
                    : "");
  }

  if (cdf_cases.empty() && opt.cdf_cases.empty()) cdf_cases = default_cdf_cases(cases, group);
  if (cdf_cases.empty()) {
    std::printf("no case has a crevasse spacing: spacing CDF figure not drawn\n");
    return written;
  }
  std::vector<analysis::NamedSample> samples;
  for (const CaseRecord* c : cdf_cases) {
    analysis::NamedSample sample;
    sample.name = "case " + std::to_string(c->case_index) + ": " +
                  group_value_label(group, c->group(group)) +
                  (std::string(group.name) == "thickness"
                       ? ""
                       : ", " + group_value_label(kFitGroups[1], c->group(kFitGroups[1])));
    std::vector<double> v = c->spacings_m;
    // c/(ρ_i g) = Π H_i: the strength scale; sqrt(c H_i/(ρ_i g)) = H_i sqrt(Π): the bending one.
    const double h = c->thickness_m(), pi = c->cohesion_ratio();
    double scale = 1.0;
    if (opt.cdf_normalise == "thickness") scale = h;
    if (opt.cdf_normalise == "bending") scale = h * std::sqrt(pi);
    if (opt.cdf_normalise == "strength") scale = pi * h;
    if (opt.cdf_normalise == "median") scale = median_of(v);
    for (double& x : v) x /= scale;
    sample.values = std::move(v);
    samples.push_back(std::move(sample));
  }
  analysis::CdfFigureOptions cdf;
  cdf.title = analysis::escape_markup(own_name) + ": crevasse spacings of " + std::to_string(samples.size()) + " case(s)";
  cdf.x_label = opt.cdf_normalise == "median"      ? "L_p / median L_p of the case"
                : opt.cdf_normalise == "thickness" ? "L_p/H_i"
                : opt.cdf_normalise == "bending"   ? "L_p / sqrt(c H_i/(ρ_i g))"
                : opt.cdf_normalise == "strength"  ? "L_p / (c/(ρ_i g))"
                                                   : "L_p [m]";
  const auto files = write_png_and_svg(analysis::empirical_cdf_figure(samples, cdf),
                                       fs::path(opt.out_dir) / (file_prefix + "spacing_cdf"));
  written.insert(written.end(), files.begin(), files.end());
  std::printf("%s: spacing CDFs of case(s)", files.front().c_str());
  for (const CaseRecord* c : cdf_cases) std::printf(" %lld", static_cast<long long>(c->case_index));
  std::printf(", normalised by %s\n", opt.cdf_normalise.c_str());

  // The depths of the same cases, over H_i (the depth of every crevasse, a case with one counts).
  std::vector<analysis::NamedSample> depths;
  for (std::size_t i = 0; i < cdf_cases.size(); ++i) {
    if (cdf_cases[i]->depths_m.empty()) continue;
    analysis::NamedSample d{samples[i].name, cdf_cases[i]->depths_m};
    for (double& x : d.values) x /= cdf_cases[i]->thickness_m();
    depths.push_back(std::move(d));
  }
  if (depths.empty()) return written;
  analysis::CdfFigureOptions depth_cdf;
  depth_cdf.title = analysis::escape_markup(own_name) + ": crevasse depths of " + std::to_string(depths.size()) + " case(s)";
  depth_cdf.x_label = "D_p/H_i";
  const auto depth_files = write_png_and_svg(analysis::empirical_cdf_figure(depths, depth_cdf),
                                             fs::path(opt.out_dir) / (file_prefix + "depth_cdf"));
  written.insert(written.end(), depth_files.begin(), depth_files.end());
  std::printf("%s: depth CDFs of the same case(s)\n", depth_files.front().c_str());
  return written;
}

int plot_command(const PlotCommandOptions& opt) {
  const auto files = plot_study(opt);
  std::printf("wrote %zu file(s) to %s\n", files.size(), opt.out_dir.c_str());
  return 0;
}

}  // namespace crevasse
