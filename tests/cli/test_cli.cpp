// The crevasse executable: a bad study file is refused with one line and exit code 2 before
// any database exists; status, export --csv and the sqlite3 CLI read a study database; a study
// killed with SIGKILL resumes with the same command, loses nothing, reruns nothing finished,
// and ends with the same contents as an uninterrupted run; --version names the engine version.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <fstream>
#include <regex>
#include <sstream>
#include <thread>
#include <vector>

#include "../study/study_test_support.hpp"

namespace crevasse {
namespace {

using namespace std::chrono_literals;

using test::read_file;
using test::run_cli;
using Result = test::CliResult;

TEST(Cli, InvalidStudyFilesExitWithCode2AndCreateNoDatabase) {
  test::ScratchDir dir("cli");
  const std::vector<std::pair<std::string, std::string>> bad = {
      {R"({"name": "b", "base_scene": {}, "sweep": {"cohesion_ratio": {"log": [0, 1, 3]}}})",
       "sweep.cohesion_ratio.log"},
      {R"({"name": "b", "base_scene": "missing.json"})", "base_scene: cannot open"},
      {R"({"name": "b"})", "base_scene: required"},
      {"not json", "not valid JSON"},
  };
  for (const auto& [text, expect] : bad) {
    test::write_text(dir / "bad.json", text);
    const Result r = run_cli(dir.path(), "study bad.json --db out/bad.db");
    EXPECT_EQ(r.code, 2) << text;
    EXPECT_NE(r.err.find("crevasse: error: "), std::string::npos) << r.err;
    EXPECT_NE(r.err.find(expect), std::string::npos) << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << "one line: " << r.err;
    EXPECT_FALSE(std::filesystem::exists(dir / "out")) << "a refused study touched the disk";
  }
  EXPECT_EQ(run_cli(dir.path(), "study bad.json --shard 3/2").code, 2);
  EXPECT_EQ(run_cli(dir.path(), "status no_such.db").code, 2);
}

// --version prints one line naming the engine version the binary was built with (the version that
// enters every case hash), and exits 0 without asking for a subcommand.
TEST(Cli, VersionNamesTheEngineVersion) {
  test::ScratchDir dir("cli_version");
  const Result r = run_cli(dir.path(), "--version");
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(r.out.rfind("crevasse ", 0), 0u) << r.out;
  EXPECT_NE(r.out.find(std::string("(engine ") + CREVASSE_ENGINE_VERSION + ", "), std::string::npos)
      << r.out;
  EXPECT_EQ(std::count(r.out.begin(), r.out.end(), '\n'), 1) << "one line: " << r.out;
  EXPECT_TRUE(r.err.empty()) << r.err;
}

// Each subcommand's name and --help text, in the order the top-level --help lists them.
std::vector<std::pair<std::string, std::string>> subcommand_helps(const std::filesystem::path& dir) {
  const std::regex subcommand_line(R"(^  ([a-z]+)  )");
  std::vector<std::pair<std::string, std::string>> helps;
  std::istringstream lines(run_cli(dir, "--help").out);
  for (std::string line; std::getline(lines, line);) {
    std::smatch sub;
    if (std::regex_search(line, sub, subcommand_line))
      helps.emplace_back(sub[1].str(), run_cli(dir, sub[1].str() + " --help").out);
  }
  return helps;
}

// Every floating-point option of every subcommand, as its --help lists them (CLI11 names their
// type FLOAT), refuses NaN, infinities and overflow with exit 2 and a line naming the option: a
// range check alone lets NaN through. main.cpp puts the check on every FLOAT option, so a new
// option is covered without editing either.
TEST(Cli, EveryFloatingPointOptionRefusesNonFiniteValues) {
  test::ScratchDir dir("cli_finite");
  const std::regex float_option(R"((--[a-z-]+) FLOAT)");
  int checked = 0;
  for (const auto& [sub, help] : subcommand_helps(dir.path())) {
    for (std::sregex_iterator it(help.begin(), help.end(), float_option), end; it != end; ++it) {
      const std::string option = (*it)[1].str();
      for (const std::string value : {"nan", "inf", "-inf", "1e400"}) {
        const Result r = run_cli(dir.path(), sub + " " + option + " " + value);
        EXPECT_EQ(r.code, 2) << sub << " " << option << " " << value;
        // NaN passes a range check, so only the finiteness check can refuse it; an infinity may be
        // refused by the option's range first, with a line naming the option all the same.
        const std::string expected =
            value == "nan" ? option + ": 'nan' is not a finite number" : "crevasse: error: " + option + ": ";
        EXPECT_NE(r.err.find(expected), std::string::npos) << sub << " " << option << " " << value << ": " << r.err;
      }
      ++checked;
    }
  }
  EXPECT_GE(checked, 10);  // vtu/measure interval, case time limit, levels, spacing, thickness, cohesion
}

// Every text option and positional argument of every subcommand, as its --help lists them,
// refuses an empty value with exit 2 and a line naming it, and writes nothing (`run --out ''`
// wrote into the current folder; `study --db ''` fell back to the default database).
TEST(Cli, EveryTextOptionRefusesAnEmptyValue) {
  test::ScratchDir dir("cli_empty");
  const std::regex text_item(R"(^  (--[a-z-]+|[a-z]+) TEXT)");
  int checked = 0;
  for (const auto& [sub, help] : subcommand_helps(dir.path())) {
    std::istringstream help_lines(help);
    std::string positionals_before;  // a placeholder for each earlier positional
    for (std::string item; std::getline(help_lines, item);) {
      std::smatch m;
      if (!std::regex_search(item, m, text_item)) continue;
      const std::string name = m[1].str();
      const bool positional = name.rfind("--", 0) != 0;
      const std::string args = sub + " " + (positional ? positionals_before + "''" : name + " ''");
      const Result r = run_cli(dir.path(), args);
      EXPECT_EQ(r.code, 2) << args;
      EXPECT_NE(r.err.find(name + ": empty value"), std::string::npos) << args << ": " << r.err;
      if (positional) positionals_before += "x.db ";
      ++checked;
    }
  }
  EXPECT_GE(checked, 30);
  int entries = 0;
  for (const auto& e : std::filesystem::directory_iterator(dir.path()))
    entries += e.path().filename() != "cli_out.txt" && e.path().filename() != "cli_err.txt";
  EXPECT_EQ(entries, 0);
}

// crevasse run --measure-interval: one row per interval of simulated time plus the final
// measurement, in time order, with the gate frame for a slab on a step.
TEST(Cli, RunMeasuresAtIntervalsWhenAsked) {
  test::ScratchDir dir("cli");
  nlohmann::json scene = test::tiny_scene();
  scene["run"] = {{"end_time", 30.0}};
  test::write_text(dir / "scene.json", scene.dump());
  const Result r = run_cli(dir.path(), "run scene.json --out out --measure-interval 10 --quiet");
  ASSERT_EQ(r.code, 0) << r.err;
  std::istringstream csv(read_file(dir / "out/measurements_over_time.csv"));
  std::string line;
  ASSERT_TRUE(std::getline(csv, line));
  EXPECT_EQ(line.rfind("time_s,gate_passed_length_m,frame,", 0), 0u) << line;
  std::vector<double> times;
  while (std::getline(csv, line)) {
    times.push_back(std::stod(line.substr(0, line.find(','))));
    EXPECT_NE(line.find(",gate,"), std::string::npos) << line;
  }
  // t = 10, 20 and 30 s (each the first step at or past the interval), then the final state,
  // which is the 30 s state again.
  ASSERT_EQ(times.size(), 4u);
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(times[k], 10.0 * (k + 1), 0.1) << k;
  EXPECT_GE(times[3], times[2]);
}

TEST(Cli, StudyStatusExportAndSqlite3) {
  test::ScratchDir dir("cli");
  test::write_text(dir / "s.json", test::tiny_study(3, 200, "cli").dump(2));
  const Result dry = run_cli(dir.path(), "study s.json --dry-run");
  EXPECT_EQ(dry.code, 0) << dry.err;
  EXPECT_NE(dry.out.find("3 case(s)"), std::string::npos) << dry.out;
  EXPECT_FALSE(std::filesystem::exists(dir / "results"));

  const Result run = run_cli(dir.path(), "study s.json --jobs 2");
  ASSERT_EQ(run.code, 0) << run.err;
  EXPECT_NE(run.err.find("3 done, 0 failed"), std::string::npos) << run.err;
  ASSERT_TRUE(std::filesystem::exists(dir / "results" / "cli.db"));

  const Result status = run_cli(dir.path(), "status results/cli.db");
  EXPECT_EQ(status.code, 0) << status.err;
  EXPECT_NE(status.out.find("3 done, 0 failed, 0 running, 0 pending"), std::string::npos)
      << status.out;
  EXPECT_NE(status.out.find("cohesion_ratio=0.05"), std::string::npos) << status.out;
  EXPECT_NE(status.out.find("compute: 3 cases run"), std::string::npos) << status.out;
  const Result compute = run_cli(dir.path(), "status --compute results/cli.db results/cli.db");
  EXPECT_EQ(compute.code, 0) << compute.err;
  EXPECT_NE(compute.out.find("| cli.db | 40 | 3 | 0 | 0 |"), std::string::npos) << compute.out;
  EXPECT_NE(compute.out.find("| all |  | 6 | 0 | 0 |"), std::string::npos) << compute.out;
  const Result two = run_cli(dir.path(), "status results/cli.db results/cli.db");
  EXPECT_EQ(two.code, 2);
  EXPECT_NE(two.err.find("several only with --compute"), std::string::npos) << two.err;

  const Result exp = run_cli(dir.path(), "export results/cli.db --csv csv");
  EXPECT_EQ(exp.code, 0) << exp.err;
  for (const char* table : {"study", "sessions", "cases", "crevasses", "summaries"}) {
    const std::string text = read_file(dir / "csv" / (std::string(table) + ".csv"));
    EXPECT_FALSE(text.empty()) << table;
  }
  const std::string cases = read_file(dir / "csv" / "cases.csv");
  const std::string header = cases.substr(0, cases.find('\n'));
  for (const char* col : {"case_id", "cohesion_ratio", "status", "axis.cohesion_ratio",
                          "scene.ice.tensile_strength", "scene.numerics.dx"})
    EXPECT_NE(header.find(col), std::string::npos) << col;
  EXPECT_EQ(std::count(cases.begin(), cases.end(), '\n'), 4);

  if (std::system("command -v sqlite3 > /dev/null 2>&1") == 0) {
    const std::string cmd = "sqlite3 '" + (dir / "results" / "cli.db").string() +
                            "' \"SELECT count(*) FROM cases WHERE status = 'done'\" > '" +
                            (dir / "q.txt").string() + "'";
    ASSERT_EQ(std::system(cmd.c_str()), 0);
    EXPECT_EQ(read_file(dir / "q.txt"), "3\n");
  }
}

std::int64_t done_count(const std::filesystem::path& db) {
  try {
    return Store::open_reader(db).counts().done;
  } catch (const std::exception&) {
    return 0;  // not created yet, or the schema is being written
  }
}

// Mid-case checkpoints: one long case, SIGKILLed once its checkpoint exists;
// the resumed study continues it from the checkpoint (run_json.resumed_from_time_s > 0), deletes
// the checkpoint, and stores the same result as an uninterrupted run.
TEST(Cli, KilledCaseResumesFromItsCheckpoint) {
  test::ScratchDir dir("cli");
  nlohmann::json study = test::tiny_study(2, 20000, "ckpt");
  study["sweep"] = {{"cohesion_ratio", {0.3}}};
  study["resources"] = {{"checkpoint_interval_s", 0.2}};
  // The field over time too: the resumed case's series must be the uninterrupted one, the rows
  // before its checkpoint kept and those after taken on the same times.
  study["measure_interval_s"] = 5.0;
  test::write_text(dir / "s.json", study.dump(2));
  const Result ref = run_cli(dir.path(), "study s.json --db ref.db --jobs 1 --threads-per-case 1 --quiet");
  ASSERT_EQ(ref.code, 0) << ref.err;
  EXPECT_FALSE(std::filesystem::exists(dir / "ref.db.checkpoints") &&
               !std::filesystem::is_empty(dir / "ref.db.checkpoints"))
      << "a finished case leaves no checkpoint";

  const std::vector<std::string> args = {"study", (dir / "s.json").string(), "--db",
                                         (dir / "k.db").string(), "--jobs", "1",
                                         "--threads-per-case", "1", "--quiet"};
  const pid_t pid = test::spawn_crevasse(args, (dir / "killed_err.txt").string());
  ASSERT_GT(pid, 0);
  const auto deadline = std::chrono::steady_clock::now() + 60s;
  bool have_checkpoint = false;
  while (!have_checkpoint && std::chrono::steady_clock::now() < deadline) {
    std::error_code ec;
    for (const auto& e : std::filesystem::directory_iterator(dir / "k.db.checkpoints", ec))
      have_checkpoint |= e.path().extension() == ".ckpt";
    std::this_thread::sleep_for(5ms);
  }
  std::this_thread::sleep_for(100ms);  // let it run on past the checkpoint
  ASSERT_EQ(::kill(pid, SIGKILL), 0);
  int status = 0;
  ::waitpid(pid, &status, 0);
  ASSERT_TRUE(have_checkpoint);
  ASSERT_TRUE(WIFSIGNALED(status)) << "the case ended before it could be killed; make it longer";

  const Result resumed =
      run_cli(dir.path(), "study s.json --db k.db --jobs 1 --threads-per-case 1 --quiet");
  ASSERT_EQ(resumed.code, 0) << resumed.err;
  EXPECT_EQ(test::pragma_integrity(dir / "k.db"), "ok");
  const auto resumed_from = test::dump_rows(
      dir / "k.db", "SELECT json_extract(run_json, '$.resumed_from_time_s') FROM cases");
  ASSERT_EQ(resumed_from.size(), 1u);
  EXPECT_GT(std::stod(resumed_from[0]), 0.0) << "the case started again from t = 0";
  // Its wall time counts the killed sitting too, up to its checkpoint (which carried it): the
  // engine's exceeds the last sitting's, and the case's (which adds measuring) is no less.
  const auto walls = test::dump_rows(dir / "k.db", "SELECT wall_s >= json_extract(run_json, '$.engine_wall_s'), "
                                                   "json_extract(run_json, '$.engine_wall_s') > "
                                                   "json_extract(run_json, '$.sitting_wall_s'), "
                                                   "json_extract(run_json, '$.earlier_wall_unknown') IS NULL FROM cases");
  EXPECT_EQ(walls, std::vector<std::string>{"1|1|1"});
  EXPECT_TRUE(std::filesystem::is_empty(dir / "k.db.checkpoints"));
  EXPECT_EQ(test::result_dump(dir / "k.db"), test::result_dump(dir / "ref.db"));
  const auto times = test::dump_rows(
      dir / "ref.db",
      "SELECT group_concat(round(json_extract(value, '$.time_s'))), max(json_extract(value, '$.time_s')) = "
      "json_extract(result_json, '$.sim_time_s') FROM cases, json_each(json_extract(result_json, "
      "'$.extra.over_time'))");
  ASSERT_EQ(times.size(), 1u);
  EXPECT_EQ(times[0].substr(0, 16), "5.0,10.0,15.0,20") << "a row every 5 s of simulated time";
  EXPECT_EQ(times[0].substr(times[0].size() - 2), "|1") << "the last row is the final state";
}

// A case that runs out of time keeps its checkpoint: the failure says so, and under a larger
// limit --retry-failed continues it from there to the uninterrupted result. (The limit is not
// part of the case, so raising it keeps the case and its checkpoint.)
TEST(Cli, CaseOutOfTimeKeepsItsCheckpointAndRetryContinuesIt) {
  test::ScratchDir dir("cli");
  nlohmann::json study = test::tiny_study(2, 60000, "late");
  study["sweep"] = {{"cohesion_ratio", {0.3}}};
  study["resources"] = {{"checkpoint_interval_s", 0.2}};
  test::write_text(dir / "s.json", study.dump(2));
  const auto t0 = std::chrono::steady_clock::now();
  const Result ref = run_cli(dir.path(), "study s.json --db ref.db --jobs 1 --threads-per-case 1 --quiet");
  ASSERT_EQ(ref.code, 0) << ref.err;
  ASSERT_GT(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(), 2.0)
      << "the case is too short for a 1 s limit; make it longer";

  study["base_scene"]["run"]["wall_time_limit"] = 1.0;
  test::write_text(dir / "s.json", study.dump(2));
  const Result late = run_cli(dir.path(), "study s.json --db k.db --jobs 1 --threads-per-case 1 --quiet");
  EXPECT_EQ(late.code, 1) << late.err;
  const auto reason = test::dump_rows(dir / "k.db", "SELECT status, failure_reason FROM cases");
  ASSERT_EQ(reason.size(), 1u);
  EXPECT_EQ(reason[0].rfind("failed|time limit: 1 s", 0), 0u) << reason[0];
  EXPECT_NE(reason[0].find("checkpoint is kept"), std::string::npos) << reason[0];
  ASSERT_FALSE(std::filesystem::is_empty(dir / "k.db.checkpoints"));

  study["base_scene"]["run"].erase("wall_time_limit");
  test::write_text(dir / "s.json", study.dump(2));
  const Result retried = run_cli(dir.path(), "study s.json --db k.db --jobs 1 --threads-per-case 1 --quiet --retry-failed");
  ASSERT_EQ(retried.code, 0) << retried.err;
  const auto resumed_from = test::dump_rows(
      dir / "k.db", "SELECT json_extract(run_json, '$.resumed_from_time_s') FROM cases");
  ASSERT_EQ(resumed_from.size(), 1u);
  EXPECT_GT(std::stod(resumed_from[0]), 0.0) << "the case started again from t = 0";
  EXPECT_TRUE(std::filesystem::is_empty(dir / "k.db.checkpoints"));
  // The stored scene and study text keep the limit the case was registered with; the result is
  // the uninterrupted run's.
  const std::string results = "SELECT case_id, status, steps, particle_steps, result_hash FROM cases";
  EXPECT_EQ(test::dump_rows(dir / "k.db", results), test::dump_rows(dir / "ref.db", results));
}

// A write that fails (here: a file-size limit, as a full disk would) ends the study with a
// clear one-line message and exit code 1; the database stays sound with whole cases only, and
// the same command resumes it to the uninterrupted result. A database path on a read-only file
// system is refused before anything runs.
TEST(Cli, FullDiskFailsCleanlyAndResumes) {
  test::ScratchDir dir("cli");
  test::write_text(dir / "s.json", test::tiny_study(12, 200, "full").dump(2));
  const Result ref = run_cli(dir.path(), "study s.json --db ref.db --jobs 1 --quiet");
  ASSERT_EQ(ref.code, 0) << ref.err;

  const Result full = test::run_cli_on_full_disk(dir.path(), "study s.json --db k.db --jobs 1 --quiet", 200);
  EXPECT_EQ(full.code, 1);
  const std::string& err = full.err;
  EXPECT_EQ(std::count(err.begin(), err.end(), '\n'), 1) << err;
  EXPECT_NE(err.find("the disk may be full"), std::string::npos) << err;
  EXPECT_EQ(test::pragma_integrity(dir / "k.db"), "ok");
  EXPECT_EQ(test::dump_rows(dir / "k.db",
                            "SELECT count(*) FROM cases c WHERE status = 'done' AND NOT EXISTS "
                            "(SELECT 1 FROM summaries s WHERE s.case_id = c.case_id)")
                .at(0),
            "0");
  const int done_before =
      std::stoi(test::dump_rows(dir / "k.db", "SELECT count(*) FROM cases WHERE status = 'done'").at(0));
  EXPECT_LT(done_before, 12) << "the limit did not stop the study; lower it";

  const Result resumed = run_cli(dir.path(), "study s.json --db k.db --jobs 1 --quiet");
  ASSERT_EQ(resumed.code, 0) << resumed.err;
  EXPECT_EQ(test::result_dump(dir / "k.db"), test::result_dump(dir / "ref.db"));

  const Result ro = run_cli(dir.path(), "study s.json --db /proc/crevasse_test.db --quiet");
  EXPECT_EQ(ro.code, 2) << ro.err;
  EXPECT_NE(ro.err.find("--db /proc/crevasse_test.db"), std::string::npos) << ro.err;
}

TEST(Cli, SigkillDuringAStudyThenResumeLosesAndRerunsNothing) {
  test::ScratchDir dir("cli");
  constexpr int kCases = 8;
  test::write_text(dir / "s.json", test::tiny_study(kCases, 4500, "killed").dump(2));
  const std::vector<std::string> args = {"study",
                                         (dir / "s.json").string(),
                                         "--db",
                                         (dir / "k.db").string(),
                                         "--jobs",
                                         "2",
                                         "--threads-per-case",
                                         "1",
                                         "--quiet"};

  // Reference: the same study, uninterrupted.
  const Result ref =
      run_cli(dir.path(), "study s.json --db ref.db --jobs 2 --threads-per-case 1 --quiet");
  ASSERT_EQ(ref.code, 0) << ref.err;

  const pid_t pid = test::spawn_crevasse(args, (dir / "killed_err.txt").string());
  ASSERT_GT(pid, 0);
  const auto deadline = std::chrono::steady_clock::now() + 60s;
  std::int64_t done_at_kill = 0;
  while (std::chrono::steady_clock::now() < deadline) {
    done_at_kill = done_count(dir / "k.db");
    if (done_at_kill >= 2) break;
    std::this_thread::sleep_for(5ms);
  }
  ASSERT_EQ(::kill(pid, SIGKILL), 0);
  int status = 0;
  ::waitpid(pid, &status, 0);
  ASSERT_TRUE(WIFSIGNALED(status))
      << "the study ended before it could be killed; make its cases longer";
  ASSERT_GE(done_at_kill, 2);

  // After the kill: a sound database holding whole cases only.
  EXPECT_EQ(test::pragma_integrity(dir / "k.db"), "ok");
  const auto finished_sql =
      "SELECT case_id, status, finished_at, session_id, wall_s, attempts, result_hash FROM cases "
      "WHERE status = 'done' ORDER BY case_id";
  const auto before = test::dump_rows(dir / "k.db", finished_sql);
  ASSERT_GE(before.size(), 2u);
  ASSERT_LT(before.size(), static_cast<std::size_t>(kCases))
      << "all cases finished before the kill";
  EXPECT_EQ(test::dump_rows(dir / "k.db",
                            "SELECT count(*) FROM cases c WHERE status = 'done' AND NOT EXISTS "
                            "(SELECT 1 FROM summaries s WHERE s.case_id = c.case_id)")
                .at(0),
            "0")
      << "a done case without its summary";
  EXPECT_EQ(test::dump_rows(dir / "k.db",
                            "SELECT count(*) FROM summaries s JOIN cases c USING (case_id) "
                            "WHERE c.status != 'done'")
                .at(0),
            "0")
      << "results of an unfinished case";

  // Resume with the same command.
  std::string cmd = "study s.json --db k.db --jobs 2 --threads-per-case 1 --quiet";
  const Result resumed = run_cli(dir.path(), cmd);
  ASSERT_EQ(resumed.code, 0) << resumed.err;
  EXPECT_EQ(test::pragma_integrity(dir / "k.db"), "ok");

  // Nothing finished before the kill ran again: same finish time, session and attempt count.
  const auto after = test::dump_rows(dir / "k.db", finished_sql);
  for (const auto& row : before)
    EXPECT_NE(std::find(after.begin(), after.end(), row), after.end()) << row;
  EXPECT_EQ(after.size(), static_cast<std::size_t>(kCases));
  EXPECT_EQ(test::dump_rows(dir / "k.db", "SELECT count(DISTINCT session_id) FROM cases").at(0),
            "2");
  EXPECT_EQ(
      test::dump_rows(dir / "k.db", "SELECT count(*) FROM sessions WHERE outcome IS NULL").at(0),
      "1")
      << "the killed session stays open in the record";

  // Same results as the uninterrupted run.
  EXPECT_EQ(test::result_dump(dir / "k.db"), test::result_dump(dir / "ref.db"));
}

// Kept particles measure again as the case was measured: `crevasse run` writes
// final_particles.bin, and `crevasse measure` on it with the run's settings writes the very
// measurement.json the run wrote; --set changes a setting, a bad one is refused naming it.
TEST(Cli, MeasureAgainReproducesTheRunsMeasurementAndTakesOtherSettings) {
  test::ScratchDir dir("cli");
  nlohmann::json scene = test::tiny_scene();
  scene["run"] = {{"end_time", 30.0}};
  test::write_text(dir / "scene.json", scene.dump());
  const Result r = run_cli(dir.path(), "run scene.json --out out --quiet");
  ASSERT_EQ(r.code, 0) << r.err;
  const Result again = run_cli(dir.path(), "measure out/final_particles.bin --out m --vtu m/final.vtu");
  ASSERT_EQ(again.code, 0) << again.err;
  EXPECT_EQ(nlohmann::json::parse(read_file(dir / "out/measurement.json")),
            nlohmann::json::parse(read_file(dir / "m/measurement.json")));
  EXPECT_EQ(read_file(dir / "out/crevasses.csv"), read_file(dir / "m/crevasses.csv"));
  EXPECT_TRUE(std::filesystem::exists(dir / "m/final.vtu"));
  EXPECT_NE(again.out.find("frame gate"), std::string::npos) << again.out;

  const Result other = run_cli(dir.path(), "measure out/final_particles.bin --set frame=final --set spacing_rule=drop");
  ASSERT_EQ(other.code, 0) << other.err;
  EXPECT_NE(other.out.find("frame final"), std::string::npos) << other.out;
  EXPECT_NE(other.out.find("rule drop"), std::string::npos) << other.out;

  for (const char* bad : {"--set frame=sideways", "--set min_depth_over_dx=-1", "--set nonsense=1", "--set frame"}) {
    const Result refused = run_cli(dir.path(), std::string("measure out/final_particles.bin ") + bad);
    EXPECT_EQ(refused.code, 2) << bad;
    EXPECT_EQ(std::count(refused.err.begin(), refused.err.end(), '\n'), 1) << refused.err;
  }
  const Result missing = run_cli(dir.path(), "measure out/nothing.bin");
  EXPECT_EQ(missing.code, 2);
  EXPECT_NE(missing.err.find("nothing.bin"), std::string::npos) << missing.err;
}

// `crevasse study --keep-particles` keeps each case's final particles in DB.particles/ beside
// the database (a folder git ignores), whether or not side views are drawn; measured again they
// give the case's stored summary (crevasse count, window, particle, damage and cluster counts),
// and the file names the case.
TEST(Cli, StudyKeepsParticlesThatMeasureAsStored) {
  test::ScratchDir dir("cli");
  nlohmann::json study = test::tiny_study(2, 200, "keep");
  study["base_scene"]["run"] = {{"end_time", 30.0}};  // long enough for some ice to break
  test::write_text(dir / "s.json", study.dump(2));
  const Result run = run_cli(dir.path(), "study s.json --keep-particles --quiet");
  ASSERT_EQ(run.code, 0) << run.err;
  EXPECT_FALSE(std::filesystem::exists(dir / "v"));
  const auto rows = test::dump_rows(dir / "results/keep.db",
                                    "SELECT c.case_id, s.crevasse_count, s.window_min_x_m, s.window_max_x_m, "
                                    "s.particle_count, s.window_particle_count, s.damaged_particle_count, "
                                    "s.cluster_count FROM cases c JOIN summaries s USING (case_id) ORDER BY c.case_index");
  ASSERT_EQ(rows.size(), 2u);
  std::int64_t damaged = 0;
  for (int k = 0; k < 2; ++k) {
    char file[64];
    std::snprintf(file, sizeof file, "results/keep.db.particles/case_%03d_particles.bin", k);
    const std::string out = "m" + std::to_string(k);
    const Result m = run_cli(dir.path(), std::string("measure ") + file + " --out " + out);
    ASSERT_EQ(m.code, 0) << m.err;
    const nlohmann::json j = nlohmann::json::parse(read_file(dir / out / "measurement.json"));
    const std::string id = rows[k].substr(0, rows[k].find('|'));
    EXPECT_NE(m.out.find("case " + id), std::string::npos) << m.out;
    std::vector<std::string> f;
    std::istringstream fields(rows[k]);
    for (std::string x; std::getline(fields, x, '|');) f.push_back(x);
    ASSERT_EQ(f.size(), 8u) << rows[k];
    const auto& c = j.at("counts");
    EXPECT_EQ(std::stoll(f[1]), j.at("crevasse_count").get<std::int64_t>());
    EXPECT_NEAR(std::stod(f[2]), j.at("settings").at("window_min_x_m").get<double>(), 1e-9);
    EXPECT_NEAR(std::stod(f[3]), j.at("settings").at("window_max_x_m").get<double>(), 1e-9);
    EXPECT_EQ(std::stoll(f[4]), c.at("particles").get<std::int64_t>());
    EXPECT_EQ(std::stoll(f[5]), c.at("window_particles").get<std::int64_t>());
    EXPECT_EQ(std::stoll(f[6]), c.at("damaged_particles").get<std::int64_t>());
    EXPECT_EQ(std::stoll(f[7]), c.at("damage_clusters").get<std::int64_t>());
    damaged += c.at("damaged_particles").get<std::int64_t>();
  }
  EXPECT_GT(damaged, 0) << "nothing was damaged: the comparison shows little; run the cases longer";
}

// What a study stores of its cases' results: records, result hashes, crevasses and summaries.
std::vector<std::string> stored_results(const std::filesystem::path& db) {
  std::vector<std::string> all;
  for (const char* sql : {"SELECT case_id, case_index, status, stop_reason, steps, particle_steps, sim_time_s, "
                          "result_json, result_hash FROM cases ORDER BY case_id",
                          "SELECT * FROM crevasses ORDER BY case_id, crevasse_index",
                          "SELECT * FROM summaries ORDER BY case_id"}) {
    const auto rows = test::dump_rows(db, sql);
    all.insert(all.end(), rows.begin(), rows.end());
  }
  return all;
}

// A study that differs from a finished one only in its measurement can be measured from the
// particles that study kept (`--remeasure DB --particles-from DIR`) instead of simulating it
// again, and it stores exactly what a full run stores: the same case ids, records, result
// hashes, crevasses and summaries. A case whose scene has no kept particles fails with the
// reason, and the options are checked before any work.
TEST(Cli, RemeasureFromKeptParticlesStoresWhatAFullRunStores) {
  test::ScratchDir dir("cli");
  nlohmann::json kept = test::tiny_study(2, 200, "kept");
  kept["base_scene"]["run"] = {{"end_time", 30.0}};  // long enough for some ice to break
  kept["measurement"] = {{"link_distance_over_spacing", 1.5}};
  test::write_text(dir / "kept.json", kept.dump(2));
  // The particles in a folder of the user's choice, as older studies kept them beside their views.
  ASSERT_EQ(run_cli(dir.path(), "study kept.json --db kept.db --views v --particles-dir v --quiet").code, 0);

  nlohmann::json other = kept;
  other["name"] = "other";
  other["measurement"] = {{"link_distance_over_spacing", 2.5}, {"min_depth_over_dx", 1.0}};
  test::write_text(dir / "other.json", other.dump(2));
  const Result again = run_cli(dir.path(), "study other.json --db again.db --remeasure kept.db --particles-from v --views w --quiet");
  ASSERT_EQ(again.code, 0) << again.err;
  ASSERT_EQ(run_cli(dir.path(), "study other.json --db full.db --quiet").code, 0);
  const auto results = [&](const char* db) { return stored_results(dir / db); };
  EXPECT_EQ(results("again.db"), results("full.db"));
  EXPECT_NE(results("kept.db"), results("full.db")) << "the settings changed nothing: the test shows nothing";
  // The same command where the kept particles are gone (a clone holds the databases, not the
  // particle files): every case is done, nothing is read, nothing changes. A study with cases
  // left to measure is still refused (below).
  const auto stored = results("again.db");
  const Result rerun = run_cli(dir.path(), "study other.json --db again.db --remeasure kept.db --particles-from gone --quiet");
  EXPECT_EQ(rerun.code, 0) << rerun.err;
  EXPECT_EQ(results("again.db"), stored);
  // With one case measured, the same holds for that case alone, and the other still needs them.
  ASSERT_EQ(run_cli(dir.path(), "study other.json --db part.db --cases 0 --remeasure kept.db --particles-from v --quiet").code, 0);
  EXPECT_EQ(run_cli(dir.path(), "study other.json --db part.db --cases 0 --remeasure kept.db --particles-from gone --quiet").code, 0);
  EXPECT_EQ(run_cli(dir.path(), "study other.json --db part.db --remeasure kept.db --particles-from gone --quiet").code, 2);
  EXPECT_EQ(test::dump_rows(dir / "again.db", "SELECT count(*) FROM cases WHERE json_extract(run_json, "
                                               "'$.measured_from.database') = 'kept.db'")[0], "2");
  EXPECT_TRUE(std::filesystem::exists(dir / "w" / "case_001_side_view.png"));
  // status marks both and shows the wall time of the runs that made the particles, not the
  // re-measurement's (the tiny runs take under a minute: status writes "%.1fs").
  const Result status = run_cli(dir.path(), "status again.db");
  const auto run_walls = test::dump_rows(dir / "kept.db", "SELECT case_index, printf('%.1fs', "
                                                          "json_extract(run_json, '$.engine_wall_s')) FROM cases");
  const auto again_walls = test::dump_rows(dir / "again.db", "SELECT case_index, printf('%.1fs', wall_s) FROM cases");
  EXPECT_NE(run_walls, again_walls) << "the run and the re-measurement took as long: the test shows nothing";
  std::size_t marked = 0;
  std::istringstream lines(status.out);
  for (std::string line; std::getline(lines, line);) {
    if (line.find("measured again from kept particles") == std::string::npos) continue;
    ++marked;
    std::string index;
    std::istringstream(line) >> index;
    std::string run_wall = "?";
    for (const std::string& row : run_walls)
      if (row.substr(0, row.find('|')) == index) run_wall = row.substr(row.find('|') + 1);
    EXPECT_NE(line.find(" " + run_wall + " "), std::string::npos) << "wall " << run_wall << " not in: " << line;
  }
  EXPECT_EQ(marked, 2u) << status.out;

  // Another scene: nothing kept for it, so its cases fail and say why.
  nlohmann::json longer = other;
  longer["name"] = "longer";
  longer["base_scene"]["run"] = {{"end_time", 31.0}};
  test::write_text(dir / "longer.json", longer.dump(2));
  const Result none = run_cli(dir.path(), "study longer.json --db longer.db --remeasure kept.db --particles-from v --quiet");
  EXPECT_EQ(none.code, 1) << none.err;
  const auto reasons = test::dump_rows(dir / "longer.db", "SELECT failure_reason FROM cases");
  ASSERT_EQ(reasons.size(), 2u);
  for (const auto& r : reasons) EXPECT_NE(r.find("no particles kept"), std::string::npos) << r;

  auto refused = [&](const std::string& args, const std::string& names) {
    const Result r = run_cli(dir.path(), args);
    EXPECT_EQ(r.code, 2) << args << ": " << r.err;
    EXPECT_NE(r.err.find(names), std::string::npos) << args << ": " << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << args << ": " << r.err;
  };
  refused("study other.json --db x.db --remeasure kept.db --quiet", "--remeasure");
  refused("study other.json --db x.db --particles-from v --quiet", "--particles-from");
  refused("study other.json --db x.db --remeasure nothing.db --particles-from v --quiet", "nothing.db");
  std::filesystem::create_directories(dir / "empty");
  refused("study other.json --db x.db --remeasure kept.db --particles-from empty --quiet", "empty");
  refused("study other.json --db x.db --remeasure kept.db --particles-from gone --quiet", "gone");
  EXPECT_FALSE(std::filesystem::exists(dir / "x.db")) << "refused, yet the study began";
}

// The field over time is measured as a run goes and cannot be taken again from the final
// particles. Measured again with the run's own settings (a newer detector on the same study),
// a case keeps it, and then stores the very record the run stored; with other settings it is
// dropped, being another measurement's.
TEST(Cli, RemeasureKeepsTheFieldOverTimeOnlyUnderTheRunsOwnSettings) {
  test::ScratchDir dir("cli");
  nlohmann::json kept = test::tiny_study(2, 200, "kept");
  kept["base_scene"]["run"] = {{"end_time", 30.0}};
  kept["measure_interval_s"] = 10.0;
  test::write_text(dir / "kept.json", kept.dump(2));
  ASSERT_EQ(run_cli(dir.path(), "study kept.json --db kept.db --keep-particles --quiet").code, 0);
  const char* over_time = "SELECT case_index, json_extract(result_json, '$.extra.over_time') FROM cases ORDER BY case_index";
  const auto series = test::dump_rows(dir / "kept.db", over_time);
  ASSERT_EQ(series.size(), 2u);
  for (const auto& row : series) ASSERT_GT(row.size(), 20u) << "no field over time stored: the test shows nothing";

  const Result same = run_cli(dir.path(), "study kept.json --db same.db --remeasure kept.db --particles-from kept.db.particles --quiet");
  ASSERT_EQ(same.code, 0) << same.err;
  EXPECT_EQ(test::dump_rows(dir / "same.db", over_time), series);
  const char* records = "SELECT case_id, result_json, result_hash FROM cases ORDER BY case_id";
  EXPECT_EQ(test::dump_rows(dir / "same.db", records), test::dump_rows(dir / "kept.db", records));
  EXPECT_EQ(test::dump_rows(dir / "same.db", "SELECT count(*) FROM cases WHERE "
                                             "json_extract(run_json, '$.over_time_measured_during_run')")[0], "2");

  nlohmann::json other = kept;
  other["name"] = "other";
  other["measurement"] = {{"min_depth_over_dx", 1.0}};
  test::write_text(dir / "other.json", other.dump(2));
  ASSERT_EQ(run_cli(dir.path(), "study other.json --db other.db --remeasure kept.db --particles-from kept.db.particles --quiet").code, 0);
  EXPECT_EQ(test::dump_rows(dir / "other.db", "SELECT count(*) FROM cases WHERE "
                                              "json_extract(result_json, '$.extra.over_time') IS NULL")[0], "2");
}

// One run serves a shorter protocol: a study whose cases keep their particles when 1.05 H_i has
// passed the gate (keep_particles_at_gate_length_ratios, a ratio with no exact binary form) lets
// --remeasure fill the study that stops there, storing exactly what running that study stores,
// damaged ice and all.
TEST(Cli, ParticlesKeptAtAGateMarkServeTheStudyThatStopsThere) {
  test::ScratchDir dir("cli");
  nlohmann::json shorter = test::tiny_study(2, 100000, "shorter");
  shorter["sweep"] = {{"cohesion_ratio", {0.05, 0.1}}};
  shorter["fixed"]["gate_length_ratio"] = 1.05;
  shorter["protocol"] = "initiation";
  test::write_text(dir / "shorter.json", shorter.dump(2));
  nlohmann::json longer = shorter;
  longer["name"] = "longer";
  longer["fixed"]["gate_length_ratio"] = 2.1;
  longer["protocol"] = "steady";
  longer["keep_particles_at_gate_length_ratios"] = {1.05};
  test::write_text(dir / "longer.json", longer.dump(2));
  ASSERT_EQ(run_cli(dir.path(), "study shorter.json --db full.db --quiet").code, 0);
  ASSERT_EQ(run_cli(dir.path(), "study longer.json --db longer.db --keep-particles --quiet").code, 0);
  EXPECT_TRUE(std::filesystem::exists(dir / "longer.db.particles" / "case_001_gate_1.05_particles.bin"));
  const Result again = run_cli(dir.path(), "study shorter.json --db again.db --remeasure longer.db --particles-from "
                                           "longer.db.particles --quiet");
  ASSERT_EQ(again.code, 0) << again.err;
  // The longer study's own final particles are named in one line, not one per file.
  EXPECT_NE(again.err.find("2 kept particle files"), std::string::npos) << again.err;
  const auto results = [&](const char* db) { return stored_results(dir / db); };
  EXPECT_EQ(results("again.db"), results("full.db"));
  for (const std::string& n : test::dump_rows(dir / "full.db", "SELECT json_extract(result_json, "
                                                                "'$.measurement.counts.damaged_particles') FROM cases"))
    EXPECT_GT(std::stoll(n), 0) << "no damaged ice: the measurement compared shows little";
  const auto steps = [&](const char* db) { return test::dump_rows(dir / db, "SELECT steps FROM cases ORDER BY case_index"); };
  EXPECT_NE(steps("longer.db"), steps("full.db")) << "the longer study stopped where the shorter does: the test shows nothing";
  // Each says which run kept its particles.
  EXPECT_EQ(test::dump_rows(dir / "again.db", "SELECT json_extract(run_json, '$.measured_from.kept_at_gate_mark_of_case_id') "
                                              "FROM cases ORDER BY case_index"),
            test::dump_rows(dir / "longer.db", "SELECT case_id FROM cases ORDER BY case_index"));
}

// The gate marks' field is checked like every other: a list of lengths in (0, 1000].
TEST(Cli, GateMarksOutsideTheirRangeAreRefused) {
  test::ScratchDir dir("cli");
  for (const char* bad : {"[]", "[0]", "[1.5, -1]", "[\"a\"]", "0.5"}) {
    nlohmann::json st = test::tiny_study(2, 100, "marks");
    st["keep_particles_at_gate_length_ratios"] = nlohmann::json::parse(bad);
    test::write_text(dir / "marks.json", st.dump(2));
    const Result r = run_cli(dir.path(), "study marks.json --db marks.db --quiet");
    EXPECT_EQ(r.code, 2) << bad << ": " << r.err;
    EXPECT_NE(r.err.find("keep_particles_at_gate_length_ratios"), std::string::npos) << bad << ": " << r.err;
    EXPECT_NE(r.err.find("(0, 1000]"), std::string::npos) << bad << ": " << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << bad << ": " << r.err;
    EXPECT_FALSE(std::filesystem::exists(dir / "marks.db")) << bad;
  }
}

}  // namespace
}  // namespace crevasse
