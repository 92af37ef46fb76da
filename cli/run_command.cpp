#include "cli/run_command.hpp"
#include "cli/cli_common.hpp"

#include <tbb/info.h>
#include <tbb/task_arena.h>

#include <filesystem>
#include <fstream>
#include <memory>
#include <optional>

#include "analysis/bed_contact.hpp"
#include "analysis/crevasse_measure.hpp"
#include "analysis/measurement_io.hpp"
#include "cli/progress_printer.hpp"
#include "engine/atomic_file.hpp"
#include "engine/error.hpp"
#include "engine/run.hpp"
#include "engine/particle_file.hpp"
#include "engine/vtu_writer.hpp"
#include "study/case_views.hpp"
#include "study/engine_case.hpp"
#include "study/memory_check.hpp"
#include "study/memory_reserve.hpp"
#include "study/scene_file.hpp"

namespace crevasse {
namespace fs = std::filesystem;

namespace {

class CliObserver : public RunObserver {
 public:
  CliObserver(fs::path out, bool quiet) : out_(std::move(out)), quiet_(quiet) {}
  // A safe place to stop when an allocation had to take the memory reserve
  // (study/memory_reserve.hpp): one line, exit 1.
  bool cancelled() override {
    throw_if_memory_ran_out();
    return false;
  }
  void on_progress(const RunProgress& p) override {
    if (quiet_) return;
    char buf[256];
    std::snprintf(buf, sizeof buf,
                  "[%3.0f%%] t = %.1f s  front x = %.0f m  %lld steps  %.0f steps/s  %.2f M "
                  "particle-steps/s  ETA %s",
                  100.0 * p.fraction_done, p.sim_time_s, p.front_x_m,
                  static_cast<long long>(p.steps), p.steps_per_second,
                  p.particle_steps_per_second / 1e6, format_duration(p.eta_s).c_str());
    printer_.update(buf);
  }
  void on_output(const ParticleSnapshot& s, int index) override {
    char name[64];
    std::snprintf(name, sizeof name, "particles_%05d.vtu", index);
    write_vtu((out_ / "snapshots" / name).string(), s);
    files_.emplace_back(s.time_s, std::string("snapshots/") + name);
    write_pvd((out_ / "particles.pvd").string(), files_);
  }
  void finish() { printer_.finish(); }

  // Periodic measurements (--measure-interval): one row per snapshot, and the final one.
  void set_measure_interval(double s) { measure_interval_ = s; }
  double snapshot_interval_s() const override { return measure_interval_; }
  void on_snapshot(const ParticleSnapshot& s) override { add_row(s, analysis::measure_crevasses(s)); }
  void add_row(const ParticleSnapshot& s, const analysis::CrevasseMeasurement& m) {
    if (measure_interval_ <= 0.0) return;
    const bool first = !rows_;
    std::ofstream f(out_ / "measurements_over_time.csv", first ? std::ios::trunc : std::ios::app);
    if (first)
      f << "time_s,gate_passed_length_m,frame,window_min_x_m,window_max_x_m,crevasse_count,"
           "spacing_q25_m,spacing_median_m,spacing_q75_m,depth_median_m,fragmented,no_crevasse,"
           "ramp_gap_max_m,ramp_gap_x_m\n";
    auto num = [](const std::optional<analysis::QuartileSummary>& q, int k) {
      if (!q) return std::string();
      return std::to_string(k == 0 ? q->q25 : k == 1 ? q->median : q->q75);
    };
    f << s.time_s << "," << s.gate_passed_length_m << "," << m.settings.frame << ","
      << m.settings.window_min_x_m << "," << m.settings.window_max_x_m << ","
      << m.crevasses.size() << "," << num(m.spacing_m, 0) << "," << num(m.spacing_m, 1) << ","
      << num(m.spacing_m, 2) << "," << num(m.depth_m, 1) << "," << m.flags.fragmented << ","
      << m.flags.no_crevasse << ",";
    if (s.bed_profile.size() >= 2 && s.step_foot_x_m > s.step_top_x_m) {
      const auto c = analysis::ramp_contact(s);
      f << c.max_gap_m << "," << c.max_gap_x_m;
    } else {
      f << ",";
    }
    f << "\n";
    ++rows_;
  }

 private:
  double measure_interval_ = 0.0;
  int rows_ = 0;
  fs::path out_;
  bool quiet_;
  ProgressPrinter printer_;
  std::vector<std::pair<double, std::string>> files_;
};

}  // namespace

int run_command(const RunCommandOptions& opt) {
  SceneConfig scene = load_scene_file(opt.scene_path);
  if (opt.vtu_interval >= 0) scene.vtu_interval = opt.vtu_interval;
  const fs::path out(opt.out_dir);
  check_output_directory("--out", out,
                         {"snapshots/", "scene_resolved.json", "run_summary.json", "crevasses.csv",
                          "measurement.json", "measurements_over_time.csv", "final_particles.bin", "side_view.png",
                          "gate_view.png"});
  check_memory_fits({&scene}, "the scene", read_memory_headroom());
  std::error_code ec;
  fs::create_directories(out / "snapshots", ec);
  if (ec)
    throw InputError("--out: cannot create directory " + out.string() + " (" + ec.message() + ")");
  write_file_atomically(out / "scene_resolved.json", scene_to_json(scene).dump(2) + "\n");

  CliObserver obs(out, opt.quiet);
  obs.set_measure_interval(opt.measure_interval);
  // The arena bounds the threads (--threads). Under it a worker that cannot start (ulimit -v,
  // -u) reaches this thread as an exception, one line and exit 1, not a termination inside TBB.
  RunSummary r;
  tbb::task_arena arena(opt.threads > 0 ? opt.threads : tbb::info::default_concurrency());
  arena.execute([&] { r = run_scene(scene, &obs); });
  obs.finish();

  nlohmann::json summary = {
      {"scene", scene.name},
      {"stop_reason", r.stop_reason},
      {"steps", r.steps},
      {"particle_steps", r.particle_steps},
      {"return_map_evaluations", r.return_map_evaluations},
      {"sim_time_s", r.sim_time_s},
      {"wall_s", r.wall_s},
      {"particle_steps_per_s", r.wall_s > 0 ? r.particle_steps / r.wall_s : 0.0},
      {"initial_particles", r.initial_particles},
      {"final_particles", r.final_particles},
      {"initial_mass", r.initial_mass},
      {"final_mass", r.final_mass},
      {"removed_mass", r.removed_mass},
      {"inflow_mass", r.inflow_mass},
      {"stage_seconds", r.stage_seconds},
      {"engine_version", CREVASSE_ENGINE_VERSION},
  };
  write_file_atomically(out / "run_summary.json", summary.dump(2) + "\n");

  // Crevasses at the end of the run (in the gate frame when the scene records one;
  // docs/measurement.md), and the side views with each one marked.
  const analysis::CrevasseMeasurement m =
      analysis::measure_crevasses(r.final_snapshot, analysis::MeasureSettings{});
  obs.add_row(r.final_snapshot, m);
  analysis::write_crevasses_csv(m, out / "crevasses.csv");
  analysis::write_measurement_summary(m, out / "measurement.json");
  write_particle_file(out / "final_particles.bin", r.final_snapshot,
                      particle_file_metadata(scene, analysis::MeasureSettings{}, "", scene.name));
  if (scene.png) write_case_views(scene, r.final_snapshot, m, out);
  if (!opt.quiet) {
    std::fprintf(
        stderr,
        "done: %s after %lld steps, t = %.1f s, wall %.1f s (%.2f M particle-steps/s) -> %s\n",
        r.stop_reason.c_str(), static_cast<long long>(r.steps), r.sim_time_s, r.wall_s,
        r.wall_s > 0 ? r.particle_steps / r.wall_s / 1e6 : 0.0, out.string().c_str());
  }
  return 0;
}

}  // namespace crevasse
