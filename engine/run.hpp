#pragma once
// Runs one scene to its stop condition, dispatching on the dimension. Progress and output go
// through an observer the caller passes in: the engine has no global logger.
#include <cstdint>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "engine/scene.hpp"
#include "engine/snapshot.hpp"

namespace crevasse {

struct RunProgress {
  double sim_time_s = 0.0;
  double fraction_done = 0.0;  // of the stop condition that will end the run, in [0, 1]
  std::int64_t steps = 0;
  std::size_t particles = 0;
  double steps_per_second = 0.0;
  double particle_steps_per_second = 0.0;
  double eta_s = 0.0;          // wall-clock estimate of the remaining time
  double front_x_m = 0.0;
  double wall_s = 0.0;
};

struct RunSummary;

class RunObserver {
 public:
  virtual ~RunObserver() = default;
  virtual void on_progress(const RunProgress&) {}
  // Called at t = 0 and every scene.vtu_interval of simulated time, when that interval is > 0.
  virtual void on_output(const ParticleSnapshot&, int /*index*/) {}
  // Called every snapshot_interval_s() of simulated time when that is > 0 (e.g. to measure the
  // crevasses while the run goes on), independently of the VTU output.
  virtual double snapshot_interval_s() const { return 0.0; }
  virtual void on_snapshot(const ParticleSnapshot&) {}
  // Checkpoints: when checkpoint_path() is not empty, the run continues from that file if it
  // exists (a run killed earlier), writes it every checkpoint_interval_s() wall seconds, the
  // settling phase included, and when cancelled, and deletes it when the run ends with a stop
  // rule (Simulation::save_checkpoint). A checkpoint can only help: one that cannot be used
  // (not a regular file, truncated, corrupt, of another scene or engine version) is reported
  // through on_warning, removed, and the run starts from t = 0; a write that fails is reported
  // and the run goes on.
  virtual std::string checkpoint_path() const { return {}; }
  virtual double checkpoint_interval_s() const { return 600.0; }
  virtual void on_warning(const std::string& /*message*/) {}
  // Called once, before the first step, when the run continues from its checkpoint: how far it
  // had got then (as RunProgress::fraction_done) and the wall seconds it had cost (nullopt: not
  // known, the checkpoint being of format 2). This is the one way the earlier wall time leaves
  // the run: it reaches the observer also when the run then fails or runs out of time.
  virtual void on_resumed(double /*fraction_done*/, std::optional<double> /*earlier_wall_s*/) {}
  // Gate marks [m of ice through the gate, ascending]: when the passed length first reaches one,
  // on_gate_mark gets the run's summary as if it had stopped there, which is bit for bit what a
  // run with run.gate_length = that mark stops with (one run serves a shorter protocol too).
  // Marks are checked after each step, before any checkpoint of that step's state is written, so
  // a resumed run calls none twice: marks already reached when it resumes are not called.
  virtual std::vector<double> gate_marks() const { return {}; }
  virtual void on_gate_mark(double /*mark_m*/, const RunSummary& /*as_if_stopped*/) {}
  // Return true to stop the run early (cancellation); the run then ends with "cancelled".
  virtual bool cancelled() { return false; }
  // Wall seconds between on_progress calls.
  virtual double progress_interval_s() const { return 2.0; }
};

// The stop rule for a gate run whose ice no longer reaches the gate. The piston can leave the
// last block of a strong slab behind on the plateau (measured: H_i = 400 m, Π = 1, V_x = 2 m/s,
// 99 % of run.gate_length passed, then nothing for the next 190,000 simulated seconds until
// the wall-time limit). A run asked for the whole slab (gate_length = upstream_length) stops
// here too: the passed length, a sum of particle volumes, falls short of it by round-off.
// stalled() is true once, after the drive's ramp, the passed length has grown by less than
// `min_growth_m` over `window_s` of simulated time; run_scene() then stops with
// "gate_stalled" and the ice that did pass is measured as usual.
struct GateStallWatch {
  double window_s = 0.0;      // 2·H_i/V_x: the time the piston takes to push two ice thicknesses
  double min_growth_m = 0.0;  // one cell
  double ramp_s = 0.0;        // no verdict while the piston speeds up
  double mark_length_m = -1.0, mark_time_s = 0.0;
  bool stalled(double time_s, double passed_m) {
    if (time_s < ramp_s) return false;
    if (mark_length_m < 0.0 || passed_m >= mark_length_m + min_growth_m) {
      mark_length_m = passed_m;
      mark_time_s = time_s;
      return false;
    }
    return time_s - mark_time_s > window_s;
  }
};

struct RunSummary {
  std::string stop_reason;  // "front_past_step", "gate_length", "gate_stalled", "end_time", "max_steps", "cancelled", "no_ice_left"
  std::int64_t steps = 0;
  std::int64_t particle_steps = 0;
  std::int64_t return_map_evaluations = 0;
  double sim_time_s = 0.0;
  double wall_s = 0.0;  // this sitting's (RunObserver::on_resumed gives the earlier ones')
  double initial_mass = 0.0;
  double final_mass = 0.0;
  double removed_mass = 0.0;
  double inflow_mass = 0.0;  // entered through the inflow boundary
  std::size_t initial_particles = 0;
  std::size_t final_particles = 0;
  nlohmann::json stage_seconds;  // per stage: seconds and calls
  double final_ice_front_x = 0.0;  // front of the connected ice at the end [m]
  double resumed_from_time_s = -1.0;  // simulated time of the checkpoint it continued from; −1: none
  ParticleSnapshot final_snapshot;
};

// Throws SimulationError on instability, and TimeLimitError (after saving the checkpoint, if
// any) when run.wall_time_limit is exceeded; both are checked between steps, the settling phase
// included.
RunSummary run_scene(const SceneConfig& scene, RunObserver* observer = nullptr);

}  // namespace crevasse
