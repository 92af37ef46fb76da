#include "cli/study_command.hpp"

#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <csignal>
#include <filesystem>
#include <map>
#include <memory>
#include <optional>
#include <cstdio>
#include <string>
#include <thread>

#include "cli/cli_common.hpp"
#include "cli/progress_printer.hpp"
#include "engine/error.hpp"
#include "study/engine_case.hpp"
#include "study/kept_runs.hpp"
#include "study/runner.hpp"
#include "study/shard.hpp"
#include "study/store.hpp"
#include "study/study_file.hpp"

namespace crevasse {
namespace {

// Ctrl-C (SIGINT), SIGTERM and SIGHUP end a study cleanly: the handler only raises a flag, the
// running cases save their checkpoint and stay pending, the session is closed as "stopped", and
// the process exits with 128 + the signal number. A second signal of the same kind kills at once
// (the handler gives the default action back).
std::atomic<bool> g_interrupt{false};
volatile std::sig_atomic_t g_signal = 0;

extern "C" void on_interrupt_signal(int sig) {
  g_signal = sig;
  g_interrupt.store(true);
  std::signal(sig, SIG_DFL);
}

struct InterruptHandlers {
  InterruptHandlers() {
    g_interrupt.store(false);
    g_signal = 0;
    for (int sig : {SIGINT, SIGTERM, SIGHUP}) std::signal(sig, on_interrupt_signal);
  }
  ~InterruptHandlers() {
    for (int sig : {SIGINT, SIGTERM, SIGHUP}) std::signal(sig, SIG_DFL);
  }
};

class ConsoleObserver : public StudyObserver {
 public:
  ConsoleObserver(std::string name, std::string db) : name_(std::move(name)), db_(std::move(db)) {}

  void on_start(const RunnerReport& plan, const RunnerProgress& p) override {
    printer_.finish();
    std::fprintf(stderr, "study %s: %zu case(s)", name_.c_str(), plan.in_scope);
    if (plan.already_done + plan.already_failed > 0)
      std::fprintf(stderr, " (%zu stored as done, %zu as failed)", plan.already_done,
                   plan.already_failed);
    if (plan.interrupted > 0)
      std::fprintf(stderr, ", %zu interrupted by a killed run", plan.interrupted);
    std::fprintf(stderr, "; running %zu on %d job(s) x %d engine thread(s) -> %s\n", p.pending,
                 plan.jobs, plan.threads_per_case, db_.c_str());
  }

  void on_case_finished(const StudyCase& c, const CaseResult& r, const RunnerProgress& p) override {
    printer_.finish();
    const std::size_t finished = p.done + p.failed;
    if (r.status == "done" && r.measurement) {
      const auto& m = *r.measurement;
      char stats[160] = "no crevasse";
      if (!m.crevasses.empty())
        std::snprintf(
            stats, sizeof stats, "%zu crevasse(s), median spacing %s H_i, median depth %s H_i",
            m.crevasses.size(),
            m.spacing_over_h ? format_number(m.spacing_over_h->median).c_str() : "-",
            m.depth_over_h ? format_number(m.depth_over_h->median).c_str() : "-");
      const SceneConfig& sc = c.scene;
      const bool under =
          analysis::strength_under_resolved(sc.tensile_strength, sc.density, sc.gravity, sc.dx);
      std::fprintf(stderr, "[%zu/%zu] done   %s: %s%s%s (%s)\n", finished, p.total,
                   c.label.c_str(), stats, m.flags.fragmented ? ", fragmented" : "",
                   under ? ", under-resolved" : "", format_wall_time(r.wall_s).c_str());
    } else if (r.status == "done") {
      std::fprintf(stderr, "[%zu/%zu] done   %s (%s)\n", finished, p.total, c.label.c_str(),
                   format_wall_time(r.wall_s).c_str());
    } else {
      std::fprintf(stderr, "[%zu/%zu] FAILED %s: %s\n", finished, p.total, c.label.c_str(),
                   r.failure_reason.c_str());
    }
  }

  void on_progress(const RunnerProgress& p) override {
    char line[384];
    std::snprintf(line, sizeof line,
                  "%s: done %zu/%zu  failed %zu  running %zu%s  pending %zu  elapsed %s  ETA %s",
                  name_.c_str(), p.done, p.total, p.failed, p.running,
                  format_running_cases(p.running_cases).c_str(), p.pending,
                  format_duration(p.elapsed_s).c_str(),
                  p.eta_s ? format_duration(*p.eta_s).c_str() : "?");
    if (!printer_is_tty_throttled(p)) printer_.update(line);
  }

  void warn(const std::string& message) {
    printer_.finish();
    std::fprintf(stderr, "crevasse: warning: %s\n", message.c_str());
  }

  void on_end(const RunnerReport& r) override {
    printer_.finish();
    std::fprintf(
        stderr,
        "study %s: ran %zu case(s) in %s: %zu done, %zu failed%s; see: crevasse status %s\n",
        name_.c_str(), r.ran, format_duration(r.wall_s).c_str(), r.done, r.failed,
        r.stopped ? " (stopped by --fail-fast)" : "", db_.c_str());
  }

 private:
  // Off a terminal one line every 10 s is enough for a log.
  bool printer_is_tty_throttled(const RunnerProgress& p) {
    if (p.elapsed_s - last_line_s_ < (tty_ ? 0.9 : 10.0)) return true;
    last_line_s_ = p.elapsed_s;
    return false;
  }
  std::string name_, db_;
  ProgressPrinter printer_;
  bool tty_ = isatty(fileno(stderr)) != 0;
  double last_line_s_ = -1e9;
};

// True when the database at `db` holds every selected case as done (or failed, without
// --retry-failed): the runner would start none, so a re-measurement reads no kept particles and
// they need not be there (a clone holds the databases, not the particle files).
bool nothing_left_to_run(const Study& study, const std::string& db, const std::optional<Shard>& shard,
                         const std::vector<std::size_t>& only, bool retry_failed) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(db, ec)) return false;
  std::map<std::string, std::string> status;
  try {
    status = Store::open_reader(db).statuses();
  } catch (const std::exception&) {
    return false;  // the runner says what is wrong with it
  }
  return cases_to_run(shard_cases(study, shard.value_or(Shard{0, 1})), status, only, retry_failed).empty();
}

}  // namespace

int study_command(const StudyCommandOptions& opt) {
  const Study study = load_study_file(opt.study_path);
  std::optional<Shard> shard;
  if (!opt.shard.empty()) shard = parse_shard(opt.shard);

  if (opt.dry_run) {
    const auto cases = shard ? shard_cases(study, *shard) : shard_cases(study, Shard{0, 1});
    std::printf(
        "study %s: %zu case(s)%s, study hash %s\n", study.name.c_str(), cases.size(),
        shard ? (" in shard " + shard->text() + " of " + std::to_string(study.cases.size())).c_str()
              : "",
        study.study_hash.substr(0, 16).c_str());
    std::printf("%5s  %-16s %8s %8s %8s %8s %6s  %s\n", "index", "case", "H_i[m]", "Pi", "c[kPa]",
                "L_s[m]", "dx[m]", "label");
    for (const StudyCase* c : cases)
      std::printf("%5zu  %-16s %8.0f %8.4g %8.4g %8.4g %6.3g  %s\n", c->index,
                  c->case_id.substr(0, 16).c_str(), c->groups.thickness_m, c->groups.cohesion_ratio,
                  c->scene.tensile_strength / 1e3, c->scene.step_length, c->scene.dx,
                  c->label.c_str());
    return 0;
  }

  if (opt.remeasure_db.empty() != opt.particles_from.empty())
    throw InputError(opt.remeasure_db.empty() ? "--particles-from: give the kept study's database with --remeasure DB too"
                                              : "--remeasure: give the folder of its kept particles with --particles-from DIR too");
  std::string db = opt.db_path;
  if (db.empty()) {
    db = "results/" + study.name;
    if (shard)
      db += ".shard-" + std::to_string(shard->index) + "-of-" + std::to_string(shard->count);
    db += ".db";
  }
  // What the study reads, which none of its outputs may be, however spelt.
  std::vector<NamedPath> inputs = {{"the study file", opt.study_path}};
  std::shared_ptr<const KeptRuns> kept;
  const std::vector<std::size_t> only_cases =
      opt.cases.empty() ? std::vector<std::size_t>() : parse_case_list(opt.cases, study.cases.size());
  if (!opt.remeasure_db.empty() && !nothing_left_to_run(study, db, shard, only_cases, opt.retry_failed)) {
    kept = std::make_shared<const KeptRuns>(opt.remeasure_db, opt.particles_from);
    inputs.push_back({"--remeasure", opt.remeasure_db});
    inputs.push_back({"--particles-from", opt.particles_from});
    for (const auto& f : kept->files()) inputs.push_back({"a file of --particles-from", f});
  }
  for (const char* suffix : {"", "-wal", "-shm"}) check_output_is_not_input("--db", db + suffix, inputs);
  // Each folder of files named by case, checked as a whole and file by file.
  const auto check_case_files = [&](const std::string& option, const std::filesystem::path& dir,
                                    const std::vector<std::string>& tails) {
    std::vector<std::string> names;
    for (const StudyCase& c : study.cases) {
      const std::string stem = case_file_stem(c.index);
      for (const std::string& tail : tails) names.push_back(stem + tail);
    }
    check_output_directory(option, dir, names);
    check_output_is_not_input(option, dir, inputs);
    for (const std::string& name : names) check_output_is_not_input(option, dir / name, inputs);
  };
  if (!opt.views_dir.empty()) check_case_files("--views", opt.views_dir, {"side_view.png", "gate_view.png"});
  const bool keep_particles = opt.keep_particles || !opt.particles_dir.empty();
  const std::filesystem::path particles_dir =
      !keep_particles ? std::filesystem::path() : std::filesystem::path(opt.particles_dir.empty() ? db + ".particles" : opt.particles_dir);
  if (keep_particles)
    check_case_files(opt.particles_dir.empty() ? "--keep-particles" : "--particles-dir", particles_dir,
                     {"particles.bin"});
  const unsigned cores = std::max(1u, std::thread::hardware_concurrency());
  const int threads_asked =
      opt.threads_per_case > 0 ? opt.threads_per_case : study.resources.threads_per_case;
  if (threads_asked > static_cast<int>(cores))
    std::fprintf(stderr,
                 "crevasse: warning: %d engine threads per case on %u core(s): the threads share "
                 "the cores, so each case runs no faster and usually slower\n",
                 threads_asked, cores);
  ConsoleObserver console(study.name, db);
  RunnerOptions ro;
  ro.db_path = db;
  ro.jobs = opt.jobs;
  ro.threads_per_case = opt.threads_per_case;
  if (opt.case_time_limit_s >= 0) ro.case_time_limit_s = opt.case_time_limit_s;
  ro.fail_fast = opt.fail_fast;
  ro.retry_failed = opt.retry_failed;
  ro.shard = shard;
  ro.only_cases = only_cases;
  ro.command = opt.command_line;
  ro.views_dir = opt.views_dir;
  ro.particles_dir = particles_dir;
  if (kept) {
    for (const std::string& w : kept->warnings(study)) console.warn(w);
    ro.case_function = [kept](const StudyCase& c, CaseContext& ctx) { return (*kept)(c, ctx); };
  }
  ro.observer = opt.quiet ? nullptr : &console;
  // Shown even with --quiet: a warning says that work may have to be redone.
  ro.warn = [&console](const std::string& m) { console.warn(m); };
  const InterruptHandlers handlers;
  ro.interrupt = &g_interrupt;
  const RunnerReport r = run_study(study, ro);
  const std::size_t failed = r.failed + r.already_failed;
  if (r.interrupted_by_request) {
    const int sig = g_signal;
    std::fprintf(stderr,
                 "crevasse: interrupted by signal %d; the running cases saved a checkpoint and "
                 "continue from it when you run the same command again\n",
                 sig);
    return 128 + sig;
  }
  if (r.stopped) {
    std::fprintf(stderr, "crevasse: stopped at the first failure (--fail-fast): %s\n",
                 r.first_failure.c_str());
    return 1;
  }
  if (failed > 0) {
    std::fprintf(stderr, "crevasse: %zu of %zu case(s) failed; see crevasse status %s\n", failed,
                 r.in_scope, db.c_str());
    return 1;
  }
  return 0;
}

}  // namespace crevasse
