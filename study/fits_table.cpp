#include "study/fits_table.hpp"

#include <cmath>
#include <set>
#include <utility>

#include "engine/error.hpp"

namespace crevasse {
namespace {

// docs/database.md describes every column. The primary key makes a second write of the same
// (quantity, group) a replacement, never a duplicate.
constexpr const char* kFitsSchema = R"SQL(
CREATE TABLE IF NOT EXISTS fits (
  quantity TEXT NOT NULL,
  group_name TEXT NOT NULL,
  model TEXT NOT NULL CHECK (model IN ('single', 'broken')),
  regime TEXT NOT NULL,
  status TEXT NOT NULL CHECK (status IN ('ok', 'not_enough_data')),
  note TEXT NOT NULL,
  accounting TEXT NOT NULL,
  n INTEGER NOT NULL,
  level REAL NOT NULL,
  exponent REAL, exponent_lo REAL, exponent_hi REAL, exponent_fixed INTEGER NOT NULL,
  prefactor REAL, prefactor_lo REAL, prefactor_hi REAL,
  log_prefactor REAL, var_log_prefactor REAL, cov_log_prefactor_exponent REAL, var_exponent REAL,
  residual_variance REAL, dof REAL,
  x_min REAL, x_max REAL, y_min REAL, y_max REAL,
  breakpoint REAL, breakpoint_lo REAL, breakpoint_hi REAL,
  breakpoint_clipped_low INTEGER NOT NULL, breakpoint_clipped_high INTEGER NOT NULL,
  r_squared REAL, aic REAL,
  f_statistic REAL, p_value REAL, aic_single REAL, aic_broken REAL, two_regimes INTEGER,
  fixed_exponents TEXT NOT NULL,
  created_at TEXT NOT NULL,
  PRIMARY KEY (quantity, group_name, model, regime)
)
)SQL";

constexpr const char* kColumns =
    "quantity, group_name, model, regime, status, note, accounting, n, level, exponent, "
    "exponent_lo, "
    "exponent_hi, exponent_fixed, prefactor, prefactor_lo, prefactor_hi, log_prefactor, "
    "var_log_prefactor, cov_log_prefactor_exponent, var_exponent, residual_variance, dof, x_min, "
    "x_max, y_min, y_max, breakpoint, breakpoint_lo, breakpoint_hi, breakpoint_clipped_low, "
    "breakpoint_clipped_high, r_squared, aic, f_statistic, p_value, aic_single, aic_broken, "
    "two_regimes, fixed_exponents, created_at";
constexpr int kColumnCount = 40;

// Visits every field in kColumns order: f(field).
template <class Record, class F>
void for_each_field(Record& r, F&& f) {
  f(r.quantity);
  f(r.group_name);
  f(r.model);
  f(r.regime);
  f(r.status);
  f(r.note);
  f(r.accounting);
  f(r.n);
  f(r.level);
  f(r.exponent);
  f(r.exponent_lo);
  f(r.exponent_hi);
  f(r.exponent_fixed);
  f(r.prefactor);
  f(r.prefactor_lo);
  f(r.prefactor_hi);
  f(r.log_prefactor);
  f(r.var_log_prefactor);
  f(r.cov_log_prefactor_exponent);
  f(r.var_exponent);
  f(r.residual_variance);
  f(r.dof);
  f(r.x_min);
  f(r.x_max);
  f(r.y_min);
  f(r.y_max);
  f(r.breakpoint);
  f(r.breakpoint_lo);
  f(r.breakpoint_hi);
  f(r.breakpoint_clipped_low);
  f(r.breakpoint_clipped_high);
  f(r.r_squared);
  f(r.aic);
  f(r.f_statistic);
  f(r.p_value);
  f(r.aic_single);
  f(r.aic_broken);
  f(r.two_regimes);
  f(r.fixed_exponents);
  f(r.created_at);
}

// SQLite stores NaN as NULL; an infinite value (e.g. an unidentifiable breakpoint's variance)
// is kept as NULL too, so every stored number is finite.
std::optional<double> finite(double v) {
  return std::isfinite(v) ? std::optional<double>(v) : std::nullopt;
}

void set_law(FitRecord& r, const analysis::PowerLaw& law) {
  r.log_prefactor = finite(law.log_a);
  r.exponent = finite(law.b);
  r.prefactor = finite(std::exp(law.log_a));
  r.var_log_prefactor = finite(law.covariance[0]);
  r.cov_log_prefactor_exponent = finite(law.covariance[1]);
  r.var_exponent = finite(law.covariance[2]);
  r.residual_variance = finite(law.residual_variance);
  r.dof = finite(law.dof);
}

void set_comparison(FitRecord& r, const analysis::ModelComparison& c) {
  r.f_statistic = finite(c.f_statistic);
  r.p_value = finite(c.p_value);
  r.aic_single = finite(c.aic_single);
  r.aic_broken = finite(c.aic_broken);
  r.two_regimes = c.two_regimes_warranted;
}

// Deletes the rows of each (quantity, group_name) in `keys` and inserts `records`, in one
// transaction, creating the table when absent.
void replace_rows(Store& store, const std::set<std::pair<std::string, std::string>>& keys,
                  const std::vector<FitRecord>& records) {
  std::string marks;
  for (int i = 0; i < kColumnCount; ++i) marks += i ? ", ?" : "?";
  store.transaction([&] {
    store.exec(kFitsSchema);
    Statement del(store.handle(), "DELETE FROM fits WHERE quantity = ? AND group_name = ?");
    for (const auto& [quantity, group_name] : keys) {
      del.bind(1, quantity).bind(2, group_name);
      del.run();
    }
    Statement ins(store.handle(),
                  std::string("INSERT INTO fits (") + kColumns + ") VALUES (" + marks + ")");
    for (const FitRecord& r : records) {
      int k = 0;
      for_each_field(r, [&](const auto& v) {
        using T = std::decay_t<decltype(v)>;
        if constexpr (std::is_same_v<T, bool>)
          ins.bind(++k, static_cast<int>(v));
        else if constexpr (std::is_same_v<T, std::optional<bool>>)
          ins.bind(++k, v ? std::optional<int>(*v ? 1 : 0) : std::nullopt);
        else
          ins.bind(++k, v);
      });
      ins.run();
    }
  });
}

}  // namespace

analysis::PowerLaw FitRecord::law() const {
  analysis::PowerLaw law;
  law.log_a = log_prefactor.value_or(NAN);
  law.b = exponent.value_or(NAN);
  law.covariance = {var_log_prefactor.value_or(0.0), cov_log_prefactor_exponent.value_or(0.0),
                    var_exponent.value_or(0.0)};
  law.residual_variance = residual_variance.value_or(0.0);
  law.dof = dof.value_or(0.0);
  return law;
}

std::vector<FitRecord> fit_records(const StudyFit& fit, const std::string& created_at,
                                   CaseReading reading) {
  FitRecord base;
  base.quantity = fit_quantity_key(fit.quantity, reading);
  base.group_name = fit.group->name;
  base.level = fit.options.level;
  base.fixed_exponents = fixed_exponents_text(fit.options);
  base.created_at = created_at;
  base.accounting = fit.accounting();
  base.n = static_cast<std::int64_t>(fit.x.size());

  std::vector<FitRecord> out;
  FitRecord single = base;
  single.model = "single";
  single.regime = "all";
  if (!fit.single) {
    single.status = "not_enough_data";
    single.note = fit.single_problem;
  } else {
    const analysis::PowerLawFit& s = *fit.single;
    single.status = "ok";
    set_law(single, s.law);
    single.exponent_lo = s.ci_b.lower;
    single.exponent_hi = s.ci_b.upper;
    single.prefactor_lo = s.ci_a.lower;
    single.prefactor_hi = s.ci_a.upper;
    single.x_min = s.x_min;
    single.x_max = s.x_max;
    single.y_min = s.y_min;
    single.y_max = s.y_max;
    single.r_squared = s.r_squared;
    single.aic = s.aic;
    if (fit.broken) set_comparison(single, fit.broken->comparison);
  }
  out.push_back(single);

  if (!fit.broken) {
    FitRecord none = base;
    none.model = "broken";
    none.regime = "all";
    none.status = "not_enough_data";
    none.note = fit.broken_problem;
    out.push_back(none);
    return out;
  }
  const analysis::BrokenLineFit& b = *fit.broken;
  for (int side = 0; side < 2; ++side) {
    FitRecord r = base;
    r.model = "broken";
    r.regime = side == 0 ? "below" : "above";
    r.status = "ok";
    r.n = static_cast<std::int64_t>(b.segment_n[side]);
    set_law(r, b.segments[side]);
    r.exponent_fixed = b.b_fixed[side];
    r.exponent_lo = finite(b.ci_b[side].lower);
    r.exponent_hi = finite(b.ci_b[side].upper);
    r.prefactor_lo = finite(b.ci_a[side].lower);
    r.prefactor_hi = finite(b.ci_a[side].upper);
    r.x_min = b.segment_x_min[side];
    r.x_max = b.segment_x_max[side];
    r.y_min = b.segment_y_min[side];
    r.y_max = b.segment_y_max[side];
    r.breakpoint = finite(b.breakpoint);
    r.breakpoint_lo = finite(b.breakpoint_ci.lower);
    r.breakpoint_hi = finite(b.breakpoint_ci.upper);
    r.breakpoint_clipped_low = b.breakpoint_ci_clipped_low;
    r.breakpoint_clipped_high = b.breakpoint_ci_clipped_high;
    r.r_squared = fit.broken_r_squared();
    r.aic = finite(b.aic);
    set_comparison(r, b.comparison);
    out.push_back(r);
  }
  return out;
}

void replace_fit_records(Store& store, const std::string& quantity, const std::string& group_name,
                         const std::vector<FitRecord>& records) {
  // The pair is replaced even when `records` is empty.
  replace_rows(store, {{quantity, group_name}}, records);
}

void replace_fit_records(Store& store, const std::vector<FitRecord>& records) {
  std::set<std::pair<std::string, std::string>> keys;
  for (const FitRecord& r : records) keys.emplace(r.quantity, r.group_name);
  replace_rows(store, keys, records);
}

bool has_fits_table(Store& store) {
  Statement t(store.handle(),
              "SELECT count(*) FROM sqlite_master WHERE type = 'table' AND name = 'fits'");
  t.step();
  return t.integer(0) > 0;
}

std::vector<FitRecord> read_fit_records(Store& store, const std::string& quantity,
                                        const std::string& group_name) {
  std::vector<FitRecord> out;
  if (!has_fits_table(store)) return out;
  Statement s(store.handle(), std::string("SELECT ") + kColumns +
                                  " FROM fits WHERE quantity = ? AND group_name = ? ORDER BY "
                                  "model DESC, regime");
  s.bind(1, quantity).bind(2, group_name);
  while (s.step()) {
    FitRecord r;
    int k = 0;
    int bad = -1;  // the first numeric column that holds no finite number
    for_each_field(r, [&](auto& v) {
      using T = std::decay_t<decltype(v)>;
      const int c = k++;
      if constexpr (!std::is_same_v<T, std::string>)
        if (bad < 0 && !s.is_null(c) && !s.is_finite_number(c)) bad = c;
      if constexpr (std::is_same_v<T, std::string>)
        v = s.text(c);
      else if constexpr (std::is_same_v<T, std::int64_t>)
        v = s.integer(c);
      else if constexpr (std::is_same_v<T, double>)
        v = s.real(c);
      else if constexpr (std::is_same_v<T, bool>)
        v = s.integer(c) != 0;
      else if constexpr (std::is_same_v<T, std::optional<bool>>)
        v = s.is_null(c) ? std::nullopt : std::optional<bool>(s.integer(c) != 0);
      else
        v = s.optional_real(c);
    });
    // A wrong number would be printed and used for predictions as if the fit had found it.
    const bool level_ok = r.level > 0.5 && r.level < 1.0;
    if (bad >= 0 || !level_ok)
      throw InputError(store.path().string() + ": fits row (" + r.quantity + ", " + r.group_name + ", " +
                       r.model + ", " + r.regime + "): " +
                       (bad >= 0 ? "column " + std::string(s.column_name(bad)) + " holds '" + s.text(bad) +
                                       "', not a finite number"
                                 : "level " + s.text(8) + " is outside (0.5, 1)") +
                       "; the table is inconsistent: run crevasse fit again to rewrite it");
    out.push_back(std::move(r));
  }
  return out;
}

}  // namespace crevasse
