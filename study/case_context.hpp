#pragma once
// What passes between the runner and one case: the case's budget and stop signal in, its
// outcome back. Both the runner (runner.hpp) and the engine's case function (engine_case.hpp)
// depend on these types, not on each other.
#include <atomic>
#include <chrono>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "analysis/crevasse_measure.hpp"
#include "study/study_file.hpp"

namespace crevasse {

// What a case hands back to the runner.
struct CaseOutcome {
  bool cancelled = false;  // stopped because the runner asked (fail-fast): stays pending
  // Set with `cancelled` when the case stopped at its time limit instead: why, for the failure.
  // The run saved its checkpoint, which the runner keeps.
  std::optional<std::string> out_of_time;
  std::string stop_reason;
  std::int64_t steps = 0;
  std::int64_t particle_steps = 0;
  double sim_time_s = 0.0;
  nlohmann::json run_json = nlohmann::json::object();  // timings and other non-deterministic data
  nlohmann::json result_extra =
      nlohmann::json::object();  // deterministic data beyond the measurement
  std::optional<analysis::CrevasseMeasurement> measurement;
};

// How far a running case has got, written by the case and read by the runner's writer (the ETA).
struct CaseProgress {
  std::atomic<double> fraction{0.0};  // 0 to 1
  // Where the case continued from when it resumed from a checkpoint (0 to 1); −1: it started
  // fresh, or has not said yet. Set before any fraction past it is reported.
  std::atomic<double> resumed_from{-1.0};
};

// What the runner gives a case: its budget, a way to learn that it should stop, and a way to
// report how far it has got (for the ETA).
class CaseContext {
 public:
  CaseContext(int threads, double time_limit_s, const analysis::MeasureSettings& measurement,
              const std::atomic<bool>& stop, CaseProgress& progress);
  int threads() const { return threads_; }
  double time_limit_s() const { return time_limit_s_; }  // 0 = none
  const analysis::MeasureSettings& measurement() const { return measurement_; }
  // For a case function without a clock of its own: it stops and says so in
  // CaseOutcome::out_of_time. The runner takes a cancelled case without it as stopped.
  bool time_limit_exceeded() const;
  bool stop_requested() const { return stop_.load(); }
  void report_fraction(double f) { progress_.fraction.store(f); }
  // The case continued from a checkpoint written at `fraction`, after `earlier_wall_s` wall
  // seconds of earlier sittings (nullopt: not known); both count in its ETA and its stored
  // wall time.
  void report_resumed(double fraction, std::optional<double> earlier_wall_s) {
    earlier_wall_s_ = earlier_wall_s;
    progress_.resumed_from.store(fraction);
  }
  double elapsed_s() const;
  std::optional<double> earlier_wall_s() const { return earlier_wall_s_; }
  // This sitting's wall seconds and those of the sittings before its checkpoint, when known
  // (otherwise a lower bound: run_json says so).
  double whole_wall_s() const { return elapsed_s() + earlier_wall_s_.value_or(0.0); }
  // Where the case keeps its checkpoint and how often it writes it (wall s); empty: none.
  void set_checkpoint(std::filesystem::path file, double interval_s) {
    checkpoint_file_ = std::move(file);
    checkpoint_interval_s_ = interval_s;
  }
  const std::filesystem::path& checkpoint_file() const { return checkpoint_file_; }
  double checkpoint_interval_s() const { return checkpoint_interval_s_; }
  // Something the user should know that does not fail the case (a checkpoint that could not be
  // written or used); the runner hands it to RunnerOptions::warn.
  void set_warn(std::function<void(const std::string&)> warn) { warn_ = std::move(warn); }
  void warn(const std::string& message) const {
    if (warn_) warn_(message);
  }
  // Where the case writes its side views (empty: none).
  void set_views_dir(std::filesystem::path dir) { views_dir_ = std::move(dir); }
  const std::filesystem::path& views_dir() const { return views_dir_; }
  // > 0: the case also measures its field every this many simulated seconds
  // (Study::measure_interval_s).
  void set_measure_interval(double s) { measure_interval_s_ = s; }
  double measure_interval_s() const { return measure_interval_s_; }
  // Lengths of ice through the gate, in H_i, at which the case also keeps its particles
  // (Study::gate_mark_ratios; only where it keeps its final particles).
  void set_gate_mark_ratios(std::vector<double> r) { gate_mark_ratios_ = std::move(r); }
  const std::vector<double>& gate_mark_ratios() const { return gate_mark_ratios_; }
  // Where the case keeps its final particles (case_NNN_particles.bin; empty: nowhere).
  void set_particles_dir(std::filesystem::path dir) { particles_dir_ = std::move(dir); }
  const std::filesystem::path& particles_dir() const { return particles_dir_; }

 private:
  int threads_;
  double time_limit_s_;
  const analysis::MeasureSettings& measurement_;
  const std::atomic<bool>& stop_;
  CaseProgress& progress_;
  std::chrono::steady_clock::time_point start_;
  std::optional<double> earlier_wall_s_ = 0.0;
  std::filesystem::path checkpoint_file_;
  double checkpoint_interval_s_ = 0.0;
  std::filesystem::path views_dir_;
  std::filesystem::path particles_dir_;
  double measure_interval_s_ = 0.0;
  std::vector<double> gate_mark_ratios_;
  std::function<void(const std::string&)> warn_;
};

// Where a case keeps the field it measured over time while it has a checkpoint, so that a
// resumed case stores the whole series.
inline std::filesystem::path over_time_file(const std::filesystem::path& checkpoint) {
  return checkpoint.string() + ".over_time.json";
}

// Runs one case; throws (SimulationError, InputError, anything) to fail it.
using CaseFunction = std::function<CaseOutcome(const StudyCase&, CaseContext&)>;

}  // namespace crevasse
