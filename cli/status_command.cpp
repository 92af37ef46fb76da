#include "cli/status_command.hpp"

#include <cstdio>
#include <filesystem>
#include <string>

#include "cli/progress_printer.hpp"
#include "engine/error.hpp"
#include "study/store.hpp"
#include "study/study_compute.hpp"

namespace crevasse {
namespace {

constexpr long long kDefaultCaseRows = 60;

std::string cell_value(double v, const char* format) {
  char buf[64];
  std::snprintf(buf, sizeof buf, format, v);
  return buf;
}

std::string cell(const Statement& s, int c, const char* format) {
  return s.is_null(c) ? "-" : cell_value(s.real(c), format);
}

void print_compute_row(const std::string& name, const ComputeRow& r, bool total) {
  std::printf("| %s | %s | %lld | %lld | %lld | %.1f | %.2f | %s |\n", name.c_str(),
              total ? "" : std::to_string(static_cast<long long>(r.thickness_m)).c_str(), r.run,
              r.served, r.pending, r.particle_steps / 1e9, r.wall_s / 3600.0,
              r.median_rate > 0 ? cell_value(r.median_rate / 1e6, "%.1f").c_str() : "-");
}

int compute_table(const std::vector<std::string>& paths) {
  std::printf(
      "| database | H_i [m] | cases run | served by another case's run | not finished | "
      "particle-steps [1e9] | case wall time [h] | M particle-steps/s per case (median) |\n"
      "|---|---|---|---|---|---|---|---|\n");
  std::vector<ComputeRow> all;
  for (const std::string& path : paths) {
    Store store = Store::open_reader(path);
    const std::string name = std::filesystem::path(path).filename().string();
    for (const ComputeRow& r : study_compute(store)) {
      print_compute_row(name, r, false);
      all.push_back(r);
    }
  }
  if (paths.size() > 1) print_compute_row("all", compute_total(all), true);
  return 0;
}

}  // namespace

int status_command(const StatusCommandOptions& opt) {
  if (opt.compute_table) return compute_table(opt.db_paths);
  if (opt.db_paths.size() != 1)
    throw InputError("status: give one database (several only with --compute)");
  const std::string& db_path = opt.db_paths.front();
  Store store = Store::open_reader(db_path);
  sqlite3* db = store.handle();
  {
    Statement s(db,
                "SELECT name, case_count, engine_version, host, started_at, coalesce(ended_at, "
                "'-'), description "
                "FROM study WHERE id = 1");
    if (!s.step()) {
      std::printf("%s: no study recorded yet\n", db_path.c_str());
      return 0;
    }
    std::printf("study %s: %lld cases, engine %s, database %s\n", s.text(0).c_str(),
                static_cast<long long>(s.integer(1)), s.text(2).c_str(), db_path.c_str());
    if (!s.text(6).empty()) std::printf("  %s\n", s.text(6).c_str());
    std::printf("  created %s on %s, last session ended %s\n", s.text(4).c_str(), s.text(3).c_str(),
                s.text(5).c_str());
  }
  const StatusCounts c = store.counts();
  {
    const std::vector<ComputeRow> rows = study_compute(store);
    const ComputeRow t = compute_total(rows);
    std::printf(
        "  in this database: %lld done, %lld failed, %lld running, %lld pending (of %lld)\n"
        "  compute: %lld cases run, %s of case wall time, %.3g particle-steps",
        static_cast<long long>(c.done), static_cast<long long>(c.failed),
        static_cast<long long>(c.running), static_cast<long long>(c.pending),
        static_cast<long long>(c.total()), t.run, format_duration(t.wall_s).c_str(),
        t.particle_steps);
    if (t.served > 0)
      std::printf("; %lld served by another case's run (counted where it ran)", t.served);
    std::printf("\n");
    if (rows.size() > 1)
      for (const ComputeRow& r : rows)
        std::printf("    H_i = %.0f m: %lld run, %lld served, %s, %.3g particle-steps\n",
                    r.thickness_m, r.run, r.served, format_duration(r.wall_s).c_str(),
                    r.particle_steps);
  }
  {
    Statement s(db, "SELECT count(*), coalesce(sum(outcome IS NULL), 0) FROM sessions");
    s.step();
    Statement last(
        db,
        "SELECT session_id, jobs, threads_per_case, shard, coalesce(outcome, 'running or killed') "
        "FROM sessions ORDER BY started_at DESC LIMIT 1");
    if (last.step())
      std::printf("  sessions: %lld (last %s: %lld jobs x %lld threads%s%s, %s)\n",
                  static_cast<long long>(s.integer(0)), last.text(0).c_str(),
                  static_cast<long long>(last.integer(1)), static_cast<long long>(last.integer(2)),
                  last.text(3).empty() ? "" : ", shard ", last.text(3).c_str(),
                  last.text(4).c_str());
  }
  if (c.running > 0) {
    std::printf("running (or interrupted; a resume reruns them):\n");
    Statement s(db,
                "SELECT label, started_at, session_id FROM cases WHERE status = 'running' ORDER BY "
                "case_index");
    while (s.step())
      std::printf("  %s  since %s  (%s)\n", s.text(0).c_str(), s.text(1).c_str(),
                  s.text(2).c_str());
  }
  if (c.failed > 0) {
    std::printf("failed:\n");
    Statement s(
        db, "SELECT label, failure_reason FROM cases WHERE status = 'failed' ORDER BY case_index");
    while (s.step()) std::printf("  %s: %s\n", s.text(0).c_str(), s.text(1).c_str());
  }
  if (c.done > 0) {
    const long long limit = opt.all_cases ? -1 : kDefaultCaseRows;
    // deep = the damaged share of the window's ice more than H_i/2 below its surface
    // (docs/measurement.md): shattering under an intact surface shows there. >H/2 = the share of
    // the crevasses deeper than H_i/2.
    std::printf("done:\n  %5s  %-10s %8s %8s %8s %7s  %5s %9s %9s %5s %5s %8s  %s\n", "index", "case",
                "H_i[m]", "Pi", "r=Ls/Hi", "S", "crev", "Lp/Hi", "Dp/Hi", ">H/2", "deep", "wall", "label");
    Statement s(
        db,
        "WITH c AS (SELECT *, json_extract(run_json, '$.measured_from') IS NOT NULL AS remeasured "
        "FROM cases WHERE status = 'done') "
        "SELECT c.case_index, substr(c.case_id, 1, 10), c.thickness_m, c.cohesion_ratio, "
        "c.step_length_ratio, "
        "c.slope, m.crevasse_count, m.spacing_median_over_h, m.depth_median_over_h, "
        // A case measured again from kept particles shows the wall time of the run that made them.
        "CASE WHEN c.remeasured THEN json_extract(c.run_json, '$.engine_wall_s') ELSE c.wall_s END, "
        "c.label, "
        "m.fragmented, " +
            store.under_resolved_column() +
            ", 100.0 * json_extract(c.result_json, '$.measurement.damage.deep_damaged_fraction'), "
            "c.remeasured, "
            "(SELECT 100.0 * avg(d.value > c.thickness_m / 2) "
            "FROM json_each(c.result_json, '$.measurement.depths_m') d) "
            "FROM c LEFT JOIN summaries m USING (case_id) ORDER BY c.case_index LIMIT ?");
    s.bind(1, static_cast<std::int64_t>(limit));
    while (s.step()) {
      std::printf("  %5lld  %-10s %8s %8s %8s %7s  %5lld %9s %9s %5s %5s %8s  %s%s%s%s\n",
                  static_cast<long long>(s.integer(0)), s.text(1).c_str(),
                  cell(s, 2, "%.0f").c_str(), cell(s, 3, "%.4g").c_str(),
                  cell(s, 4, "%.3g").c_str(), cell(s, 5, "%.3g").c_str(),
                  static_cast<long long>(s.integer(6)), cell(s, 7, "%.3f").c_str(),
                  cell(s, 8, "%.3f").c_str(), cell(s, 15, "%.0f%%").c_str(), cell(s, 13, "%.0f%%").c_str(),
                  format_wall_time(s.real(9)).c_str(),
                  s.text(10).c_str(),
                  s.integer(11) ? "  (fragmented)" : "",
                  s.integer(12) ? "  (under-resolved: c/(rho_i g) < 3 dx)" : "",
                  s.integer(14) ? "  (measured again from kept particles; wall: the run's)" : "");
    }
    if (limit >= 0 && c.done > limit)
      std::printf("  ... %lld more (crevasse status --all, or crevasse export --csv)\n",
                  static_cast<long long>(c.done - limit));
  }
  return 0;
}

}  // namespace crevasse
