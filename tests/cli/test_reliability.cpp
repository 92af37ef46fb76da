// docs/reliability.md, "Faults never cost a case": a checkpoint can only help (an unusable one
// is reported, dropped and the case reruns from t = 0; a failed write warns and the case goes
// on; a stop leaves the case pending), the settling phase honours signals, the case time limit
// and checkpoints, and a file where the checkpoint folder belongs is refused before anything runs.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <functional>
#include <fstream>
#include <iterator>
#include <thread>
#include <tuple>

#include <sqlite3.h>

#include "../study/study_test_support.hpp"

namespace crevasse {
namespace {

using namespace std::chrono_literals;
namespace fs = std::filesystem;
using test::read_file;
using test::run_cli;

std::string one_value(const fs::path& db, const std::string& sql) {
  const auto rows = test::dump_rows(db, sql);
  return rows.empty() ? std::string() : rows.front();
}

// Waits (up to 60 s) for a .ckpt file in `dir`; returns its path or "".
fs::path wait_for_checkpoint(const fs::path& dir) {
  const auto deadline = std::chrono::steady_clock::now() + 60s;
  while (std::chrono::steady_clock::now() < deadline) {
    std::error_code ec;
    for (const auto& e : fs::directory_iterator(dir, ec))
      if (e.path().extension() == ".ckpt") return e.path();
    std::this_thread::sleep_for(5ms);
  }
  return {};
}

struct Ended {
  int status = 0;
  double seconds = 0.0;  // from the signal to the exit
};

Ended signal_and_wait(pid_t pid, int sig) {
  const auto t0 = std::chrono::steady_clock::now();
  EXPECT_EQ(::kill(pid, sig), 0);
  Ended e;
  ::waitpid(pid, &e.status, 0);
  e.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return e;
}

std::vector<std::string> study_args(const fs::path& dir, const std::string& db) {
  return {"study", (dir / "s.json").string(), "--db", (dir / db).string(), "--jobs", "1",
          "--threads-per-case", "1", "--quiet"};
}

// One case of the tiny glacier whose checkpoints (every 50 ms) appear early.
nlohmann::json checkpointed_study(std::int64_t max_steps) {
  nlohmann::json study = test::tiny_study(2, max_steps, "rel");
  study["sweep"] = {{"cohesion_ratio", {0.3}}};
  study["resources"] = {{"checkpoint_interval_s", 0.05}};
  return study;
}

// Every kind of unusable checkpoint in a case's place (empty, garbage, one flipped byte of a
// real one, a directory, a FIFO) is reported on one warning line, removed, and the case runs
// from t = 0 to the uninterrupted result: exit 0, done, never failed, never blocked. A stop
// (SIGTERM) with the case unfinished leaves it pending with its checkpoint.
TEST(Reliability, UnusableCheckpointIsDroppedAndTheCaseRerunsFromZero) {
  test::ScratchDir dir("rel_ckpt");
  test::write_text(dir / "s.json", checkpointed_study(1500).dump(2));
  ASSERT_EQ(run_cli(dir.path(), "study s.json --db ref.db --jobs 1 --quiet").code, 0);
  const std::string case_id = one_value(dir / "ref.db", "SELECT case_id FROM cases");

  // A real checkpoint, of a long case (another case: foreign to s.json's): the study stopped by
  // SIGTERM once it has one.
  test::write_text(dir / "long.json", checkpointed_study(10000000).dump(2));
  std::vector<std::string> args = study_args(dir.path(), "k.db");
  args[1] = (dir / "long.json").string();
  const pid_t pid = test::spawn_crevasse(args, (dir / "k_err.txt").string());
  ASSERT_GT(pid, 0);
  const fs::path real = wait_for_checkpoint(dir / "k.db.checkpoints");
  ASSERT_FALSE(real.empty());
  const Ended e = signal_and_wait(pid, SIGTERM);
  ASSERT_TRUE(WIFEXITED(e.status)) << "the case ended before it could be stopped; make it longer";
  EXPECT_EQ(WEXITSTATUS(e.status), 143);
  EXPECT_EQ(one_value(dir / "k.db", "SELECT status FROM cases"), "pending") << "a stop failed the case";
  ASSERT_TRUE(fs::is_regular_file(real));
  std::string bytes;
  {
    std::ifstream f(real, std::ios::binary);
    bytes.assign(std::istreambuf_iterator<char>(f), {});
  }
  ASSERT_GT(bytes.size(), 1000u);
  const std::string foreign = bytes;
  bytes[bytes.size() / 2] ^= 0x04;

  const std::vector<std::pair<std::string, std::string>> kinds = {
      {"empty", "truncated or empty"}, {"garbage", "not a crevasse checkpoint"},
      {"flipped", "checksum"},         {"foreign", "written for another scene"},
      {"directory", "not a regular file"}, {"fifo", "not a regular file"}};
  for (const auto& [kind, reason] : kinds) {
    const std::string db = kind + ".db";
    const fs::path ckpt = dir / (db + ".checkpoints") / (case_id + ".ckpt");
    fs::create_directories(ckpt.parent_path());
    if (kind == "empty") test::write_text(ckpt, "");
    if (kind == "garbage") test::write_text(ckpt, std::string(4096, 'g'));
    if (kind == "flipped") std::ofstream(ckpt, std::ios::binary) << bytes;
    if (kind == "foreign") std::ofstream(ckpt, std::ios::binary) << foreign;
    if (kind == "directory") fs::create_directory(ckpt);
    if (kind == "fifo") ASSERT_EQ(::mkfifo(ckpt.c_str(), 0600), 0);
    const test::CliResult r = run_cli(dir.path(), "study s.json --db " + db + " --jobs 1 --quiet");
    EXPECT_EQ(r.code, 0) << kind << ": " << r.err;
    EXPECT_NE(r.err.find("crevasse: warning: "), std::string::npos) << kind << ": " << r.err;
    EXPECT_NE(r.err.find(reason), std::string::npos) << kind << ": " << r.err;
    EXPECT_NE(r.err.find("the case runs from t = 0"), std::string::npos) << kind << ": " << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << kind << ": " << r.err;
    EXPECT_EQ(one_value(dir / db, "SELECT json_extract(run_json, '$.resumed_from_time_s') FROM cases"), "-1.0");
    EXPECT_EQ(test::result_dump(dir / db), test::result_dump(dir / "ref.db")) << kind;
    EXPECT_FALSE(fs::exists(fs::symlink_status(ckpt))) << kind;
  }
}

// A checkpoint that cannot be written (here: a directory where its temporary file goes) warns
// and the case goes on to the uninterrupted result; a regular file where the checkpoint folder
// belongs is refused with exit 2 and its path before any database exists.
TEST(Reliability, FailedCheckpointWriteWarnsAndTheCaseGoesOn) {
  test::ScratchDir dir("rel_ckpt_write");
  test::write_text(dir / "s.json", checkpointed_study(1500).dump(2));
  ASSERT_EQ(run_cli(dir.path(), "study s.json --db ref.db --jobs 1 --quiet").code, 0);
  const std::string case_id = one_value(dir / "ref.db", "SELECT case_id FROM cases");
  fs::create_directories(dir / "k.db.checkpoints" / (case_id + ".ckpt.tmp"));
  const test::CliResult r = run_cli(dir.path(), "study s.json --db k.db --jobs 1 --quiet");
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.err.find("crevasse: warning: "), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("the case goes on without it"), std::string::npos) << r.err;
  EXPECT_EQ(one_value(dir / "k.db", "SELECT status FROM cases"), "done");
  EXPECT_EQ(test::result_dump(dir / "k.db"), test::result_dump(dir / "ref.db"));
  EXPECT_TRUE(fs::is_directory(dir / "k.db.checkpoints" / (case_id + ".ckpt.tmp"))) << "not ours to remove";

  test::write_text(dir / "f.db.checkpoints", "a file");
  const test::CliResult f = run_cli(dir.path(), "study s.json --db f.db --jobs 1 --quiet");
  EXPECT_EQ(f.code, 2) << f.err;
  EXPECT_NE(f.err.find("f.db.checkpoints"), std::string::npos) << f.err;
  EXPECT_NE(f.err.find("checkpoint_interval_s"), std::string::npos) << f.err;
  EXPECT_FALSE(fs::exists(dir / "f.db"));
}

// The settling phase is a phase like the run, on a case whose settling lasts many seconds:
// SIGTERM ends the study within a few seconds with the case pending and a checkpoint written
// while settling; the case time limit fires while settling; the same command then continues
// from the settling checkpoint to the uninterrupted result.
TEST(Reliability, SettlingHonoursSignalsTimeLimitAndCheckpoints) {
  test::ScratchDir dir("rel_settle");
  nlohmann::json study = checkpointed_study(100);
  study["base_scene"]["ice"]["settle_time"] = 500.0;  // about 120,000 steps: 3-6 s
  study["resources"]["checkpoint_interval_s"] = 0.3;
  test::write_text(dir / "s.json", study.dump(2));

  const auto t0 = std::chrono::steady_clock::now();
  ASSERT_EQ(run_cli(dir.path(), "study s.json --db ref.db --jobs 1 --quiet").code, 0);
  const double whole_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  ASSERT_GT(whole_s, 2.5) << "settling is too short to tell; raise settle_time";

  const pid_t pid = test::spawn_crevasse(study_args(dir.path(), "k.db"), (dir / "k_err.txt").string());
  ASSERT_GT(pid, 0);
  ASSERT_FALSE(wait_for_checkpoint(dir / "k.db.checkpoints").empty());
  const Ended e = signal_and_wait(pid, SIGTERM);
  ASSERT_TRUE(WIFEXITED(e.status));
  EXPECT_EQ(WEXITSTATUS(e.status), 143) << read_file(dir / "k_err.txt");
  // The poll is every 0.5 s of wall time; the rest is the checkpoint and closing the session.
  EXPECT_LT(e.seconds, whole_s / 2) << "the signal waited for the settling phase to end";
  EXPECT_EQ(one_value(dir / "k.db", "SELECT status FROM cases"), "pending");

  const test::CliResult limited = run_cli(dir.path(), "study s.json --db t.db --jobs 1 --quiet --case-time-limit 1");
  EXPECT_EQ(limited.code, 1) << limited.err;
  const std::string reason = one_value(dir / "t.db", "SELECT failure_reason FROM cases");
  EXPECT_NE(reason.find("while settling"), std::string::npos) << reason;

  const test::CliResult resumed = run_cli(dir.path(), "study s.json --db k.db --jobs 1 --quiet");
  ASSERT_EQ(resumed.code, 0) << resumed.err;
  EXPECT_GT(std::stod(one_value(dir / "k.db", "SELECT json_extract(run_json, '$.resumed_from_time_s') FROM cases")), 0.0);
  EXPECT_EQ(test::result_dump(dir / "k.db"), test::result_dump(dir / "ref.db"));
}

// Every output path is checked before any work, as input paths are: an output folder that is
// a file, or a file in it that is a folder, is refused with exit 2 and a line naming the
// option and the path, before a case is simulated, a database is created or a file is written.
TEST(Reliability, OutputPathsAreCheckedBeforeAnyWork) {
  test::ScratchDir dir("rel_outputs");
  test::write_text(dir / "s.json", test::tiny_study(2, 200, "outs").dump(2));
  test::write_text(dir / "a_file", "x");
  auto refused = [&](const std::string& args, const std::string& names) {
    const test::CliResult r = run_cli(dir.path(), args);
    EXPECT_EQ(r.code, 2) << args << ": " << r.err;
    EXPECT_NE(r.err.find(names), std::string::npos) << args << ": " << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << args << ": " << r.err;
  };
  refused("study s.json --db v.db --views a_file --quiet", "--views: ");
  refused("study s.json --db v.db --views a_file/sub --quiet", "a_file");
  fs::create_directories(dir / "views" / "case_001_side_view.png");
  refused("study s.json --db v.db --views views --quiet", "case_001_side_view.png");
  EXPECT_FALSE(fs::exists(dir / "v.db")) << "refused, yet the study began";

  fs::create_directories(dir / "run_out" / "run_summary.json");
  test::write_text(dir / "scene.json", test::tiny_scene(200).dump());
  refused("run scene.json --out run_out --quiet", "run_summary.json");
  EXPECT_FALSE(fs::exists(dir / "run_out" / "scene_resolved.json")) << "written before the check";
  refused("run scene.json --out a_file --quiet", "--out: ");

  ASSERT_EQ(run_cli(dir.path(), "study s.json --db s.db --quiet").code, 0);
  fs::create_directories(dir / "csv" / "cases.csv");
  refused("export s.db --csv csv", "cases.csv");
  EXPECT_FALSE(fs::exists(dir / "csv" / "study.csv")) << "some tables written before the refusal";
  refused("export s.db --csv a_file", "--csv: ");
  refused("plot s.db --out a_file", "--out: ");
  refused("accuracy s.db --out a_file", "--out: ");
}

// Exit status of `crevasse ARGS > /dev/full` run in `dir`, and its stderr.
test::CliResult to_full_disk(const fs::path& dir, const std::string& args, const std::string& err = "2> cli_err.txt") {
  const std::string cmd = "cd '" + dir.string() + "' && '" CREVASSE_BINARY "' " + args + " > /dev/full " + err;
  const int status = std::system(cmd.c_str());
  test::CliResult r;
  r.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  r.err = read_file(dir / "cli_err.txt");
  return r;
}

// Lost output is an error: every command that prints its result exits non-zero, saying so,
// when standard output cannot be written (here /dev/full, as on a full disk), and so does one
// whose standard error cannot be written either.
TEST(Reliability, LostOutputIsAnError) {
  if (!fs::exists("/dev/full")) GTEST_SKIP() << "no /dev/full";
  test::ScratchDir dir("rel_lost");
  test::write_text(dir / "s.json", test::tiny_study(3, 200, "lost").dump(2));
  ASSERT_EQ(run_cli(dir.path(), "study s.json --db s.db --quiet").code, 0);
  for (const std::string args : {"status s.db", "status s.db --all", "export s.db --csv csv",
                                 "study s.json --dry-run", "fit s.db --no-store", "--version", "--help"}) {
    const test::CliResult r = to_full_disk(dir.path(), args);
    EXPECT_NE(r.code, 0) << args;
    EXPECT_NE(r.err.find("writing to standard output failed"), std::string::npos) << args << ": " << r.err;
  }
  EXPECT_NE(to_full_disk(dir.path(), "status s.db", "2> /dev/full").code, 0);
  EXPECT_EQ(run_cli(dir.path(), "status s.db").code, 0);
}

// Out of memory is one line and exit 1, never SIGABRT: under address-space limits from "no
// thread can start" to "enough", each run ends with exit 0 or 1 and at most one line, leaves
// no case running (each is pending, failed with its reason, or done) and closes its session;
// the same command without the limit then completes the study to the uninterrupted result.
TEST(Reliability, OutOfMemoryIsOneLineAndLeavesTheStudyResumable) {
  if (test::kSanitized) GTEST_SKIP() << "a sanitizer's shadow memory does not fit under ulimit -v";
  test::ScratchDir dir("rel_oom");
  test::write_text(dir / "s.json", test::tiny_study(2, 300, "oom").dump(2));
  ASSERT_EQ(run_cli(dir.path(), "study s.json --db ref.db --jobs 2 --quiet").code, 0);
  int ran_out = 0;
  for (int kib = 40000; kib <= 84000; kib += 4000) {
    const std::string db = "m" + std::to_string(kib) + ".db";
    const std::string cmd = "cd '" + dir.path().string() + "' && bash -c \"ulimit -v " + std::to_string(kib) +
                            "; exec '" CREVASSE_BINARY "' study s.json --db " + db +
                            " --jobs 2 --quiet\" > /dev/null 2> err.txt";
    const int status = std::system(cmd.c_str());
    ASSERT_TRUE(WIFEXITED(status)) << kib << " KiB: killed by a signal";
    const int code = WEXITSTATUS(status);
    const std::string err = read_file(dir / "err.txt");
    EXPECT_TRUE(code == 0 || code == 1) << kib << " KiB: exit " << code << ": " << err;
    if (code != 0) {
      ++ran_out;
      EXPECT_EQ(err.rfind("crevasse: ", 0), 0u) << kib << " KiB: " << err;
      EXPECT_EQ(std::count(err.begin(), err.end(), '\n'), 1) << kib << " KiB: " << err;
    }
    if (!fs::exists(dir / db)) continue;
    EXPECT_EQ(one_value(dir / db, "SELECT count(*) FROM cases WHERE status = 'running'"), "0") << kib;
    EXPECT_EQ(one_value(dir / db, "SELECT count(*) FROM cases WHERE status = 'failed' AND "
                                  "coalesce(failure_reason, '') = ''"), "0") << kib;
    EXPECT_EQ(one_value(dir / db, "SELECT count(*) FROM sessions WHERE outcome IS NULL"), "0") << kib;
    const test::CliResult again = run_cli(dir.path(), "study s.json --db " + db + " --jobs 2 --retry-failed --quiet");
    EXPECT_EQ(again.code, 0) << kib << ": " << again.err;
    EXPECT_EQ(test::result_dump(dir / db), test::result_dump(dir / "ref.db")) << kib;
  }
  EXPECT_GT(ran_out, 0) << "no limit ran out of memory; lower the first one";
}

// A case that cannot fit is refused before any work: one line saying how much it needs and
// which limit refuses it, exit 1, and its study database with every case pending and no session
// open, to run the same command on a machine (or under a limit) where it fits. Refused here by
// the machine (a case of 3e8 particles) and by the address-space limit (2e6 particles under
// ulimit -v 1 GB); `crevasse run` refuses the same scene before it creates --out.
TEST(Reliability, CaseLargerThanMemoryIsRefusedBeforeItStarts) {
  if (test::kSanitized) GTEST_SKIP() << "a sanitizer's shadow memory does not fit under ulimit -v";
  test::ScratchDir dir("rel_big");
  const auto refused = [&](const std::string& name, double dx, const std::string& limit, const std::string& says) {
    nlohmann::json study = test::tiny_study(2, 200, name);
    study["base_scene"]["numerics"]["dx"] = dx;
    test::write_text(dir / (name + ".json"), study.dump(2));
    const std::string cmd = "cd '" + dir.path().string() + "' && bash -c \"" + limit + "exec '" CREVASSE_BINARY
                            "' study " + name + ".json --db " + name + ".db --jobs 2 --quiet\" > /dev/null 2> err.txt";
    const auto t0 = std::chrono::steady_clock::now();
    const int status = std::system(cmd.c_str());
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    const std::string err = read_file(dir / "err.txt");
    ASSERT_TRUE(WIFEXITED(status)) << name;
    EXPECT_EQ(WEXITSTATUS(status), 1) << name << ": " << err;
    EXPECT_EQ(err.rfind("crevasse: error: case ", 0), 0u) << err;
    EXPECT_NE(err.find("needs about"), std::string::npos) << err;
    EXPECT_NE(err.find(says), std::string::npos) << err;
    EXPECT_NE(err.find("--jobs"), std::string::npos) << err;  // two cases at once
    EXPECT_EQ(std::count(err.begin(), err.end(), '\n'), 1) << err;
    EXPECT_LT(seconds, 20.0) << name << ": the refusal came after work";
    ASSERT_TRUE(fs::exists(dir / (name + ".db"))) << name;
    EXPECT_EQ(one_value(dir / (name + ".db"), "SELECT group_concat(DISTINCT status) FROM cases"), "pending");
    EXPECT_EQ(one_value(dir / (name + ".db"), "SELECT count(*) FROM sessions WHERE outcome IS NULL"), "0");
  };
  refused("machine", 0.01, "", "the machine has");
  refused("ulimit", 0.25, "ulimit -v 1000000; ", "the address-space limit (ulimit -v) leaves");

  nlohmann::json scene = test::tiny_scene();
  scene["numerics"]["dx"] = 0.01;
  test::write_text(dir / "big.json", scene.dump(2));
  const test::CliResult r = run_cli(dir.path(), "run big.json --out out --quiet");
  EXPECT_EQ(r.code, 1) << r.err;
  EXPECT_EQ(r.err.rfind("crevasse: error: the scene needs about", 0), 0u) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_FALSE(fs::exists(dir / "out"));
}

std::string bytes_of(const fs::path& p) {
  std::ifstream f(p, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(f), {});
}

// Foreign files stay untouched: an SQLite database of another program is refused by every
// command that writes a study database (study --db, merge's OUT), with exit 2 and its path,
// before anything writes to it (no WAL switch, no -wal or -shm), whatever its user_version,
// and so is a file that is not SQLite at all.
TEST(Reliability, ForeignDatabasesAreRefusedUntouched) {
  test::ScratchDir dir("rel_foreign");
  test::write_text(dir / "s.json", test::tiny_study(2, 100, "foreign").dump(2));
  ASSERT_EQ(run_cli(dir.path(), "study s.json --db in.db --quiet").code, 0);
  const std::vector<std::pair<std::string, std::string>> foreign = {
      {"v0.db", "CREATE TABLE notes(x); PRAGMA user_version = 0;"},
      {"v1.db", "CREATE TABLE notes(x); PRAGMA user_version = 1;"},
      {"v2.db", "CREATE TABLE cases(x); CREATE TABLE study(y); PRAGMA user_version = 2;"},
      {"v7.db", "CREATE TABLE notes(x); PRAGMA user_version = 7;"},
      {"empty_v5.db", "PRAGMA user_version = 5;"},
  };
  std::vector<std::string> names;
  for (const auto& [name, sql] : foreign) {
    sqlite3* db = nullptr;
    ASSERT_EQ(sqlite3_open((dir / name).c_str(), &db), SQLITE_OK);
    ASSERT_EQ(sqlite3_exec(db, sql.c_str(), nullptr, nullptr, nullptr), SQLITE_OK) << name;
    sqlite3_close(db);
    names.push_back(name);
  }
  test::write_text(dir / "text.db", std::string(2048, 't'));
  names.push_back("text.db");
  for (const std::string& name : names) {
    const std::string before = bytes_of(dir / name);
    for (const std::string args : {"study s.json --quiet --db " + name, "merge " + name + " in.db"}) {
      const test::CliResult r = run_cli(dir.path(), args);
      EXPECT_EQ(r.code, 2) << args << ": " << r.err;
      EXPECT_NE(r.err.find(name), std::string::npos) << args << ": " << r.err;
      EXPECT_NE(r.err.find("not a crevasse study database"), std::string::npos) << args << ": " << r.err;
      EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << args << ": " << r.err;
      EXPECT_EQ(bytes_of(dir / name), before) << args << ": the file changed";
      EXPECT_FALSE(fs::exists(dir / (name + "-wal"))) << args;
      EXPECT_FALSE(fs::exists(dir / (name + "-shm"))) << args;
    }
  }
}

// A refused --db leaves no file under a resource failure: with the file-size limit at zero
// (as on a full disk) a new database cannot be begun, and neither it nor its -wal is left.
TEST(Reliability, RefusedDatabaseLeavesNoFile) {
  test::ScratchDir dir("rel_refused_db");
  test::write_text(dir / "s.json", test::tiny_study(2, 100, "refused").dump(2));
  const std::string cmd = "cd '" + dir.path().string() +
                          "' && bash -c \"trap '' XFSZ; ulimit -f 0; exec '" CREVASSE_BINARY
                          "' study s.json --db new/k.db --quiet\" 2> /dev/null";
  const int status = std::system(cmd.c_str());
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 1);  // the disk, not the input (the message cannot reach err.txt: it is a file, too)
  EXPECT_FALSE(fs::exists(dir / "new")) << "a refused --db left files behind";
}

void sql(const fs::path& db, const std::string& statement) {
  sqlite3* h = nullptr;
  ASSERT_EQ(sqlite3_open(db.c_str(), &h), SQLITE_OK);
  char* err = nullptr;
  EXPECT_EQ(sqlite3_exec(h, statement.c_str(), nullptr, nullptr, &err), SQLITE_OK) << (err ? err : "");
  sqlite3_free(err);
  sqlite3_close(h);
}

// Inconsistent databases are reported, not read as data: a fits value that is text or infinite,
// a fits level outside (0.5, 1), a done case without its summaries row and a summaries value
// that is text each make every command that reads them refuse with exit 2 and one line naming
// the row and the column; and a --level that rounds to 1 is refused before anything is fitted.
TEST(Reliability, InconsistentDatabasesAreReportedNotReadAsData) {
  test::ScratchDir dir("rel_inconsistent");
  test::write_text(dir / "s.json", test::tiny_study(3, 200, "incons").dump(2));
  ASSERT_EQ(run_cli(dir.path(), "study s.json --db s.db --quiet").code, 0);
  ASSERT_EQ(run_cli(dir.path(), "fit s.db").code, 0);
  auto refused = [&](const std::string& args, const std::string& names) {
    const test::CliResult r = run_cli(dir.path(), args);
    EXPECT_EQ(r.code, 2) << args << ": " << r.err;
    EXPECT_NE(r.err.find(names), std::string::npos) << args << ": " << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << args << ": " << r.err;
  };
  const std::string predict = "predict --db s.db --cohesion 100000 --thickness 100";
  for (const std::string level : {"0.9999999999999999", "0.99999"}) {
    refused("fit s.db --level " + level, "rounds to 1");
    refused(predict + " --level " + level, "rounds to 1");
  }

  fs::copy_file(dir / "s.db", dir / "good.db");
  sql(dir / "s.db", "UPDATE fits SET exponent = 'abc' WHERE rowid = (SELECT min(rowid) FROM fits)");
  refused(predict, "column exponent holds 'abc'");
  refused("plot s.db --out plots", "column exponent holds 'abc'");
  sql(dir / "s.db", "UPDATE fits SET exponent = NULL, exponent_lo = 9e999");
  refused(predict, "column exponent_lo holds 'Inf'");
  sql(dir / "s.db", "UPDATE fits SET exponent_lo = NULL, level = 1");
  refused(predict, "level 1.0 is outside (0.5, 1)");

  fs::copy_file(dir / "good.db", dir / "s.db", fs::copy_options::overwrite_existing);
  sql(dir / "s.db", "UPDATE summaries SET spacing_count = 'many' WHERE rowid = (SELECT min(rowid) FROM summaries)");
  refused("fit s.db --no-store", "summaries.spacing_count holds 'many'");
  sql(dir / "s.db", "DELETE FROM summaries WHERE rowid = (SELECT min(rowid) FROM summaries)");
  refused("fit s.db --no-store", "is done but has no summaries row");
  refused("plot s.db --out plots", "is done but has no summaries row");
  EXPECT_FALSE(fs::exists(dir / "plots"));
}

// Starts crevasse with `args` in `dir`, SIGKILLs it after `delay`, and waits for it; true when
// the kill landed (the command had not finished).
bool kill_after(const fs::path& dir, std::vector<std::string> args, std::chrono::microseconds delay) {
  for (auto& a : args)
    if (a.find('/') == std::string::npos && (a.ends_with(".db") || a == "csv" || a == "plots")) a = (dir / a).string();
  const pid_t pid = test::spawn_crevasse(args, (dir / "killed_err.txt").string());
  EXPECT_GT(pid, 0);
  std::this_thread::sleep_for(delay);
  ::kill(pid, SIGKILL);
  int status = 0;
  ::waitpid(pid, &status, 0);
  return WIFSIGNALED(status);
}

double seconds_of(const std::function<void()>& f) {
  const auto t0 = std::chrono::steady_clock::now();
  f();
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

void remove_db(const fs::path& db) {
  for (const char* suffix : {"", "-wal", "-shm"}) fs::remove(db.string() + suffix);
}

// Files appear whole or not at all: SIGKILL at spread-out moments of fit, export, plot and
// merge (24 that land, about 6 each) leaves every file either as it was or whole as an uninterrupted run writes it,
// a fits table with the old rows or all the new ones, and no OUT or the whole merge; a retried
// merge then completes.
TEST(Reliability, KillsDuringFitExportPlotAndMergeLeaveOldOrWholeNew) {
  test::ScratchDir dir("rel_kills");
  test::write_text(dir / "s.json", test::tiny_study(6, 300, "kills").dump(2));
  ASSERT_EQ(run_cli(dir.path(), "study s.json --db s.db --quiet").code, 0);
  ASSERT_EQ(run_cli(dir.path(), "fit s.db --group all --level 0.9").code, 0);
  fs::copy_file(dir / "s.db", dir / "old.db");
  fs::copy_file(dir / "s.db", dir / "new.db");
  const std::string fits = "SELECT quantity, group_name, model, regime, status, level, exponent FROM fits ORDER BY 1, 2, 3, 4";
  const double fit_s = seconds_of([&] { ASSERT_EQ(run_cli(dir.path(), "fit new.db --group all --level 0.8").code, 0); });
  const auto old_rows = test::dump_rows(dir / "old.db", fits), new_rows = test::dump_rows(dir / "new.db", fits);
  ASSERT_NE(old_rows, new_rows);
  const double export_s = seconds_of([&] { ASSERT_EQ(run_cli(dir.path(), "export s.db --csv ref_csv").code, 0); });
  const double plot_s = seconds_of([&] { ASSERT_EQ(run_cli(dir.path(), "plot s.db --out ref_plots").code, 0); });
  const double merge_s = seconds_of([&] { ASSERT_EQ(run_cli(dir.path(), "merge ref_m.db s.db").code, 0); });
  // A file of `got` is either "old" (as placed before the kill) or the reference's bytes.
  auto old_or_whole = [&](const fs::path& got, const fs::path& ref) {
    for (const auto& e : fs::directory_iterator(ref)) {
      const fs::path f = got / e.path().filename();
      if (!fs::exists(f)) continue;
      const std::string bytes = bytes_of(f);
      EXPECT_TRUE(bytes == "old" || bytes == bytes_of(e.path())) << f << ": a partial file";
    }
  };
  auto place_old = [&](const fs::path& got, const fs::path& ref) {
    fs::create_directories(got);
    for (const auto& e : fs::directory_iterator(ref)) test::write_text(got / e.path().filename(), "old");
  };
  // Kills spread over the first 80 % of each command's run; on a loaded machine a command may
  // end before its kill, so rounds go on until 24 kills have landed (at most 16 rounds).
  constexpr int kSpread = 6;
  int landed = 0;
  for (int k = 0; k < 16 && landed < 24; ++k) {
    const auto at = [&](double whole_s) {
      return std::chrono::microseconds(static_cast<long>(0.8e6 * whole_s * (k % kSpread + 0.5) / kSpread));
    };
    remove_db(dir / "s.db");
    fs::copy_file(dir / "old.db", dir / "s.db");
    landed += kill_after(dir.path(), {"fit", "s.db", "--group", "all", "--level", "0.8"}, at(fit_s));
    EXPECT_EQ(test::pragma_integrity(dir / "s.db"), "ok");
    const auto rows = test::dump_rows(dir / "s.db", fits);
    EXPECT_TRUE(rows == old_rows || rows == new_rows) << "fit killed at kill " << k << ": a mix of rows";

    place_old(dir / "csv", dir / "ref_csv");
    landed += kill_after(dir.path(), {"export", "old.db", "--csv", "csv"}, at(export_s));
    old_or_whole(dir / "csv", dir / "ref_csv");

    place_old(dir / "plots", dir / "ref_plots");
    landed += kill_after(dir.path(), {"plot", "old.db", "--out", "plots"}, at(plot_s));
    old_or_whole(dir / "plots", dir / "ref_plots");

    remove_db(dir / "m.db");
    landed += kill_after(dir.path(), {"merge", "m.db", "old.db"}, at(merge_s));
    if (fs::exists(dir / "m.db")) {
      EXPECT_EQ(test::pragma_integrity(dir / "m.db"), "ok");
      EXPECT_EQ(test::result_dump(dir / "m.db"), test::result_dump(dir / "ref_m.db")) << "a partial OUT";
    }
    const test::CliResult retry = run_cli(dir.path(), "merge m.db old.db");
    EXPECT_EQ(retry.code, 0) << retry.err;
    EXPECT_EQ(test::result_dump(dir / "m.db"), test::result_dump(dir / "ref_m.db"));
  }
  EXPECT_GE(landed, 20) << "the commands ended before their kills";
  // Killed writers' temporary files are removed by the next writer of the same file.
  ASSERT_EQ(run_cli(dir.path(), "export old.db --csv csv").code, 0);
  for (const auto& e : fs::directory_iterator(dir / "csv"))
    EXPECT_NE(e.path().filename().string().front(), '.') << e.path() << " left behind";
}

// A command killed between the probe of its output folder and the probe's removal leaves the
// probe file; the next command writing there removes it.
TEST(Reliability, AProbeLeftByAKilledCommandIsClearedByTheNext) {
  test::ScratchDir dir("rel_probe");
  test::write_text(dir / "s.json", test::tiny_study(2, 300, "probe").dump(2));
  ASSERT_EQ(run_cli(dir.path(), "study s.json --db s.db --quiet").code, 0);
  fs::create_directories(dir / "csv");
  test::write_text(dir / "csv" / ".crevasse-probe-AbC123", "");
  ASSERT_EQ(run_cli(dir.path(), "export s.db --csv csv").code, 0);
  EXPECT_FALSE(fs::exists(dir / "csv" / ".crevasse-probe-AbC123"));
}

// A full disk (here a file-size limit of 4 KiB, with SIGXFSZ ignored) midway through export or
// plot leaves each file as it was or whole, never truncated, and the command exits non-zero.
TEST(Reliability, FullDiskLeavesOldOrWholeFiles) {
  test::ScratchDir dir("rel_full_files");
  test::write_text(dir / "s.json", test::tiny_study(6, 300, "fullfiles").dump(2));
  ASSERT_EQ(run_cli(dir.path(), "study s.json --db s.db --quiet").code, 0);
  ASSERT_EQ(run_cli(dir.path(), "export s.db --csv ref_csv").code, 0);
  ASSERT_EQ(run_cli(dir.path(), "plot s.db --out ref_plots").code, 0);
  for (const auto& [args, out, ref] : std::vector<std::tuple<std::string, std::string, std::string>>{
           {"export s.db --csv csv", "csv", "ref_csv"}, {"plot s.db --out plots", "plots", "ref_plots"}}) {
    fs::create_directories(dir / out);
    for (const auto& e : fs::directory_iterator(dir / ref)) test::write_text(dir / out / e.path().filename(), "old");
    const std::string cmd = "cd '" + dir.path().string() + "' && bash -c \"trap '' XFSZ; ulimit -f 4; exec '" CREVASSE_BINARY
                            "' " + args + "\" > /dev/null 2>&1";
    const int status = std::system(cmd.c_str());
    EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) != 0) << args << ": the limit did not bite";
    for (const auto& e : fs::directory_iterator(dir / ref)) {
      const std::string bytes = bytes_of(dir / out / e.path().filename());
      EXPECT_TRUE(bytes == "old" || bytes == bytes_of(e.path())) << args << ": " << e.path().filename() << " is partial";
    }
  }
}

// The files of `crevasse run` are whole or absent too: under a 4 KiB file-size limit the run
// fails at its first snapshot, and every file of a complete run's folder (VTU snapshots, the
// PVD, the JSON and CSV files, the side views) is either the old one or the new one whole.
TEST(Reliability, RunOutputsAreOldOrWhole) {
  test::ScratchDir dir("rel_run_files");
  nlohmann::json scene = test::tiny_scene(200);
  scene["output"]["vtu_interval"] = 0.2;
  scene["output"]["png"] = true;
  test::write_text(dir / "scene.json", scene.dump(2));
  ASSERT_EQ(run_cli(dir.path(), "run scene.json --out ref --threads 1 --quiet").code, 0);
  std::vector<fs::path> files;
  for (const auto& e : fs::recursive_directory_iterator(dir / "ref"))
    if (e.is_regular_file()) files.push_back(fs::relative(e.path(), dir / "ref"));
  ASSERT_GE(files.size(), 5u);
  for (const fs::path& f : files) {
    fs::create_directories((dir / "out" / f).parent_path());
    test::write_text(dir / "out" / f, "old");
  }
  const std::string cmd = "cd '" + dir.path().string() + "' && bash -c \"trap '' XFSZ; ulimit -f 4; exec '" CREVASSE_BINARY
                          "' run scene.json --out out --threads 1 --quiet\" > /dev/null 2>&1";
  const int status = std::system(cmd.c_str());
  EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) != 0) << "the limit did not bite";
  for (const fs::path& f : files) {
    const std::string bytes = bytes_of(dir / "out" / f);
    if (f == "run_summary.json") {  // holds wall times: whole means it parses
      EXPECT_TRUE(bytes == "old" || nlohmann::json::accept(bytes)) << f << " is partial";
      continue;
    }
    EXPECT_TRUE(bytes == "old" || bytes == bytes_of(dir / "ref" / f)) << f << " is partial";
  }
  for (const auto& e : fs::recursive_directory_iterator(dir / "out"))
    EXPECT_EQ(e.path().filename().string().find(".tmp-"), std::string::npos) << e.path() << " left behind";
}

// Two merges into one new OUT: both succeed (the second waits for the first's lock and then
// merges into the OUT the first made), in every round.
TEST(Reliability, ConcurrentMergesIntoOneNewOutBothSucceed) {
  test::ScratchDir dir("rel_merge_race");
  nlohmann::json study = test::tiny_study(4, 100, "race");
  test::write_text(dir / "s.json", study.dump(2));
  ASSERT_EQ(run_cli(dir.path(), "study s.json --db a.db --shard 0/2 --quiet").code, 0);
  ASSERT_EQ(run_cli(dir.path(), "study s.json --db b.db --shard 1/2 --quiet").code, 0);
  for (int round = 0; round < 5; ++round) {
    remove_db(dir / "m.db");
    const pid_t a = test::spawn_crevasse({"merge", (dir / "m.db").string(), (dir / "a.db").string()}, (dir / "a_err.txt").string());
    const pid_t b = test::spawn_crevasse({"merge", (dir / "m.db").string(), (dir / "b.db").string()}, (dir / "b_err.txt").string());
    int sa = 0, sb = 0;
    ::waitpid(a, &sa, 0);
    ::waitpid(b, &sb, 0);
    EXPECT_TRUE(WIFEXITED(sa) && WEXITSTATUS(sa) == 0) << read_file(dir / "a_err.txt");
    EXPECT_TRUE(WIFEXITED(sb) && WEXITSTATUS(sb) == 0) << read_file(dir / "b_err.txt");
    EXPECT_EQ(one_value(dir / "m.db", "SELECT count(*) FROM cases WHERE status = 'done'"), "4") << round;
  }
}

}  // namespace
}  // namespace crevasse
