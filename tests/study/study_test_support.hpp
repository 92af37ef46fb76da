#pragma once
// Shared by the study tests: scratch directories, tiny real scenes, deterministic fake cases,
// and database dumps for comparing two runs.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <thread>

#include "study/runner.hpp"
#include "study/store.hpp"
#include "study/study_file.hpp"

extern char** environ;

namespace crevasse::test {

// Built with AddressSanitizer or ThreadSanitizer, whose shadow memory does not fit under an
// address-space limit (ulimit -v).
#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
inline constexpr bool kSanitized = true;
#else
inline constexpr bool kSanitized = false;
#endif

// A fresh directory under the system temp dir, removed at the end of the test.
class ScratchDir {
 public:
  explicit ScratchDir(const std::string& tag) {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    path_ = std::filesystem::temp_directory_path() /
            ("crevasse_" + tag + "_" + (info ? std::string(info->name()) : "x") + "_" +
             std::to_string(::getpid()));
    std::filesystem::remove_all(path_);
    std::filesystem::create_directories(path_);
  }
  ~ScratchDir() {
    std::error_code ec;
    std::filesystem::remove_all(path_, ec);
  }
  const std::filesystem::path& path() const { return path_; }
  std::filesystem::path operator/(const std::string& name) const { return path_ / name; }

 private:
  std::filesystem::path path_;
};

inline void write_text(const std::filesystem::path& p, const std::string& text) {
  std::ofstream(p) << text;
}

// A small real glacier: H_i = 40 m at dx = 10 m, about 1,300 particles; a few hundred steps
// take a fraction of a second on one thread.
inline nlohmann::json tiny_scene(std::int64_t max_steps = 200) {
  return {{"name", "tiny"},
          {"dim", 2},
          {"effects", {"gravity", "drive", "basal_friction", "plasticity", "softening", "outflow"}},
          {"ice", {{"thickness", 40.0}}},
          {"bed", {{"shape", "step"}, {"step_height", 40.0}, {"step_length", 40.0}}},
          {"numerics", {{"dx", 10.0}}},
          {"run", {{"max_steps", max_steps}}},
          {"output", {{"vtu_interval", 0.0}, {"png", false}}}};
}

// A study over cohesion_ratio with `n` values on the tiny scene.
inline nlohmann::json tiny_study(int n, std::int64_t max_steps = 200,
                                 const std::string& name = "tiny") {
  return {{"name", name},
          {"base_scene", tiny_scene(max_steps)},
          {"fixed", {{"step_length_ratio", 1.0}, {"slope", 1.0}}},
          {"sweep", {{"cohesion_ratio", {{"log", {0.05, 1.0, n}}}}}},
          {"resources", {{"threads_per_case", 1}}}};
}

inline Study parse(const nlohmann::json& j) {
  return parse_study(j.dump(), std::filesystem::current_path(), "test");
}

// A deterministic stand-in for the engine: index+1 crevasses 50 m apart, depth from Π.
inline CaseOutcome fake_outcome(const StudyCase& c, double depth_scale = 1.0) {
  CaseOutcome o;
  o.stop_reason = "fake";
  o.steps = static_cast<std::int64_t>(100 + c.index);
  o.particle_steps = o.steps * 1000;
  o.sim_time_s = 1.0 + static_cast<double>(c.index);
  analysis::CrevasseMeasurement m;
  m.settings.ice_thickness_m = c.groups.thickness_m;
  m.settings.dx_m = c.scene.dx;
  m.time_s = o.sim_time_s;
  for (std::size_t k = 0; k <= c.index; ++k) {
    analysis::Crevasse cr;
    cr.x_m = 500.0 + 50.0 * static_cast<double>(k);
    cr.surface_z_m = 100.0;
    cr.depth_m = depth_scale * 10.0 * c.groups.cohesion_ratio;
    cr.bottom_z_m = cr.surface_z_m - cr.depth_m;
    cr.width_m = 5.0;
    cr.particle_count = 10;
    if (k < c.index) cr.spacing_to_next_m = 50.0;
    m.crevasses.push_back(cr);
    if (k < c.index) m.spacings_m.push_back(50.0);
  }
  if (!m.spacings_m.empty()) m.spacing_m = analysis::QuartileSummary{50.0, 50.0, 50.0};
  o.measurement = m;
  return o;
}

// Rows of a query, one string per row (columns joined by '|'), for comparing databases.
inline std::vector<std::string> dump_rows(const std::filesystem::path& db, const std::string& sql) {
  Store store = Store::open_reader(db);
  Statement s(store.handle(), sql);
  std::vector<std::string> rows;
  while (s.step()) {
    std::string row;
    for (int c = 0; c < s.columns(); ++c) {
      if (c) row += '|';
      row += s.is_null(c) ? std::string("NULL") : s.text(c);
    }
    rows.push_back(row);
  }
  return rows;
}

// Everything deterministic about a study database's results (no timings, hosts or sessions).
inline std::vector<std::string> result_dump(const std::filesystem::path& db) {
  std::vector<std::string> all;
  for (const char* sql :
       {"SELECT case_id, case_index, label, status, failure_reason IS NOT NULL, stop_reason, "
        "steps, particle_steps, "
        "sim_time_s, result_json, result_hash, scene_json FROM cases ORDER BY case_id",
        "SELECT * FROM crevasses ORDER BY case_id, crevasse_index",
        "SELECT * FROM summaries ORDER BY case_id",
        "SELECT name, study_hash, case_count, file_text FROM study"}) {
    auto rows = dump_rows(db, sql);
    all.push_back(std::string("-- ") + sql);
    all.insert(all.end(), rows.begin(), rows.end());
  }
  return all;
}

inline std::string pragma_integrity(const std::filesystem::path& db) {
  const auto rows = dump_rows(db, "PRAGMA integrity_check");
  return rows.empty() ? "" : rows.front();
}

inline std::string read_file(const std::filesystem::path& p) {
  std::ifstream f(p);
  std::ostringstream s;
  s << f.rdbuf();
  return s.str();
}

struct CliResult {
  int code = -1;
  std::string out, err;
};

// Runs the crevasse binary with `args` (already shell-quoted where needed) in `dir`.
inline CliResult run_cli(const std::filesystem::path& dir, const std::string& args) {
  const std::string cmd = "cd '" + dir.string() + "' && '" CREVASSE_BINARY "' " + args +
                          " > cli_out.txt 2> cli_err.txt";
  const int status = std::system(cmd.c_str());
  CliResult r;
  r.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  r.out = read_file(dir / "cli_out.txt");
  r.err = read_file(dir / "cli_err.txt");
  return r;
}

// The same under a file-size limit of `kib` KiB, as a full disk would stop its writes: bash
// ignores SIGXFSZ, so that writes past `ulimit -f` fail with EFBIG instead. Standard output is
// dropped.
inline CliResult run_cli_on_full_disk(const std::filesystem::path& dir, const std::string& args, int kib) {
  const std::string cmd = "cd '" + dir.string() + "' && bash -c \"trap '' XFSZ; ulimit -f " + std::to_string(kib) +
                          "; exec '" CREVASSE_BINARY "' " + args + "\" > /dev/null 2> cli_err.txt";
  const int status = std::system(cmd.c_str());
  CliResult r;
  r.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  r.err = read_file(dir / "cli_err.txt");
  return r;
}

// Starts the crevasse binary (CREVASSE_BINARY) with `args`, its stderr to `stderr_path`;
// returns the child's pid, or -1.
inline pid_t spawn_crevasse(const std::vector<std::string>& args, const std::string& stderr_path) {
  std::vector<std::string> all = {CREVASSE_BINARY};
  all.insert(all.end(), args.begin(), args.end());
  std::vector<char*> argv;
  for (auto& a : all) argv.push_back(a.data());
  argv.push_back(nullptr);
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, 2, stderr_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC,
                                   0644);
  pid_t pid = -1;
  const int rc = posix_spawn(&pid, CREVASSE_BINARY, &actions, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  return rc == 0 ? pid : -1;
}

}  // namespace crevasse::test
