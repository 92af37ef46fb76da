#include "study/engine_case.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <stdexcept>

#include "analysis/measurement_io.hpp"
#include "engine/error.hpp"
#include "engine/particle_file.hpp"
#include "engine/run.hpp"
#include "study/case_hash.hpp"
#include "study/case_views.hpp"
#include "study/field_over_time.hpp"
#include "study/memory_reserve.hpp"
#include "study/study_file.hpp"

namespace crevasse {
namespace {

// What a run's result and run records hold of its summary, at its stop or at a gate mark.
nlohmann::json result_extra_of(const RunSummary& r) {
  return {{"initial_mass_kg", r.initial_mass},    {"final_mass_kg", r.final_mass},
          {"removed_mass_kg", r.removed_mass},    {"inflow_mass_kg", r.inflow_mass},
          {"initial_particles", r.initial_particles},
          {"final_particles", r.final_particles}, {"return_map_evaluations", r.return_map_evaluations}};
}

// The whole run's wall time, its earlier sittings included (the checkpoint carries them);
// stage_seconds are this sitting's. A format 2 checkpoint did not keep them: then the wall
// times stored are this sitting's alone, and run_json says so.
nlohmann::json run_json_of(const RunSummary& r, std::optional<double> earlier) {
  const double engine_wall_s = r.wall_s + earlier.value_or(0.0);
  nlohmann::json run = {{"engine_wall_s", engine_wall_s},
                        {"sitting_wall_s", r.wall_s},
                        {"resumed_from_time_s", r.resumed_from_time_s},
                        {"stage_seconds", r.stage_seconds},
                        {"particle_steps_per_s",
                         engine_wall_s > 0 ? static_cast<double>(r.particle_steps) / engine_wall_s : 0.0}};
  if (!earlier) {
    run["earlier_wall_unknown"] = true;
    run["particle_steps_per_s"] = nullptr;  // all the steps over one sitting's wall
  }
  return run;
}


// A side file of the case (its views, its kept particles) is a view of the result, not the
// result: one that cannot be written (a full disk) is reported, and the case is stored all the same.
template <class Write>
void write_side_files(CaseContext& ctx, const std::filesystem::path& dir, const std::string& what, const Write& write) {
  if (dir.empty()) return;
  try {
    std::filesystem::create_directories(dir);
    write(dir);
  } catch (const std::exception& e) {
    ctx.warn("its " + what + " in " + dir.string() + " were not all written (" + e.what() + "); its result is stored");
  }
}

class CaseObserver : public RunObserver {
 public:
  CaseObserver(const StudyCase& study_case, CaseContext& ctx)
      : case_(study_case),
        ctx_(ctx),
        over_time_(ctx.checkpoint_file().empty() || ctx.measure_interval_s() <= 0
                       ? std::filesystem::path()
                       : over_time_file(ctx.checkpoint_file())) {}
  double snapshot_interval_s() const override { return ctx_.measure_interval_s(); }
  void on_snapshot(const ParticleSnapshot& s) override {
    try {
      over_time_.add(s, ctx_.measurement());
    } catch (const std::invalid_argument& e) {
      throw SimulationError(std::string("measurement at t = ") + std::to_string(s.time_s) + " s failed: " + e.what());
    }
  }
  const FieldOverTime& over_time() const { return over_time_; }
  // Gate marks only where the case keeps particles and its scene has a gate; a mark at or past
  // the case's own stop is its final state, kept as such.
  std::vector<double> gate_marks() const override {
    std::vector<double> marks;
    if (ctx_.particles_dir().empty() || !case_.scene.records_gate()) return marks;
    for (double ratio : ctx_.gate_mark_ratios()) {
      const double at = ratio * case_.scene.ice_thickness;
      if (case_.scene.gate_length <= 0.0 || at < case_.scene.gate_length) marks.push_back(at);
    }
    return marks;
  }
  void on_gate_mark(double mark_m, const RunSummary& at) override { keep_gate_mark(mark_m, at); }
  void on_progress(const RunProgress& p) override { ctx_.report_fraction(p.fraction_done); }
  bool cancelled() override {
    // A safe place to fail when an allocation had to take the memory reserve.
    throw_if_memory_ran_out();
    // The stop signal only: the time limit is the engine's (run.wall_time_limit).
    return ctx_.stop_requested();
  }
  double progress_interval_s() const override { return 0.5; }
  std::string checkpoint_path() const override { return ctx_.checkpoint_file().string(); }
  double checkpoint_interval_s() const override { return ctx_.checkpoint_interval_s(); }
  void on_warning(const std::string& message) override { ctx_.warn(message); }
  void on_resumed(double fraction_done, std::optional<double> earlier_wall_s) override {
    ctx_.report_resumed(fraction_done, earlier_wall_s);
  }

 private:
  // The particles at the mark, as the case with run.gate_length = mark would keep them at its
  // end: under that case's id, with its result and run records, so that --remeasure measures
  // them as that case (study/kept_runs.cpp).
  void keep_gate_mark(double mark_m, const RunSummary& at) {
    SceneConfig twin = case_.scene;
    twin.gate_length = mark_m;
    const nlohmann::json measurement = measure_settings_to_json(ctx_.measurement());
    char ratio[32];
    std::snprintf(ratio, sizeof ratio, "%g", mark_m / case_.scene.ice_thickness);
    nlohmann::json meta = particle_file_metadata(twin, ctx_.measurement(), case_hash(twin, measurement),
                                                 case_.label + " (kept at " + ratio + " H_i through the gate)");
    meta["gate_mark"] = {{"of_case_id", case_.case_id},
                         {"gate_length_m", mark_m},
                         {"result", {{"stop_reason", at.stop_reason},
                                     {"steps", at.steps},
                                     {"particle_steps", at.particle_steps},
                                     {"sim_time_s", at.sim_time_s},
                                     {"extra", result_extra_of(at)}}},
                         {"run", run_json_of(at, ctx_.earlier_wall_s())}};
    const std::string name = case_file_stem(case_.index) + "gate_" + ratio + "_particles.bin";
    write_side_files(ctx_, ctx_.particles_dir(), std::string("particles at ") + ratio + " H_i through the gate",
                     [&](const std::filesystem::path& dir) { write_particle_file(dir / name, at.final_snapshot, meta); });
  }

  const StudyCase& case_;
  CaseContext& ctx_;
  FieldOverTime over_time_;
};

// Thrown by the measurement's poll when the case has to stop: for the runner's stop signal
// (out_of_time empty) or for its time limit.
struct MeasurementStopped {
  std::optional<std::string> out_of_time;
};

// The shorter of the scene's run.wall_time_limit and the case's time limit; 0: none.
double case_wall_limit_s(const SceneConfig& scene, const CaseContext& ctx) {
  const double a = scene.wall_time_limit, b = ctx.time_limit_s();
  return a > 0 && b > 0 ? std::min(a, b) : std::max(a, b);
}

void check_finite(const ParticleSnapshot& s) {
  for (std::size_t i = 0; i < s.size(); ++i) {
    const bool ok = std::isfinite(s.x[i]) && std::isfinite(s.z[i]) && std::isfinite(s.eps_v_p[i]) &&
                    (s.y.empty() || std::isfinite(s.y[i]));
    if (!ok)
      throw SimulationError("non-finite state of particle " + std::to_string(i) +
                            " at the end of the run (t = " + std::to_string(s.time_s) + " s)");
  }
}

}  // namespace

std::string case_file_stem(std::size_t index) {
  char stem[32];
  std::snprintf(stem, sizeof stem, "case_%03zu_", index);
  return stem;
}

nlohmann::json particle_file_metadata(const SceneConfig& scene, const analysis::MeasureSettings& measurement,
                                     const std::string& case_id, const std::string& label) {
  return {{"case_id", case_id},
          {"label", label},
          {"engine_version", CREVASSE_ENGINE_VERSION},
          {"density_kg_m3", scene.density},
          {"gravity_m_s2", scene.gravity},
          {"measurement", measure_settings_to_json(measurement)}};
}

void measure_final_state(const StudyCase& study_case, CaseContext& ctx, const ParticleSnapshot& final_snapshot,
                         CaseOutcome& out) {
  // The measurement stops for the same signal and clock as the run: the case stays pending, or
  // fails out of time.
  const double limit_s = case_wall_limit_s(study_case.scene, ctx);
  const analysis::MeasurePoll poll = [&ctx, limit_s] {
    if (ctx.stop_requested()) throw MeasurementStopped{};
    if (limit_s > 0 && ctx.elapsed_s() > limit_s) {
      char what[160];
      std::snprintf(what, sizeof what,
                    "time limit: %g s (run.wall_time_limit or the case time limit) reached while measuring", limit_s);
      throw MeasurementStopped{what};
    }
  };
  try {
    out.measurement = analysis::measure_crevasses(final_snapshot, ctx.measurement(), poll);
    // The other spacing rule on the same snapshot, so that both are reported
    // (docs/measurement.md, "The source study's rule"): result_json.other_spacing_rule.
    analysis::MeasureSettings other = ctx.measurement();
    other.spacing_rule = other.spacing_rule == "merge" ? "drop" : "merge";
    const analysis::CrevasseMeasurement alt = analysis::measure_crevasses(final_snapshot, other, poll);
    nlohmann::json depths = nlohmann::json::array();
    for (const auto& c : alt.crevasses) depths.push_back(c.depth_m);
    out.result_extra["other_spacing_rule"] = {
        {"spacing_rule", other.spacing_rule},
        {"crevasse_count", alt.crevasses.size()},
        {"spacings_m", alt.spacings_m},
        {"depths_m", depths},
        {"dropped_spacing_count", alt.dropped_spacing_count},
        {"spacing_median_m", alt.spacing_m ? nlohmann::json(alt.spacing_m->median) : nlohmann::json()},
        {"depth_median_m", alt.depth_m ? nlohmann::json(alt.depth_m->median) : nlohmann::json()}};
  } catch (const std::invalid_argument& e) {
    throw SimulationError(std::string("measurement of the final snapshot failed: ") + e.what());
  } catch (const MeasurementStopped& stopped) {
    out.cancelled = true;
    out.out_of_time = stopped.out_of_time;
    out.measurement.reset();
    return;
  }
  const std::string stem = case_file_stem(study_case.index);
  write_side_files(ctx, ctx.views_dir(), "side views", [&](const std::filesystem::path& dir) {
    write_case_views(study_case.scene, final_snapshot, *out.measurement, dir, stem);
  });
  write_side_files(ctx, ctx.particles_dir(), "kept particles", [&](const std::filesystem::path& dir) {
    write_particle_file(dir / (stem + "particles.bin"), final_snapshot,
                        particle_file_metadata(study_case.scene, ctx.measurement(), study_case.case_id, study_case.label));
  });
}

CaseOutcome run_engine_case(const StudyCase& study_case, CaseContext& ctx) {
  SceneConfig scene = study_case.scene;
  scene.vtu_interval = 0.0;
  scene.png = false;
  // The shorter of the scene's run.wall_time_limit and the case's time limit. The engine saves
  // the checkpoint when it fires and leaves the limit out of the checkpoint's scene, so a case
  // that ran out of time continues from where it stopped once the limit is raised (the runner
  // keeps the checkpoint).
  scene.wall_time_limit = case_wall_limit_s(scene, ctx);
  CaseObserver observer(study_case, ctx);
  RunSummary r;
  try {
    r = run_scene(scene, &observer);
  } catch (const TimeLimitError& e) {
    CaseOutcome out;
    out.cancelled = true;
    char what[200];
    if (e.settled)
      std::snprintf(what, sizeof what, "time limit: %g s (run.wall_time_limit or the case time limit) reached at t = %.1f s (%.0f%% done)",
                    e.limit_s, e.sim_time_s, 100.0 * e.fraction_done);
    else
      std::snprintf(what, sizeof what, "time limit: %g s (run.wall_time_limit or the case time limit) reached while settling",
                    e.limit_s);
    out.out_of_time = what;
    return out;
  }

  CaseOutcome out;
  if (r.stop_reason == "cancelled") {
    out.cancelled = true;
    return out;
  }
  check_finite(r.final_snapshot);
  out.stop_reason = r.stop_reason;
  out.steps = r.steps;
  out.particle_steps = r.particle_steps;
  out.sim_time_s = r.sim_time_s;
  out.result_extra = result_extra_of(r);
  if (ctx.measure_interval_s() > 0) {
    // The series ends with the final state, measured as the case's result is.
    FieldOverTime series = observer.over_time();
    series.add(r.final_snapshot, ctx.measurement());
    out.result_extra["over_time"] = series.rows();
  }
  out.run_json = run_json_of(r, ctx.earlier_wall_s());
  measure_final_state(study_case, ctx, r.final_snapshot, out);
  return out;
}

}  // namespace crevasse
