#include "cli/calibrate_command.hpp"
#include "cli/cli_common.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <vector>

#include "analysis/calibration.hpp"
#include "cli/csv_file.hpp"
#include "engine/error.hpp"
#include "study/case_results.hpp"
#include "study/field_observations.hpp"
#include "study/fits_table.hpp"
#include "study/store.hpp"
#include "study/study_fit.hpp"

namespace crevasse {
namespace {


std::string range(double lo, double hi) {
  std::string text = "[";
  text += short_number(lo);
  text += ", ";
  text += short_number(hi);
  return text + "]";
}

// One law of one quantity over a Π range.
struct QuantityRegime {
  std::string name;
  double pi_min = 0.0, pi_max = 0.0;
  double y_min = 0.0, y_max = 0.0;
  analysis::PowerLaw law;
};

// As the calibration library takes it.
analysis::RegimeLaw spacing_regime(const QuantityRegime& r) {
  analysis::RegimeLaw regime;
  regime.name = r.name;
  regime.pi_min = r.pi_min;
  regime.pi_max = r.pi_max;
  regime.spacing_ratio_min = r.y_min;
  regime.spacing_ratio_max = r.y_max;
  regime.spacing = r.law;
  return regime;
}

// The regimes of one quantity: the broken line's two segments when two regimes are warranted,
// else the single law. `model` describes the choice.
struct QuantityLaws {
  std::vector<QuantityRegime> regimes;
  std::string model;
  std::string problem;  // why there is no law
};

QuantityLaws laws_from_records(const std::vector<FitRecord>& records) {
  QuantityLaws out;
  const FitRecord* single = nullptr;
  const FitRecord* below = nullptr;
  const FitRecord* above = nullptr;
  for (const FitRecord& r : records) {
    if (r.model == "single" && r.ok()) single = &r;
    if (r.model == "broken" && r.ok() && r.regime == "below") below = &r;
    if (r.model == "broken" && r.ok() && r.regime == "above") above = &r;
    if (r.model == "single" && !r.ok()) out.problem = r.note;
  }
  if (below && above && below->two_regimes.value_or(false) && below->breakpoint) {
    const double pi_star = *below->breakpoint;
    out.model = "two regimes (broken line, Π* = " + short_number(pi_star) + " " +
                range(below->breakpoint_lo.value_or(NAN), below->breakpoint_hi.value_or(NAN)) + ")";
    out.regimes.push_back({"below Π* (Π < " + short_number(pi_star) + ")", below->x_min.value_or(NAN),
                           pi_star, below->y_min.value_or(NAN), below->y_max.value_or(NAN),
                           below->law()});
    out.regimes.push_back({"above Π* (Π ≥ " + short_number(pi_star) + ")", pi_star,
                           above->x_max.value_or(NAN), above->y_min.value_or(NAN),
                           above->y_max.value_or(NAN), above->law()});
    return out;
  }
  if (single) {
    out.model =
        std::string("one regime (single power law; ") +
        (below && above ? "a second regime is not warranted)" : "too few cases for a broken line)");
    out.regimes.push_back({"all Π (one regime)", single->x_min.value_or(NAN),
                           single->x_max.value_or(NAN), single->y_min.value_or(NAN),
                           single->y_max.value_or(NAN), single->law()});
  }
  return out;
}

struct StudyLaws {
  std::string title;
  std::string source;  // where the laws come from
  QuantityLaws spacing, depth;
  analysis::IceConstants ice;
  double thickness_min = 0.0, thickness_max = 0.0;  // H_i the study ran
};

StudyLaws load_laws(const std::string& db_path, CaseReading reading) {
  const std::string flag = reading == CaseReading::window ? "" : std::string(" ") + reading_flag(reading);
  Store store = Store::open_reader(db_path);
  const std::vector<CaseRecord> cases = read_case_records(store, reading);
  StudyLaws laws;
  laws.title = study_title(store, reading);
  const FitGroup& pi = find_fit_group("cohesion_ratio", "group");
  std::vector<FitRecord> spacing =
      read_fit_records(store, fit_quantity_key(Quantity::spacing, reading), pi.name);
  std::vector<FitRecord> depth =
      read_fit_records(store, fit_quantity_key(Quantity::depth, reading), pi.name);
  if (!spacing.empty()) {
    laws.source = std::string("laws from the fits table (crevasse fit") +
                  flag + ", " + spacing.front().created_at + ")";
  } else {
    laws.source = std::string("no fits table yet: laws fitted now with the defaults (crevasse fit") +
                  flag + " stores them)";
    spacing = fit_records(fit_study(cases, Quantity::spacing, pi), "", reading);
    depth = fit_records(fit_study(cases, Quantity::depth, pi), "", reading);
  }
  laws.spacing = laws_from_records(spacing);
  laws.depth = laws_from_records(depth);
  if (laws.spacing.regimes.empty())
    throw InputError(db_path + ": the study has no law of L_p/H_i against Π to use: " +
                     (laws.spacing.problem.empty() ? std::string("run crevasse fit first")
                                                   : laws.spacing.problem));
  {
    // Π = c/(ρ_i g H_i) with the ρ_i and g the study ran with.
    Statement s(store.handle(),
                "SELECT json_extract(scene_json, '$.ice.density'), "
                "json_extract(scene_json, '$.gravity.g'), min(thickness_m), max(thickness_m) "
                "FROM cases WHERE status = 'done'");
    if (s.step()) {
      if (!s.is_null(0)) laws.ice.density_kg_m3 = s.real(0);
      if (!s.is_null(1)) laws.ice.gravity_m_s2 = s.real(1);
      laws.thickness_min = s.real(2);
      laws.thickness_max = s.real(3);
    }
  }
  return laws;
}

void print_header(const StudyLaws& laws, double level) {
  std::printf("%s\n  %s; %.0f %% intervals; ρ_i = %s kg/m³, g = %s m/s² as in the study\n",
              laws.title.c_str(), laws.source.c_str(), 100.0 * level,
              short_number(laws.ice.density_kg_m3).c_str(), short_number(laws.ice.gravity_m_s2).c_str());
  std::printf("  L_p/H_i: %s\n", laws.spacing.model.c_str());
}

std::string law_text(const char* symbol, const QuantityRegime& r) {
  return std::string(symbol) + " = " + short_number(r.law.a()) + " Π^" + short_number(r.law.b) + " on Π in " +
         range(r.pi_min, r.pi_max) + ", " + symbol + " in " + range(r.y_min, r.y_max);
}

void note_thickness(const StudyLaws& laws, double h) {
  if (h < laws.thickness_min * (1 - 1e-9) || h > laws.thickness_max * (1 + 1e-9))
    std::printf(
        "  note: H_i = %s m is outside the thicknesses the study ran (%s to %s m); the "
        "law is used through Π and L_p/H_i alone\n",
        short_number(h).c_str(), short_number(laws.thickness_min).c_str(), short_number(laws.thickness_max).c_str());
}

// The study's ice constants and the confidence level asked for.
analysis::CalibrationOptions calibration_options(const StudyLaws& laws, double level) {
  analysis::CalibrationOptions options;
  options.ice = laws.ice;
  options.level = level;
  return options;
}

double positive(double v, const std::string& option) {
  if (!std::isfinite(v) || v <= 0.0)
    throw InputError(option + ": must be a positive number, got " + short_number(v));
  return v;
}

// Each regime's answer to one observation, or why it refused.
struct Answer {
  std::optional<analysis::CohesionEstimate> estimate;
  std::string refusal;
};

std::vector<Answer> invert_in_every_regime(const StudyLaws& laws,
                                           const analysis::SpacingObservation& obs,
                                           const analysis::CalibrationOptions& options,
                                           const std::string& bad_input_prefix) {
  std::vector<Answer> answers;
  for (const QuantityRegime& r : laws.spacing.regimes) {
    const analysis::RegimeLaw regime = spacing_regime(r);
    Answer a;
    try {
      a.estimate = analysis::invert_spacing_for_cohesion(regime, obs, options);
    } catch (const std::out_of_range& e) {
      a.refusal = e.what();
    } catch (const std::domain_error& e) {
      a.refusal = e.what();
    } catch (const std::invalid_argument& e) {
      throw InputError(bad_input_prefix + e.what());
    }
    answers.push_back(std::move(a));
  }
  return answers;
}

// `crevasse calibrate --observations FILE`: every site of the file against the study's laws,
// one row per site and regime that answers (or one row saying why none does).
int calibrate_observations(const CalibrateCommandOptions& opt) {
  const FieldObservationFile file = load_field_observations(opt.observations_path);
  const std::vector<FieldObservation>& sites = file.sites;
  const std::vector<LiteratureStrength>& literature = file.literature;
  const StudyLaws laws = load_laws(opt.db_path, opt.reading);
  const analysis::CalibrationOptions options = calibration_options(laws, opt.level);
  print_header(laws, opt.level);
  std::printf("observations: %s (%zu sites)\n\n", opt.observations_path.c_str(), sites.size());
  std::printf("%-32s %9s %-20s %8s %7s  %-26s %10s %-22s %-24s %s\n", "site", "L_p[m]", "spread used",
              "H_i[m]", "L_p/H_i", "regime", "c[kPa]", "interval[kPa]", "Pi [interval]", "in regime / why not");
  std::optional<CsvFile> csv;
  if (!opt.csv_path.empty()) {
    csv.emplace(opt.csv_path);
    csv->row({"id", "site", "spacing_m", "spacing_statistic", "spread_used", "spread_q25_m",
              "spread_q75_m", "thickness_m", "regime", "c_kpa", "c_lo_kpa", "c_hi_kpa", "pi",
              "pi_lo", "pi_hi", "pi_in_regime", "refusal", "reference"});
  }
  const auto opt_num = [](const std::optional<double>& v) { return v ? short_number(*v) : std::string(); };
  for (const FieldObservation& site : sites) {
    std::string spread;
    const analysis::SpacingObservation obs = to_spacing_observation(site, &spread);
    const std::vector<Answer> answers =
        invert_in_every_regime(laws, obs, options, opt.observations_path + ": " + site.id + ": ");
    const std::string h = site.thickness_m ? short_number(*site.thickness_m) : "-";
    const std::string ratio = site.thickness_m ? short_number(site.spacing_m / *site.thickness_m) : "-";
    const bool any = std::any_of(answers.begin(), answers.end(), [](const Answer& a) { return a.estimate.has_value(); });
    std::string refusals;
    for (const Answer& a : answers)
      if (!a.estimate) refusals += (refusals.empty() ? "" : "; ") + a.refusal;
    std::string h_hint;
    if (!site.thickness_m) {
      // Which thickness would put the site inside what the study covered.
      double y_lo = INFINITY, y_hi = 0.0;
      for (const QuantityRegime& r : laws.spacing.regimes) {
        y_lo = std::min(y_lo, r.y_min);
        y_hi = std::max(y_hi, r.y_max);
      }
      h_hint = "the study's L_p/H_i range " + range(y_lo, y_hi) + " needs H_i in " +
               range(site.spacing_m / y_hi, site.spacing_m / y_lo) + " m";
      refusals = "H_i unknown: " + h_hint + "; " + refusals;
    }
    for (std::size_t k = 0; k < answers.size(); ++k) {
      if (any && !answers[k].estimate) continue;
      if (!any && k > 0) break;
      const std::string regime = any ? laws.spacing.regimes[k].name : "-";
      std::string c = "-", interval = "-", pi = "-", verdict = refusals;
      if (any) {
        const analysis::CohesionEstimate& e = *answers[k].estimate;
        c = short_number(e.tensile_strength_pa / 1e3);
        interval = range(e.interval_pa.lower / 1e3, e.interval_pa.upper / 1e3);
        if (e.cohesion_ratio_pi) {
          pi = short_number(e.cohesion_ratio_pi->value) + " " +
               range(e.cohesion_ratio_pi->interval.lower, e.cohesion_ratio_pi->interval.upper);
          verdict = e.pi_in_regime_range.value_or(false)
                        ? (e.pi_interval_in_regime_range.value_or(false) ? "inside" : "inside (interval reaches out)")
                        : "OUTSIDE: not self-consistent";
        } else {
          verdict = "H_i unknown, regime not checked: " + h_hint;
        }
      }
      std::printf("%-32s %9s %-20s %8s %7s  %-26s %10s %-22s %-24s %s\n", site.id.c_str(),
                  short_number(site.spacing_m).c_str(), spread.c_str(), h.c_str(), ratio.c_str(),
                  regime.c_str(), c.c_str(), interval.c_str(), pi.c_str(), verdict.c_str());
      if (csv) {
        const analysis::CohesionEstimate* e = any ? &*answers[k].estimate : nullptr;
        const bool has_pi = e && e->cohesion_ratio_pi;
        csv->row({site.id, site.site, short_number(site.spacing_m), site.statistic, spread,
                  opt_num(obs.spacing_q25_m), opt_num(obs.spacing_q75_m), opt_num(site.thickness_m),
                  any ? regime : "", e ? short_number(e->tensile_strength_pa / 1e3) : "",
                  e ? short_number(e->interval_pa.lower / 1e3) : "",
                  e ? short_number(e->interval_pa.upper / 1e3) : "",
                  has_pi ? short_number(e->cohesion_ratio_pi->value) : "",
                  has_pi ? short_number(e->cohesion_ratio_pi->interval.lower) : "",
                  has_pi ? short_number(e->cohesion_ratio_pi->interval.upper) : "",
                  e && e->pi_in_regime_range ? (*e->pi_in_regime_range ? "yes" : "no") : "",
                  any ? "" : refusals, site.reference});
      }
    }
  }
  if (csv) csv->close();
  std::printf("\nc from the inverted law with its %.0f %% interval (fit uncertainty and the site's spread); "
              "Pi = c/(rho_i g H_i); a site is in a regime when its Pi lies in the regime's Pi range\n",
              100.0 * opt.level);
  if (!literature.empty()) {
    std::printf("\ntensile strengths reported in the literature (%s):\n", opt.observations_path.c_str());
    std::printf("%-36s %16s  %s\n", "id", "c[kPa]", "method");
    for (const LiteratureStrength& s : literature) {
      const std::string value = s.low_kpa == s.high_kpa ? short_number(s.low_kpa)
                                                        : range(s.low_kpa, s.high_kpa);
      std::printf("%-36s %16s  %s\n", s.id.c_str(), value.c_str(), s.method.c_str());
    }
  }
  return 0;
}

}  // namespace

int calibrate_command(const CalibrateCommandOptions& opt) {
  check_confidence_level(opt.level);
  if (!opt.observations_path.empty()) {
    if (opt.spacing_m != 0.0 || !opt.spacing_quartiles.empty() || opt.thickness_m)
      throw InputError("--observations: give either --observations or --spacing [--spacing-quartiles] [--thickness], not both");
    if (!opt.csv_path.empty()) check_output_file("--csv", opt.csv_path);
    return calibrate_observations(opt);
  }
  if (!opt.csv_path.empty()) throw InputError("--csv: only with --observations");
  analysis::SpacingObservation obs;
  obs.spacing_m = positive(opt.spacing_m, "--spacing");
  if (opt.thickness_m) obs.thickness_m = positive(*opt.thickness_m, "--thickness");
  if (!opt.spacing_quartiles.empty()) {
    const auto comma = opt.spacing_quartiles.find(',');
    double q25 = NAN, q75 = NAN;
    try {
      std::size_t used1 = 0, used2 = 0;
      const std::string a = opt.spacing_quartiles.substr(0, comma);
      const std::string b =
          comma == std::string::npos ? "" : opt.spacing_quartiles.substr(comma + 1);
      q25 = std::stod(a, &used1);
      q75 = std::stod(b, &used2);
      if (used1 != a.size() || used2 != b.size()) q25 = NAN;
    } catch (const std::exception&) {
      q25 = NAN;
    }
    if (!std::isfinite(q25) || !std::isfinite(q75))
      throw InputError("--spacing-quartiles: expected Q25,Q75 in metres, got '" +
                       opt.spacing_quartiles + "'");
    if (!(q25 > 0.0 && q25 <= obs.spacing_m && obs.spacing_m <= q75))
      throw InputError("--spacing-quartiles: need 0 < Q25 <= spacing <= Q75, got " + short_number(q25) +
                       " <= " + short_number(obs.spacing_m) + " <= " + short_number(q75));
    obs.spacing_q25_m = q25;
    obs.spacing_q75_m = q75;
  }

  const StudyLaws laws = load_laws(opt.db_path, opt.reading);
  const analysis::CalibrationOptions options = calibration_options(laws, opt.level);

  const std::vector<Answer> answers = invert_in_every_regime(laws, obs, options, "--spacing: ");
  if (std::none_of(answers.begin(), answers.end(), [](const Answer& a) { return a.estimate; })) {
    std::string all;
    for (const Answer& a : answers) all += (all.empty() ? "" : "; ") + a.refusal;
    throw InputError("--spacing: no regime of the study can invert this observation: " + all);
  }

  print_header(laws, opt.level);
  std::printf("observation: median spacing L_p = %s m", short_number(obs.spacing_m).c_str());
  if (obs.spacing_q25_m)
    std::printf(", quartiles %s m", range(*obs.spacing_q25_m, *obs.spacing_q75_m).c_str());
  if (obs.thickness_m)
    std::printf(", H_i = %s m (L_p/H_i = %s)", short_number(*obs.thickness_m).c_str(),
                short_number(obs.spacing_m / *obs.thickness_m).c_str());
  else
    std::printf(", thickness not given");
  std::printf("\n");
  for (std::size_t k = 0; k < answers.size(); ++k) {
    const QuantityRegime& r = laws.spacing.regimes[k];
    std::printf("\nregime '%s': %s\n", r.name.c_str(), law_text("L_p/H_i", r).c_str());
    if (!answers[k].estimate) {
      std::printf("  refused: %s\n", answers[k].refusal.c_str());
      continue;
    }
    const analysis::CohesionEstimate& e = *answers[k].estimate;
    std::printf("  tensile strength c = %s Pa, %.0f %% interval %s Pa\n",
                short_number(e.tensile_strength_pa).c_str(), 100.0 * e.level,
                range(e.interval_pa.lower, e.interval_pa.upper).c_str());
    if (e.cohesion_ratio_pi) {
      const bool in = e.pi_in_regime_range.value_or(false);
      std::printf(
          "  Π = %s %s: %s this regime's Π range %s%s\n", short_number(e.cohesion_ratio_pi->value).c_str(),
          range(e.cohesion_ratio_pi->interval.lower, e.cohesion_ratio_pi->interval.upper).c_str(),
          in ? "inside" : "OUTSIDE", range(r.pi_min, r.pi_max).c_str(),
          in ? (e.pi_interval_in_regime_range.value_or(false)
                    ? " (whole interval inside): the thickness puts the site in this "
                      "regime"
                    : " (the interval reaches outside it)")
             : ": the thickness does not put the site in this regime; this answer is "
               "not self-consistent");
    } else {
      std::printf("  without H_i it cannot be checked that the site is in this regime\n");
    }
    for (const std::string& n : e.notes) std::printf("  - %s\n", n.c_str());
  }
  if (obs.thickness_m) note_thickness(laws, *obs.thickness_m);
  return 0;
}

int predict_command(const PredictCommandOptions& opt) {
  check_confidence_level(opt.level);
  positive(opt.tensile_strength_pa, "--cohesion");
  positive(opt.thickness_m, "--thickness");
  const StudyLaws laws = load_laws(opt.db_path, opt.reading);
  const double pi = analysis::cohesion_ratio(opt.tensile_strength_pa, opt.thickness_m, laws.ice);
  const auto holds = [&](const QuantityRegime& r) { return r.pi_min <= pi && pi <= r.pi_max; };
  const auto& spacing = laws.spacing.regimes;
  const auto s = std::find_if(spacing.begin(), spacing.end(), holds);
  if (s == spacing.end())
    throw InputError("--cohesion/--thickness: Π = c/(ρ_i g H_i) = " + short_number(pi) +
                     " lies outside the Π range the study covered, " +
                     range(spacing.front().pi_min, spacing.back().pi_max) +
                     "; the laws are not extrapolated");
  analysis::RegimeLaw regime = spacing_regime(*s);
  const auto& depth = laws.depth.regimes;
  const auto d = std::find_if(depth.begin(), depth.end(), holds);
  if (d != depth.end()) regime.depth = d->law;
  const analysis::CalibrationOptions options = calibration_options(laws, opt.level);
  const analysis::CrevassePrediction p =
      analysis::predict_crevasses(regime, opt.tensile_strength_pa, opt.thickness_m, options);

  print_header(laws, opt.level);
  std::printf("c = %s Pa, H_i = %s m: Π = %s, regime %s\n", short_number(opt.tensile_strength_pa).c_str(),
              short_number(opt.thickness_m).c_str(), short_number(pi).c_str(), s->name.c_str());
  std::printf("  %s\n", law_text("L_p/H_i", *s).c_str());
  std::printf("  median spacing L_p = %s m: the law's %.0f %% band %s m, one site %s m\n",
              short_number(p.spacing_m.value).c_str(), 100.0 * opt.level,
              range(p.spacing_m.interval.lower, p.spacing_m.interval.upper).c_str(),
              range(p.spacing_prediction_m.lower, p.spacing_prediction_m.upper).c_str());
  if (p.depth_m) {
    std::printf("  %s\n", law_text("D_p/H_i", *d).c_str());
    std::printf("  median depth D_p = %s m: the law's %.0f %% band %s m, one site %s m\n",
                short_number(p.depth_m->value).c_str(), 100.0 * opt.level,
                range(p.depth_m->interval.lower, p.depth_m->interval.upper).c_str(),
                range(p.depth_prediction_m->lower, p.depth_prediction_m->upper).c_str());
  } else {
    std::printf("  depth: no law of D_p/H_i covers Π = %s (%s)\n", short_number(pi).c_str(),
                depth.empty() ? laws.depth.problem.c_str() : "outside its Π range");
  }
  note_thickness(laws, opt.thickness_m);
  return 0;
}

}  // namespace crevasse
