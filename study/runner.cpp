#include "study/runner.hpp"

#include <tbb/global_control.h>
#include <tbb/task_arena.h>
#include <unistd.h>

#include <algorithm>
#include <condition_variable>
#include <deque>
#include <exception>
#include <fstream>
#include <map>
#include <memory>
#include <mutex>
#include <new>
#include <thread>

#include "analysis/measurement_io.hpp"
#include "engine/error.hpp"
#include "study/engine_case.hpp"
#include "study/eta.hpp"
#include "study/memory_check.hpp"
#include "study/memory_reserve.hpp"

namespace crevasse {
namespace {

using clock_type = std::chrono::steady_clock;

// Next to the database, so that a resumed session finds it.
std::filesystem::path checkpoint_dir(const std::filesystem::path& db) { return db.string() + ".checkpoints"; }

double seconds_since(clock_type::time_point t0) {
  return std::chrono::duration<double>(clock_type::now() - t0).count();
}

// Peak resident set (VmHWM) of this process, and its reset (Linux ≥ 4.0: writing 5 to
// clear_refs). With one case at a time this is the case's own peak.
std::optional<std::int64_t> peak_rss_bytes() {
  std::ifstream f("/proc/self/status");
  std::string key;
  while (f >> key) {
    if (key == "VmHWM:") {
      std::int64_t kb = 0;
      f >> kb;
      return kb * 1024;
    }
    std::getline(f, key);
  }
  return std::nullopt;
}

void reset_peak_rss() {
  std::ofstream f("/proc/self/clear_refs");
  if (f) f << "5";
}

std::string host_name() {
  char host[256] = "unknown";
  gethostname(host, sizeof host - 1);
  host[sizeof host - 1] = '\0';
  return host;
}

nlohmann::json deterministic_result(const CaseOutcome& o) {
  nlohmann::json j = {{"status", "done"},           {"stop_reason", o.stop_reason},
                      {"steps", o.steps},           {"particle_steps", o.particle_steps},
                      {"sim_time_s", o.sim_time_s}, {"extra", o.result_extra}};
  if (o.measurement) j["measurement"] = analysis::measurement_summary_json(*o.measurement);
  return j;
}

// What a worker hands to the writer (the calling thread).
struct Event {
  enum class Kind { started, finished, cancelled, warning } kind;
  std::size_t slot = 0;  // index into the list of cases to run
  CaseResult result;     // finished only
  std::string started_at;
  std::string message;  // warning only
};

class EventQueue {
 public:
  void push(Event e) {
    {
      std::lock_guard lock(mutex_);
      events_.push_back(std::move(e));
    }
    cv_.notify_one();
  }
  void close() {
    {
      std::lock_guard lock(mutex_);
      closed_ = true;
    }
    cv_.notify_one();
  }
  // Waits up to `timeout` for events; returns them and whether the producers are finished.
  std::pair<std::vector<Event>, bool> take(std::chrono::milliseconds timeout) {
    std::unique_lock lock(mutex_);
    cv_.wait_for(lock, timeout, [&] { return !events_.empty() || closed_; });
    std::vector<Event> out(std::make_move_iterator(events_.begin()),
                           std::make_move_iterator(events_.end()));
    events_.clear();
    return {std::move(out), closed_};
  }

 private:
  std::mutex mutex_;
  std::condition_variable cv_;
  std::deque<Event> events_;
  bool closed_ = false;
};

}  // namespace

int default_jobs(int threads_per_case) {
  const int cores = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  return std::max(1, cores / std::max(1, threads_per_case));
}

namespace {

// One run of a study: set up (everything that can refuse the run does so before a case
// starts), the workers that run one case at a time each, and the writer loop on the calling
// thread, which alone touches the database.
class StudyRun {
 public:
  StudyRun(const Study& study, const RunnerOptions& opt)
      : study_(study), opt_(opt), t0_(clock_type::now()), store_(Store::open_writer(opt.db_path)) {}

  RunnerReport run() {
    set_up();
    try {
      return run_cases();
    } catch (...) {
      // Out of memory or threads, or a store that failed: the running cases go back to pending
      // and the session is closed, so that the next session neither waits for nor reruns
      // anything by mistake. Best effort: the store may be what failed.
      stop().store(true);
      try {
        store_.reset_running();
        store_.end_session(report_.session_id, "stopped", static_cast<std::int64_t>(report_.ran));
      } catch (...) {
      }
      throw;
    }
  }

 private:
  RunnerReport run_cases() {
    const int jobs = std::max(
        1, std::min<int>(report_.jobs, static_cast<int>(std::max<std::size_t>(todo_.size(), 1))));
    // Workers: `jobs` loops, each taking the next case; each case runs in its own arena so that
    // the engine's parallel loops use exactly threads_per_case threads.
    tbb::global_control parallelism(tbb::global_control::max_allowed_parallelism,
                                    static_cast<std::size_t>(std::max(1, jobs * report_.threads_per_case)));
    exact_peak_rss_ = jobs == 1;
    progress_of_ = std::vector<CaseProgress>(todo_.size());
    // One plain thread per job: a job blocks on its case for minutes, which is no work for
    // TBB's scheduler, and thread start/join is a hand-over ThreadSanitizer can see (TBB's own
    // queues, in an uninstrumented libtbb, are not). Each case still runs in its own task arena.
    std::exception_ptr worker_error;
    std::mutex worker_error_mutex;
    auto keep_error = [&] {
      const std::lock_guard<std::mutex> lock(worker_error_mutex);
      if (!worker_error) worker_error = std::current_exception();
      stop().store(true);
    };
    std::thread executor([&] {
      std::vector<std::thread> workers;
      try {
        for (int j = 0; j < jobs; ++j)
          workers.emplace_back([&] {
            try {
              while (!stop().load()) {
                const std::size_t slot = next_.fetch_add(1);
                if (slot >= todo_.size()) return;
                run_case(slot);
              }
            } catch (...) {
              keep_error();
            }
          });
      } catch (...) {  // a thread the system would not start ends the run like a worker's error
        keep_error();
      }
      for (auto& w : workers) w.join();
      queue_.close();
    });
    const std::exception_ptr writer_error = write_events(jobs);
    executor.join();
    if (writer_error) std::rethrow_exception(writer_error);
    if (worker_error) std::rethrow_exception(worker_error);
    return finish();
  }

  std::atomic<bool>& stop() { return opt_.interrupt ? *opt_.interrupt : own_stop_; }

  void set_up() {
    report_.threads_per_case = opt_.threads_per_case > 0 ? opt_.threads_per_case
                               : study_.resources.threads_per_case > 0
                                   ? study_.resources.threads_per_case
                                   : kDefaultThreadsPerCase;
    report_.jobs = opt_.jobs > 0               ? opt_.jobs
                   : study_.resources.jobs > 0 ? study_.resources.jobs
                                               : default_jobs(report_.threads_per_case);
    time_limit_ = opt_.case_time_limit_s.value_or(study_.resources.case_time_limit_s);
    case_function_ = opt_.case_function ? opt_.case_function : CaseFunction(run_engine_case);

    store_.init_study(study_);
    if (study_.resources.checkpoint_interval_s > 0) {
      const std::filesystem::path dir = checkpoint_dir(opt_.db_path);
      std::error_code ec;
      std::filesystem::create_directories(dir, ec);
      if (ec || !std::filesystem::is_directory(dir))
        throw InputError("resources.checkpoint_interval_s: cannot create the checkpoint folder " +
                         dir.string() + (ec ? " (" + ec.message() + ")" : "") +
                         "; remove what is in its place, or set checkpoint_interval_s to 0");
    }
    const std::vector<const StudyCase*> scope =
        opt_.shard ? shard_cases(study_, *opt_.shard) : shard_cases(study_, Shard{0, 1});
    report_.in_scope = scope.size();
    store_.add_cases(scope);
    report_.interrupted = static_cast<std::size_t>(store_.reset_running());

    SessionInfo session;
    session.host = host_name();
    session.pid = static_cast<std::int64_t>(::getpid());
    session.started_at = utc_now_iso8601();
    session.session_id = session.host + ":" + std::to_string(session.pid) + ":" +
                         std::to_string(std::chrono::duration_cast<std::chrono::milliseconds>(
                                            std::chrono::system_clock::now().time_since_epoch())
                                            .count());
    session.jobs = report_.jobs;
    session.threads_per_case = report_.threads_per_case;
    session.shard = opt_.shard ? opt_.shard->text() : "";
    session.command = opt_.command;

    for (std::size_t i : opt_.only_cases)
      if (std::none_of(scope.begin(), scope.end(), [i](const StudyCase* c) { return c->index == i; }))
        throw InputError("--cases: case " + std::to_string(i) + " is not in shard " +
                         (opt_.shard ? opt_.shard->text() : std::string("0/1")));
    const auto status = store_.statuses();
    for (const StudyCase* c : scope) {
      const std::string& st = status.at(c->case_id);
      if (st == "done")
        ++report_.already_done;
      else if (st == "failed" && !opt_.retry_failed)
        ++report_.already_failed;
    }
    todo_ = cases_to_run(scope, status, opt_.only_cases, opt_.retry_failed);
    if (!opt_.case_function) check_memory();  // before the session: the cases stay pending
    store_.begin_session(session);
    report_.session_id = session.session_id;
    progress_.total = scope.size();
    progress_.done = report_.already_done;
    progress_.failed = report_.already_failed;
    progress_.pending = todo_.size();
    if (opt_.observer) opt_.observer->on_start(report_, progress_);
  }

  // The largest cases to run, as many as run at once, must fit in the memory this process may
  // still take: otherwise the study is refused before any case starts.
  void check_memory() const {
    std::vector<const SceneConfig*> largest;
    for (const StudyCase* c : todo_) largest.push_back(&c->scene);
    const std::size_t at_once = std::min<std::size_t>(largest.size(), static_cast<std::size_t>(report_.jobs));
    std::partial_sort(largest.begin(), largest.begin() + static_cast<std::ptrdiff_t>(at_once), largest.end(),
                      [](const SceneConfig* a, const SceneConfig* b) { return case_memory_bytes(*a) > case_memory_bytes(*b); });
    largest.resize(at_once);
    if (largest.empty()) return;
    const auto it = std::find_if(todo_.begin(), todo_.end(), [&](const StudyCase* c) { return &c->scene == largest[0]; });
    std::string what = "case " + (*it)->label;
    if (at_once > 1) what += " with the next " + std::to_string(at_once - 1) + " largest at once";
    check_memory_fits(largest, what, read_memory_headroom());
  }

  // One case, on a worker: runs it and hands its start and its end to the writer.
  void run_case(std::size_t slot) {
    const StudyCase& c = *todo_[slot];
    const int threads = report_.threads_per_case;
    Event started{Event::Kind::started, slot, {}, utc_now_iso8601(), {}};
    const std::string started_at = started.started_at;
    queue_.push(std::move(started));
    if (exact_peak_rss_) reset_peak_rss();
    top_up_memory_reserve();  // in case an earlier failure could not take all of it back
    CaseContext ctx(threads, time_limit_, study_.measurement, stop(), progress_of_[slot]);
    if (!opt_.views_dir.empty()) ctx.set_views_dir(opt_.views_dir);
    if (!opt_.particles_dir.empty()) ctx.set_particles_dir(opt_.particles_dir);
    ctx.set_measure_interval(study_.measure_interval_s);
    ctx.set_gate_mark_ratios(study_.gate_mark_ratios);
    ctx.set_warn([this, slot](const std::string& m) { queue_.push(Event{Event::Kind::warning, slot, {}, {}, m}); });
    std::filesystem::path checkpoint;
    if (study_.resources.checkpoint_interval_s > 0) {
      // DB.checkpoints/CASE.ckpt, kept only while the case is unfinished (set_up made the folder).
      checkpoint = checkpoint_dir(opt_.db_path) / (c.case_id + ".ckpt");
      ctx.set_checkpoint(checkpoint, study_.resources.checkpoint_interval_s);
    }
    CaseOutcome outcome;
    std::string failure;
    try {
      tbb::task_arena arena(threads);
      arena.execute([&] { outcome = case_function_(c, ctx); });
      throw_if_memory_ran_out();  // the reserve got a case through: this one fails and frees its memory
    } catch (const SimulationError& e) {
      failure = e.what();
    } catch (const InputError& e) {
      failure = std::string("invalid input: ") + e.what();
    } catch (const std::bad_alloc&) {
      failure = "out of memory";
    } catch (const std::exception& e) {
      failure = std::string("error: ") + e.what();
    } catch (...) {
      failure = "unknown exception";
    }
    // The case's memory is freed by now: after running out, take the reserve back and let the
    // other cases go on.
    if (!failure.empty()) rearm_memory_reserve();
    bool out_of_time = false;
    // Only the case knows whether it stopped for its clock or for the stop signal: a stop
    // that arrives after the limit has passed is still a stop, and the case stays pending.
    if (failure.empty() && outcome.cancelled) {
      if (!outcome.out_of_time) {
        queue_.push(Event{Event::Kind::cancelled, slot, {}, started_at, {}});
        return;
      }
      out_of_time = true;
      failure = *outcome.out_of_time;
    }
    // A case out of time keeps its checkpoint, to continue from under a larger limit; any other
    // end is final: nothing to continue from.
    if (!checkpoint.empty()) {
      std::error_code ec;
      if (!out_of_time) {
        std::filesystem::remove(checkpoint, ec);
        std::filesystem::remove(over_time_file(checkpoint), ec);
      }
      else if (std::filesystem::is_regular_file(checkpoint, ec))
        failure += "; its checkpoint is kept: raise the limit and run again with --retry-failed to continue from it";
    }
    CaseResult r;
    r.case_id = c.case_id;
    r.session_id = report_.session_id;
    r.started_at = started_at;
    r.finished_at = utc_now_iso8601();
    r.wall_s = ctx.whole_wall_s();
    r.threads = threads;
    r.peak_rss_bytes = peak_rss_bytes();
    if (failure.empty()) {
      r.status = "done";
      r.stop_reason = outcome.stop_reason;
      r.steps = outcome.steps;
      r.particle_steps = outcome.particle_steps;
      r.sim_time_s = outcome.sim_time_s;
      r.run_json = outcome.run_json;
      r.run_json["peak_rss_exact"] = exact_peak_rss_;
      r.result_json = deterministic_result(outcome);
      r.measurement = std::move(outcome.measurement);
    } else {
      r.status = "failed";
      r.failure_reason = failure;
      r.result_json = {{"status", "failed"}};
      if (opt_.fail_fast) stop().store(true);
    }
    queue_.push(Event{Event::Kind::finished, slot, std::move(r), started_at, {}});
  }

  // The writer loop: stores what the workers hand over and reports progress, until the workers
  // are done. Returns the first error of the store (the run then stops).
  std::exception_ptr write_events(int jobs) {
    std::exception_ptr writer_error;
    EtaEstimator eta(jobs);
    const auto update_progress = [&] {
      progress_.running = eta.running();
      progress_.elapsed_s = seconds_since(t0_);
      progress_.running_cases.clear();
      eta.observe_running(
          [&](std::size_t slot) {
            // In this order: a case says where it resumed from before it reports any fraction.
            const double fraction = progress_of_[slot].fraction.load();
            progress_.running_cases.emplace_back(todo_[slot]->index, fraction);
            return std::pair{fraction, progress_of_[slot].resumed_from.load()};
          },
          progress_.elapsed_s);
      std::sort(progress_.running_cases.begin(), progress_.running_cases.end());
      progress_.eta_s = eta.eta(progress_.pending, progress_.elapsed_s);
    };
    bool closed = false;
    while (!closed) {
      auto [events, is_closed] = queue_.take(std::chrono::milliseconds(1000));
      closed = is_closed;
      for (Event& e : events) {
        if (writer_error) break;
        try {
          const StudyCase& c = *todo_[e.slot];
          switch (e.kind) {
            case Event::Kind::started:
              store_.mark_running(c.case_id, report_.session_id, e.started_at, report_.threads_per_case);
              eta.started(e.slot, seconds_since(t0_));
              --progress_.pending;
              break;
            case Event::Kind::warning:
              if (opt_.warn) opt_.warn(c.label + ": " + e.message);
              break;
            case Event::Kind::cancelled:
              store_.mark_pending(c.case_id);
              eta.stopped(e.slot);
              ++progress_.pending;
              ++report_.cancelled;
              break;
            case Event::Kind::finished:
              store_.record_result(e.result);
              ++report_.ran;
              if (e.result.status == "done") {
                ++report_.done;
                ++progress_.done;
                eta.finished(e.slot, e.result.wall_s);
              } else {
                eta.stopped(e.slot);
                ++report_.failed;
                ++progress_.failed;
                if (report_.first_failure.empty()) report_.first_failure = c.label + ": " + e.result.failure_reason;
              }
              update_progress();
              if (opt_.observer) opt_.observer->on_case_finished(c, e.result, progress_);
              break;
          }
        } catch (...) {
          writer_error = std::current_exception();
          stop().store(true);
        }
      }
      update_progress();
      if (opt_.observer && !writer_error) opt_.observer->on_progress(progress_);
    }
    return writer_error;
  }

  RunnerReport finish() {
    report_.stopped = opt_.fail_fast && report_.failed > 0;
    report_.interrupted_by_request = opt_.interrupt && opt_.interrupt->load() && !report_.stopped;
    report_.wall_s = seconds_since(t0_);
    const std::string outcome = report_.stopped || report_.interrupted_by_request ? "stopped"
                                : report_.failed + report_.already_failed > 0    ? "failures"
                                                                                 : "complete";
    store_.end_session(report_.session_id, outcome, static_cast<std::int64_t>(report_.ran));
    store_.checkpoint();
    if (opt_.observer) opt_.observer->on_end(report_);
    return report_;
  }

  const Study& study_;
  const RunnerOptions& opt_;
  const clock_type::time_point t0_;
  Store store_;
  RunnerReport report_;
  RunnerProgress progress_;
  double time_limit_ = 0.0;
  CaseFunction case_function_;
  std::vector<const StudyCase*> todo_;
  bool exact_peak_rss_ = false;
  std::vector<CaseProgress> progress_of_;  // per case to run, written by its worker
  std::atomic<bool> own_stop_{false};
  std::atomic<std::size_t> next_{0};
  EventQueue queue_;
};

}  // namespace

std::vector<const StudyCase*> cases_to_run(const std::vector<const StudyCase*>& scope,
                                           const std::map<std::string, std::string>& status,
                                           const std::vector<std::size_t>& only_cases, bool retry_failed) {
  std::vector<const StudyCase*> out;
  for (const StudyCase* c : scope) {
    if (!only_cases.empty() && !std::binary_search(only_cases.begin(), only_cases.end(), c->index)) continue;
    const auto it = status.find(c->case_id);
    const bool stored_done = it != status.end() && it->second == "done";
    const bool stored_failed = it != status.end() && it->second == "failed";
    if (!stored_done && !(stored_failed && !retry_failed)) out.push_back(c);
  }
  return out;
}

RunnerReport run_study(const Study& study, const RunnerOptions& opt) {
  // Before the database is opened: a file where the checkpoint folder belongs would otherwise
  // turn checkpointing off without a word, or be found only after hours of simulation.
  if (study.resources.checkpoint_interval_s > 0) {
    const std::filesystem::path dir = checkpoint_dir(opt.db_path);
    std::error_code ec;
    const auto st = std::filesystem::status(dir, ec);
    if (std::filesystem::exists(st) && !std::filesystem::is_directory(st))
      throw InputError("resources.checkpoint_interval_s: " + dir.string() +
                       " must be a folder for the checkpoints but is a file; remove or rename it, "
                       "or set checkpoint_interval_s to 0");
  }
  return StudyRun(study, opt).run();
}

}  // namespace crevasse
