#pragma once
// Runs a study's cases (docs/study_format.md): skips the ones already stored, runs the rest concurrently on
// TBB (each case in its own task arena of `threads_per_case` engine threads), survives failing
// cases (recorded with their reason) and killed runs (rerun the same command: nothing stored is
// lost, nothing finished is rerun), and reports progress to an observer the caller passes in.
// Only the calling thread touches the database: workers hand finished cases to it.
#include <atomic>
#include <chrono>
#include <filesystem>
#include <functional>
#include <optional>
#include <string>

#include "analysis/crevasse_measure.hpp"
#include "study/shard.hpp"
#include "study/store.hpp"
#include "study/study_file.hpp"

namespace crevasse {

// Core split, measured on 2 cores (docs/study_format.md): one engine thread per case and as
// many cases at once as there are cores was faster than fewer cases with more threads each.
inline constexpr int kDefaultThreadsPerCase = 1;
// Cases at once when neither --jobs nor resources.jobs says: the cores / threads per case.
int default_jobs(int threads_per_case);

// What a case hands back to the runner.
struct CaseOutcome {
  bool cancelled = false;  // stopped because the runner asked (fail-fast): stays pending
  std::string stop_reason;
  std::int64_t steps = 0;
  std::int64_t particle_steps = 0;
  double sim_time_s = 0.0;
  nlohmann::json run_json = nlohmann::json::object();  // timings and other non-deterministic data
  nlohmann::json result_extra =
      nlohmann::json::object();  // deterministic data beyond the measurement
  std::optional<analysis::CrevasseMeasurement> measurement;
};

// What the runner gives a case: its budget, a way to learn that it should stop, and a way to
// report how far it has got (for the ETA).
class CaseContext {
 public:
  CaseContext(int threads, double time_limit_s, const analysis::MeasureSettings& measurement,
              const std::atomic<bool>& stop, std::atomic<double>& fraction);
  int threads() const { return threads_; }
  double time_limit_s() const { return time_limit_s_; }  // 0 = none
  const analysis::MeasureSettings& measurement() const { return measurement_; }
  bool time_limit_exceeded() const;
  bool should_stop() const { return stop_.load() || time_limit_exceeded(); }
  void report_fraction(double f) { fraction_.store(f); }
  double elapsed_s() const;
  // Where the case keeps its checkpoint and how often it writes it (wall s); empty: none.
  void set_checkpoint(std::filesystem::path file, double interval_s) {
    checkpoint_file_ = std::move(file);
    checkpoint_interval_s_ = interval_s;
  }
  const std::filesystem::path& checkpoint_file() const { return checkpoint_file_; }
  double checkpoint_interval_s() const { return checkpoint_interval_s_; }
  // Where the case writes its side views (empty: none).
  void set_views_dir(std::filesystem::path dir) { views_dir_ = std::move(dir); }
  const std::filesystem::path& views_dir() const { return views_dir_; }

 private:
  int threads_;
  double time_limit_s_;
  const analysis::MeasureSettings& measurement_;
  const std::atomic<bool>& stop_;
  std::atomic<double>& fraction_;
  std::chrono::steady_clock::time_point start_;
  std::filesystem::path checkpoint_file_;
  double checkpoint_interval_s_ = 0.0;
  std::filesystem::path views_dir_;
};

// Runs one case; throws (SimulationError, InputError, anything) to fail it.
using CaseFunction = std::function<CaseOutcome(const StudyCase&, CaseContext&)>;

struct RunnerProgress {
  std::size_t total = 0;  // cases in scope (this shard)
  std::size_t done = 0, failed = 0, running = 0, pending = 0;
  double elapsed_s = 0.0;
  std::optional<double> eta_s;
};

struct RunnerReport {
  std::size_t in_scope = 0;        // cases of this shard (all cases without --shard)
  std::size_t already_done = 0;    // stored before this run
  std::size_t already_failed = 0;  // stored as failed before this run and not retried
  std::size_t interrupted = 0;     // left 'running' by a killed run, run again
  std::size_t ran = 0, done = 0, failed = 0, cancelled = 0;
  bool stopped = false;       // --fail-fast stopped the run
  bool interrupted_by_request = false;  // RunnerOptions::interrupt ended the session
  std::string first_failure;  // "label: reason"
  double wall_s = 0.0;
  int jobs = 0, threads_per_case = 0;
  std::string session_id;
};

class StudyObserver {
 public:
  virtual ~StudyObserver() = default;
  virtual void on_start(const RunnerReport& /*plan*/, const RunnerProgress&) {}
  virtual void on_case_finished(const StudyCase&, const CaseResult&, const RunnerProgress&) {}
  virtual void on_progress(const RunnerProgress&) {}  // about once a second
  virtual void on_end(const RunnerReport&) {}
};

struct RunnerOptions {
  std::filesystem::path db_path;
  int jobs = 0;                             // 0: resources.jobs, else default_jobs()
  int threads_per_case = 0;                 // 0: resources.threads_per_case, else kDefault…
  std::optional<double> case_time_limit_s;  // overrides resources.case_time_limit_s
  bool fail_fast = false;
  bool retry_failed = false;  // run cases stored as failed again
  std::optional<Shard> shard;
  std::string command;         // recorded in the sessions table
  CaseFunction case_function;  // empty: run_engine_case (engine_case.hpp)
  StudyObserver* observer = nullptr;
  std::filesystem::path views_dir;  // non-empty: each case writes its side views there
  // Set from outside (a signal handler) to end the session early: no new case starts, and the
  // running ones save a checkpoint and stay pending for the next session (report.interrupted).
  std::atomic<bool>* interrupt = nullptr;
};

// Throws InputError before anything runs when the database is unusable or holds another study.
RunnerReport run_study(const Study& study, const RunnerOptions& options);

}  // namespace crevasse
