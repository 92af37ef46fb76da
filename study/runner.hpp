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
#include <map>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "analysis/crevasse_measure.hpp"
#include "study/case_context.hpp"
#include "study/shard.hpp"
#include "study/store.hpp"
#include "study/study_file.hpp"

namespace crevasse {

// Core split, measured on 2 cores (docs/study_format.md): one engine thread per case and as
// many cases at once as there are cores was faster than fewer cases with more threads each.
inline constexpr int kDefaultThreadsPerCase = 1;
// Cases at once when neither --jobs nor resources.jobs says: the cores / threads per case.
int default_jobs(int threads_per_case);

struct RunnerProgress {
  std::size_t total = 0;  // cases in scope (this shard)
  std::size_t done = 0, failed = 0, running = 0, pending = 0;
  double elapsed_s = 0.0;
  std::optional<double> eta_s;
  // The running cases: {StudyCase::index, how far it has got, 0 to 1}, by index.
  std::vector<std::pair<std::size_t, double>> running_cases;
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
  // Non-empty: run only these cases (indices, sorted; parse_case_list); the others in scope stay
  // as they are. Each must be in scope (in the shard, with --shard).
  std::vector<std::size_t> only_cases;
  std::string command;         // recorded in the sessions table
  CaseFunction case_function;  // empty: run_engine_case (engine_case.hpp)
  StudyObserver* observer = nullptr;
  // Warnings that do not fail a case (a checkpoint that could not be written or used), with
  // the case's label; called on the calling thread. Empty: not shown.
  std::function<void(const std::string&)> warn;
  std::filesystem::path views_dir;      // non-empty: each case writes its side views there
  std::filesystem::path particles_dir;  // non-empty: and keeps its final particles there
  // Set from outside (a signal handler) to end the session early: no new case starts, and the
  // running ones save a checkpoint and stay pending for the next session (report.interrupted).
  std::atomic<bool>* interrupt = nullptr;
};

// The cases of `scope` a run starts, given the stored `status` of each case id: those selected by
// `only_cases` (all when empty; sorted) that are not stored as done, nor as failed unless
// `retry_failed`. A case with no status yet, or left "running" by a stopped session, is to run.
std::vector<const StudyCase*> cases_to_run(const std::vector<const StudyCase*>& scope,
                                           const std::map<std::string, std::string>& status,
                                           const std::vector<std::size_t>& only_cases, bool retry_failed);

// Throws InputError before anything runs when the database is unusable or holds another study,
// or when DB.checkpoints (needed when resources.checkpoint_interval_s > 0) is not a directory.
RunnerReport run_study(const Study& study, const RunnerOptions& options);

}  // namespace crevasse
