#include "study/runner.hpp"

#include <tbb/global_control.h>
#include <tbb/task_arena.h>
#include <unistd.h>

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

namespace crevasse {
namespace {

using clock_type = std::chrono::steady_clock;

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
  enum class Kind { started, finished, cancelled } kind;
  std::size_t slot = 0;  // index into the list of cases to run
  CaseResult result;     // finished only
  std::string started_at;
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

RunnerReport run_study(const Study& study, const RunnerOptions& opt) {
  const auto t0 = clock_type::now();
  RunnerReport report;
  report.threads_per_case = opt.threads_per_case > 0 ? opt.threads_per_case
                            : study.resources.threads_per_case > 0
                                ? study.resources.threads_per_case
                                : kDefaultThreadsPerCase;
  report.jobs = opt.jobs > 0               ? opt.jobs
                : study.resources.jobs > 0 ? study.resources.jobs
                                           : default_jobs(report.threads_per_case);
  const double time_limit = opt.case_time_limit_s.value_or(study.resources.case_time_limit_s);
  const CaseFunction case_function =
      opt.case_function ? opt.case_function : CaseFunction(run_engine_case);

  // Everything that can refuse the run does so before a case starts.
  Store store = Store::open_writer(opt.db_path);
  store.init_study(study);
  const std::vector<const StudyCase*> scope =
      opt.shard ? shard_cases(study, *opt.shard) : shard_cases(study, Shard{0, 1});
  report.in_scope = scope.size();
  store.add_cases(scope);
  report.interrupted = static_cast<std::size_t>(store.reset_running());

  SessionInfo session;
  session.host = host_name();
  session.pid = static_cast<std::int64_t>(::getpid());
  session.started_at = utc_now_iso8601();
  session.session_id = session.host + ":" + std::to_string(session.pid) + ":" +
                       std::to_string(std::chrono::duration_cast<std::chrono::milliseconds>(
                                          std::chrono::system_clock::now().time_since_epoch())
                                          .count());
  session.jobs = report.jobs;
  session.threads_per_case = report.threads_per_case;
  session.shard = opt.shard ? opt.shard->text() : "";
  session.command = opt.command;
  store.begin_session(session);
  report.session_id = session.session_id;

  const auto status = store.statuses();
  std::vector<const StudyCase*> todo;
  for (const StudyCase* c : scope) {
    const std::string& s = status.at(c->case_id);
    if (s == "done")
      ++report.already_done;
    else if (s == "failed" && !opt.retry_failed)
      ++report.already_failed;
    else
      todo.push_back(c);
  }

  RunnerProgress progress;
  progress.total = scope.size();
  progress.done = report.already_done;
  progress.failed = report.already_failed;
  progress.pending = todo.size();
  if (opt.observer) opt.observer->on_start(report, progress);

  // Workers: `jobs` loops in one arena, each taking the next case; each case runs in its own
  // arena so that the engine's parallel loops use exactly threads_per_case threads.
  const int jobs = std::max(
      1, std::min<int>(report.jobs, static_cast<int>(std::max<std::size_t>(todo.size(), 1))));
  tbb::global_control parallelism(
      tbb::global_control::max_allowed_parallelism,
      static_cast<std::size_t>(std::max(1, jobs * report.threads_per_case)));
  std::atomic<bool> own_stop{false};
  std::atomic<bool>& stop = opt.interrupt ? *opt.interrupt : own_stop;
  std::atomic<std::size_t> next{0};
  std::vector<std::atomic<double>> fraction(todo.size());
  for (auto& f : fraction) f.store(0.0);
  EventQueue queue;
  const bool exact_peak_rss = jobs == 1;
  const std::string session_id = session.session_id;
  const int threads = report.threads_per_case;

  auto work = [&] {
    while (!stop.load()) {
      const std::size_t slot = next.fetch_add(1);
      if (slot >= todo.size()) return;
      const StudyCase& c = *todo[slot];
      Event started{Event::Kind::started, slot, {}, utc_now_iso8601()};
      const std::string started_at = started.started_at;
      queue.push(std::move(started));
      if (exact_peak_rss) reset_peak_rss();
      CaseContext ctx(threads, time_limit, study.measurement, stop, fraction[slot]);
      if (!opt.views_dir.empty()) ctx.set_views_dir(opt.views_dir);
      std::filesystem::path checkpoint;
      if (study.resources.checkpoint_interval_s > 0) {
        // Next to the database: DB.checkpoints/CASE.ckpt (kept only while the case is unfinished).
        const std::filesystem::path dir = opt.db_path.string() + ".checkpoints";
        std::error_code ec;
        std::filesystem::create_directories(dir, ec);
        if (!ec) {
          checkpoint = dir / (c.case_id + ".ckpt");
          ctx.set_checkpoint(checkpoint, study.resources.checkpoint_interval_s);
        }
      }
      CaseOutcome outcome;
      std::string failure;
      try {
        tbb::task_arena arena(threads);
        arena.execute([&] { outcome = case_function(c, ctx); });
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
      if (failure.empty() && outcome.cancelled) {
        if (!ctx.time_limit_exceeded()) {
          queue.push(Event{Event::Kind::cancelled, slot, {}, started_at});
          continue;
        }
        failure = "time limit: the case ran longer than the case time limit of " +
                  std::to_string(time_limit) + " s";
      }
      if (!checkpoint.empty()) {  // finished or failed for good: nothing to continue from
        std::error_code ec;
        std::filesystem::remove(checkpoint, ec);
      }
      CaseResult r;
      r.case_id = c.case_id;
      r.session_id = session_id;
      r.started_at = started_at;
      r.finished_at = utc_now_iso8601();
      r.wall_s = ctx.elapsed_s();
      r.threads = threads;
      r.peak_rss_bytes = peak_rss_bytes();
      if (failure.empty()) {
        r.status = "done";
        r.stop_reason = outcome.stop_reason;
        r.steps = outcome.steps;
        r.particle_steps = outcome.particle_steps;
        r.sim_time_s = outcome.sim_time_s;
        r.run_json = outcome.run_json;
        r.run_json["peak_rss_exact"] = exact_peak_rss;
        r.result_json = deterministic_result(outcome);
        r.measurement = std::move(outcome.measurement);
      } else {
        r.status = "failed";
        r.failure_reason = failure;
        r.result_json = {{"status", "failed"}};
        if (opt.fail_fast) stop.store(true);
      }
      queue.push(Event{Event::Kind::finished, slot, std::move(r), started_at});
    }
  };

  // One plain thread per job: a job blocks on its case for minutes, which is no work for TBB's
  // scheduler, and thread start/join is a hand-over ThreadSanitizer can see (TBB's own queues,
  // in an uninstrumented libtbb, are not). Each case still runs in its own task arena.
  std::exception_ptr worker_error;
  std::mutex worker_error_mutex;
  std::thread executor([&] {
    std::vector<std::thread> workers;
    for (int j = 0; j < jobs; ++j)
      workers.emplace_back([&] {
        try {
          work();
        } catch (...) {
          const std::lock_guard<std::mutex> lock(worker_error_mutex);
          if (!worker_error) worker_error = std::current_exception();
          stop.store(true);
        }
      });
    for (auto& w : workers) w.join();
    queue.close();
  });

  // The writer: this thread alone touches the database.
  std::exception_ptr writer_error;
  std::map<std::size_t, clock_type::time_point> running;
  std::vector<double> finished_walls;
  auto eta = [&]() -> std::optional<double> {
    double per_case = 0.0;
    if (!finished_walls.empty()) {
      for (double w : finished_walls) per_case += w;
      per_case /= static_cast<double>(finished_walls.size());
    } else {
      int n = 0;
      for (const auto& [slot, start] : running) {
        const double f = fraction[slot].load();
        if (f > 0.02) {
          per_case += seconds_since(start) / f;
          ++n;
        }
      }
      if (n == 0) return std::nullopt;
      per_case /= n;
    }
    double remaining = static_cast<double>(progress.pending) * per_case;
    for (const auto& [slot, start] : running) {
      const double f = fraction[slot].load();
      const double total = f > 0.02 ? seconds_since(start) / f : per_case;
      remaining += std::max(0.0, total - seconds_since(start));
    }
    return remaining / jobs;
  };
  bool closed = false;
  while (!closed) {
    auto [events, is_closed] = queue.take(std::chrono::milliseconds(1000));
    closed = is_closed;
    for (Event& e : events) {
      if (writer_error) break;
      try {
        const StudyCase& c = *todo[e.slot];
        switch (e.kind) {
          case Event::Kind::started:
            store.mark_running(c.case_id, session_id, e.started_at, threads);
            running[e.slot] = clock_type::now();
            --progress.pending;
            break;
          case Event::Kind::cancelled:
            store.mark_pending(c.case_id);
            running.erase(e.slot);
            ++progress.pending;
            ++report.cancelled;
            break;
          case Event::Kind::finished:
            store.record_result(e.result);
            running.erase(e.slot);
            ++report.ran;
            if (e.result.status == "done") {
              ++report.done;
              ++progress.done;
              finished_walls.push_back(e.result.wall_s);
            } else {
              ++report.failed;
              ++progress.failed;
              if (report.first_failure.empty())
                report.first_failure = c.label + ": " + e.result.failure_reason;
            }
            progress.running = running.size();
            progress.elapsed_s = seconds_since(t0);
            progress.eta_s = eta();
            if (opt.observer) opt.observer->on_case_finished(c, e.result, progress);
            break;
        }
      } catch (...) {
        writer_error = std::current_exception();
        stop.store(true);
      }
    }
    progress.running = running.size();
    progress.elapsed_s = seconds_since(t0);
    progress.eta_s = eta();
    if (opt.observer && !writer_error) opt.observer->on_progress(progress);
  }
  executor.join();
  if (writer_error) std::rethrow_exception(writer_error);
  if (worker_error) std::rethrow_exception(worker_error);

  report.stopped = opt.fail_fast && report.failed > 0;
  report.interrupted_by_request = opt.interrupt && opt.interrupt->load() && !report.stopped &&
                                  !writer_error && !worker_error;
  report.wall_s = seconds_since(t0);
  const std::string outcome = report.stopped || report.interrupted_by_request ? "stopped"
                              : report.failed + report.already_failed > 0 ? "failures"
                                                                          : "complete";
  store.end_session(session_id, outcome, static_cast<std::int64_t>(report.ran));
  store.checkpoint();
  if (opt.observer) opt.observer->on_end(report);
  return report;
}

}  // namespace crevasse
