// Classes of hostile input that once crashed, hung, bypassed the one-writer lock or wrote on
// refusal (docs/reliability.md, "Guarantees"): each test tries several members of its class.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <fstream>
#include <set>
#include <thread>

#include "engine/json_input.hpp"
#include "study/store.hpp"
#include "../study/study_test_support.hpp"

namespace crevasse {
namespace {

namespace fs = std::filesystem;
using namespace std::chrono_literals;
using test::run_cli;

std::string nested(int levels, const std::string& inner = "") {
  return std::string(levels, '[') + inner + std::string(levels, ']');
}

std::set<std::string> listing(const fs::path& dir) {
  std::set<std::string> names;
  for (const auto& e : fs::recursive_directory_iterator(dir))
    if (e.path().filename() != "cli_out.txt" && e.path().filename() != "cli_err.txt")
      names.insert(fs::relative(e.path(), dir).string());
  return names;
}

void expect_refusal(const test::CliResult& r, const std::string& text) {
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_NE(r.err.find(text), std::string::npos) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
}

// A finished tiny study in dir/name.db.
void tiny_db(const fs::path& dir, const std::string& name, int cases = 2) {
  test::write_text(dir / (name + ".json"), test::tiny_study(cases, 20, name).dump());
  const auto r = run_cli(dir, "study " + name + ".json --db " + name + ".db --quiet");
  ASSERT_EQ(r.code, 0) << r.err;
}

TEST(HostileInputs, DeepNestingIsRefusedByEveryLoader) {
  test::ScratchDir dir("hostile");
  const std::string deep = nested(100000);
  test::write_text(dir / "scene.json", "{\"dim\": " + deep + "}");
  expect_refusal(run_cli(dir.path(), "run scene.json --out o"), "nested deeper than 64");
  EXPECT_FALSE(fs::exists(dir / "o"));
  for (const char* key : {"fixed", "sweep", "replicas", "measurement", "resources"}) {
    nlohmann::json j = test::tiny_study(2);
    std::string text = j.dump();
    text.insert(text.size() - 1, std::string(",\"") + key + "\":" + deep);
    j.erase(key);
    test::write_text(dir / "s.json", text);
    expect_refusal(run_cli(dir.path(), "study s.json --db s.db"), "nested deeper than 64");
  }
  nlohmann::json inline_scene = test::tiny_study(2);
  std::string text = inline_scene.dump();
  const auto at = text.find("\"base_scene\":{") + 14;
  text.insert(at, "\"deep\":" + deep + ",");
  test::write_text(dir / "s.json", text);
  expect_refusal(run_cli(dir.path(), "study s.json --db s.db"), "nested deeper than 64");
  test::write_text(dir / "obs.json", "{\"observations\": " + deep + "}");
  tiny_db(dir.path(), "t");
  expect_refusal(run_cli(dir.path(), "calibrate --db t.db --observations obs.json"),
                 "nested deeper than 64");
  EXPECT_FALSE(fs::exists(dir / "s.db"));

  // JSON the database holds: a deep scene_json is skipped by export, refused by accuracy.
  {
    Store writer = Store::open_writer(dir / "t.db", 0.0);
    writer.exec("UPDATE cases SET scene_json = '" + nested(200000) + "', axes_json = '" +
                nested(200000) + "'");
  }
  EXPECT_EQ(run_cli(dir.path(), "export t.db --csv csv").code, 0);
  const auto acc = run_cli(dir.path(), "accuracy t.db --out acc");
  EXPECT_EQ(acc.code, 2) << acc.err;
  EXPECT_NE(acc.err.find("scene_json"), std::string::npos) << acc.err;
  // The limit itself: 64 levels load, 65 do not.
  EXPECT_NO_THROW(parse_json_input<nlohmann::json>(nested(64), "t"));
  EXPECT_THROW(parse_json_input<nlohmann::json>(nested(65), "t"), InputError);
  EXPECT_NO_THROW(parse_json_input<nlohmann::json>("[\"" + std::string(100, '[') + "\"]", "t"))
      << "brackets inside strings do not count";
}

TEST(HostileInputs, DuplicateKeysNulBytesAndEscapesAreRefused) {
  test::ScratchDir dir("hostile");
  test::write_text(dir / "dup.json", R"({"dim": 2, "dim": 3})");
  expect_refusal(run_cli(dir.path(), "run dup.json --out o"), "\"dim\" appears twice");
  nlohmann::json j = test::tiny_study(2);
  std::string text = j.dump();
  text.insert(text.size() - 1, ",\"name\":\"other\"");
  test::write_text(dir / "s.json", text);
  expect_refusal(run_cli(dir.path(), "study s.json --db s.db"), "\"name\" appears twice");
  // A duplicate nested in an object inside an array is found too.
  EXPECT_THROW(parse_json_input<nlohmann::json>(R"({"a": [{"b": 1, "b": 2}]})", "t"), InputError);
  EXPECT_NO_THROW(parse_json_input<nlohmann::json>(R"({"a": [{"b": 1}, {"b": 2}]})", "t"));
  {
    std::ofstream f(dir / "nul.json", std::ios::binary);
    f << j.dump() << '\0' << "{\"anything\": 1}";
  }
  expect_refusal(run_cli(dir.path(), "study nul.json --db s.db"), "NUL byte");
  // Escapes and megabytes echoed from a key come out as one short printable line.
  test::write_text(dir / "esc.json", "{\"dim\": 2, \"\\u001b[31m" + std::string(3000000, 'k') + "\": 1}");
  const auto esc = run_cli(dir.path(), "run esc.json --out o");
  EXPECT_EQ(esc.code, 2);
  EXPECT_EQ(esc.err.find('\x1b'), std::string::npos);
  EXPECT_LT(esc.err.size(), 1000u);
  EXPECT_FALSE(fs::exists(dir / "s.db"));
}

TEST(HostileInputs, NonRegularFilesAreRefusedWithoutBlocking) {
  test::ScratchDir dir("hostile");
  tiny_db(dir.path(), "t");
  ASSERT_EQ(::mkfifo((dir / "f.db").c_str(), 0644), 0);
  // Each of these blocked forever on the FIFO (the test's timeout is the failure).
  for (const std::string cmd :
       {"status f.db", "export f.db --csv c", "fit f.db", "plot f.db --out p",
        "plot t.db --out p --add-cases f.db", "merge out.db f.db", "accuracy f.db --out a",
        "calibrate --db f.db --spacing 100"})
    expect_refusal(run_cli(dir.path(), cmd), "not a regular file");
  expect_refusal(run_cli(dir.path(), "study t.json --db f.db"), "not a regular file");
  expect_refusal(run_cli(dir.path(), "study t.json --db /dev/null"), "not a regular file");
  for (const char* gone : {"c", "p", "a", "out.db", "f.db.lock", "f.db-wal"})
    EXPECT_FALSE(fs::exists(dir / gone)) << gone;
  EXPECT_FALSE(fs::exists("/dev/null-wal"));
}

TEST(HostileInputs, TheWriterLockFollowsTheFileNotItsPath) {
  test::ScratchDir dir("hostile");
  fs::create_directories(dir / "sub");
  Store first = Store::open_writer(dir / "c.db", 0.0);
  fs::create_symlink("../c.db", dir / "sub" / "a.db");
  fs::create_hard_link(dir / "c.db", dir / "hard.db");
  for (const fs::path& other : {dir / "sub" / "a.db", dir / "hard.db", dir / "sub" / ".." / "c.db"})
    EXPECT_THROW(Store::open_writer(other, 0.0), ResourceError) << other;
  EXPECT_FALSE(fs::exists(dir / "c.db.lock"));
  EXPECT_TRUE(fs::exists(dir / "c.db")) << "a refused writer removed the holder's new database";
}

TEST(HostileInputs, ARefusedCommandLeavesTheFileSystemAsItFoundIt) {
  test::ScratchDir dir("hostile");
  tiny_db(dir.path(), "a");
  tiny_db(dir.path(), "b", 3);
  const std::set<std::string> before = listing(dir.path());
  const std::string a_bytes = test::read_file(dir / "a.db");

  expect_refusal(run_cli(dir.path(), "merge out.db a.db b.db"), "another study");
  expect_refusal(run_cli(dir.path(), "study b.json --db a.db"), "holds study");
  expect_refusal(run_cli(dir.path(), "plot a.db --out figs --add-cases missing.db"), "no such");
  expect_refusal(run_cli(dir.path(), "study b.json --db new/dir/x.db --shard 9/2"), "shard");
  {
    Store writer = Store::open_writer(dir / "a.db", 0.0);
    const auto r = run_cli(dir.path(), "study a.json --db a.db --quiet");
    EXPECT_EQ(r.code, 1) << r.err;  // busy, not bad input
  }
  for (const std::string cmd : {"status a.db", "export a.db --csv csv", "plot a.db --out figs2",
                                "fit a.db --no-store"})
    EXPECT_EQ(run_cli(dir.path(), cmd).code, 0) << cmd;
  fs::remove_all(dir / "csv");
  fs::remove_all(dir / "figs2");
  EXPECT_EQ(listing(dir.path()), before) << "no -wal, -shm, .lock, out.db or figs left";
  EXPECT_EQ(test::read_file(dir / "a.db"), a_bytes) << "the refused study wrote to a.db";
}

TEST(HostileInputs, AmbiguousOrOutOfRangeValuesAreRefusedNamingTheField) {
  test::ScratchDir dir("hostile");
  nlohmann::json scene = test::tiny_scene(20);
  scene["effects"] = {"gravity", "drive", "basal_friction", "plasticity", "softening", "outflow"};
  scene["ice"]["softening"] = {{"zeta", 300.0}, {"fracture_energy", 50.0}};
  test::write_text(dir / "both.json", scene.dump());
  expect_refusal(run_cli(dir.path(), "run both.json --out o"), "ice.softening.fracture_energy");
  // ζ and G that agree (as scene_to_json writes them) are one source, accepted.
  scene["ice"]["softening"] = {{"fracture_energy", 50.0}};
  test::write_text(dir / "g.json", scene.dump());
  ASSERT_EQ(run_cli(dir.path(), "run g.json --out g --quiet").code, 0);
  EXPECT_EQ(run_cli(dir.path(), "run g/scene_resolved.json --out g2 --quiet").code, 0);

  nlohmann::json boxes = test::tiny_scene(20);
  boxes["effects"].push_back("velocity_boundaries");
  boxes["velocity_boxes"] = nlohmann::json::array();
  for (int i = 0; i < 1001; ++i)
    boxes["velocity_boxes"].push_back({{"min", {0.0, 0.0}}, {"max", {1.0, 1.0}}, {"velocity", {0.0, 0.0}}});
  test::write_text(dir / "boxes.json", boxes.dump());
  expect_refusal(run_cli(dir.path(), "run boxes.json --out b"), "velocity_boxes");

  for (const char* name : {"..", ".", ".hidden"}) {
    nlohmann::json j = test::tiny_study(2, 20, name);
    test::write_text(dir / "n.json", j.dump());
    expect_refusal(run_cli(dir.path(), "study n.json --dry-run"), "name");
  }
  tiny_db(dir.path(), "t", 4);
  for (const char* fixed : {"1e308,free", "free,-101"})
    expect_refusal(run_cli(dir.path(), std::string("fit t.db --fixed-exponents ") + fixed),
                   "--fixed-exponents");
  const auto warned = run_cli(dir.path(), "study t.json --db t.db --threads-per-case 1024 --quiet");
  EXPECT_EQ(warned.code, 0) << warned.err;
  EXPECT_NE(warned.err.find("warning: 1024 engine threads per case"), std::string::npos)
      << warned.err;
}

TEST(HostileInputs, MessagesBlameTheRightFileAndCiteOnlyOptionsTheCommandHas) {
  test::ScratchDir dir("hostile");
  tiny_db(dir.path(), "t");
  test::write_text(dir / "corrupt.db", std::string(8192, 'x'));
  const auto merged = run_cli(dir.path(), "merge out.db corrupt.db");
  expect_refusal(merged, "corrupt.db");
  EXPECT_EQ(merged.err.find("out.db"), std::string::npos) << merged.err;
  EXPECT_FALSE(fs::exists(dir / "out.db"));
  expect_refusal(run_cli(dir.path(), "export corrupt.db --csv cc"), "corrupt.db");
  EXPECT_FALSE(fs::exists(dir / "cc")) << "a refused export leaves no partial CSV folder";
  Store writer = Store::open_writer(dir / "t.db", 0.0);
  for (const std::string cmd : {"fit t.db", "merge t.db t.db"}) {
    const auto r = run_cli(dir.path(), cmd);
    EXPECT_NE(r.code, 0) << cmd;
    EXPECT_EQ(r.err.find("--db"), std::string::npos) << cmd << ": " << r.err;
  }
}

TEST(HostileInputs, CtrlCCheckpointsTheRunningCaseAndTheSameCommandResumesIt) {
  test::ScratchDir dir("hostile");
  nlohmann::json study = test::tiny_study(2, 400000, "sig");
  study["sweep"] = {{"cohesion_ratio", {0.3}}};
  test::write_text(dir / "s.json", study.dump(2));
  for (const int sig : {SIGINT, SIGTERM, SIGHUP}) {
    SCOPED_TRACE(sig);
    fs::remove_all(dir / "k.db.checkpoints");
    fs::remove(dir / "k.db");
    const std::vector<std::string> args = {"study", (dir / "s.json").string(), "--db",
                                           (dir / "k.db").string(), "--jobs", "1", "--quiet"};
    const pid_t pid = test::spawn_crevasse(args, (dir / "err.txt").string());
    ASSERT_GT(pid, 0);
    const auto deadline = std::chrono::steady_clock::now() + 30s;
    const auto running = [&] {
      try {
        return test::dump_rows(dir / "k.db",
                               "SELECT count(*) FROM cases WHERE status = 'running'") ==
               std::vector<std::string>{"1"};
      } catch (const std::exception&) {
        return false;  // not created yet
      }
    };
    while (!running() && std::chrono::steady_clock::now() < deadline)
      std::this_thread::sleep_for(20ms);
    std::this_thread::sleep_for(300ms);
    ASSERT_EQ(::kill(pid, sig), 0);
    int status = 0;
    ::waitpid(pid, &status, 0);
    ASSERT_TRUE(WIFEXITED(status)) << "killed by the signal instead of stopping";
    EXPECT_EQ(WEXITSTATUS(status), 128 + sig);
    EXPECT_NE(test::read_file(dir / "err.txt").find("checkpoint"), std::string::npos);
    EXPECT_EQ(test::dump_rows(dir / "k.db", "SELECT status FROM cases").at(0), "pending");
    EXPECT_EQ(test::dump_rows(dir / "k.db", "SELECT outcome FROM sessions").at(0), "stopped");
    std::size_t checkpoints = 0;
    for (const auto& e : fs::directory_iterator(dir / "k.db.checkpoints"))
      checkpoints += e.path().extension() == ".ckpt";
    EXPECT_EQ(checkpoints, 1u);
  }
  const auto resumed = run_cli(dir.path(), "study s.json --db k.db --jobs 1 --quiet");
  ASSERT_EQ(resumed.code, 0) << resumed.err;
  const auto from = test::dump_rows(
      dir / "k.db", "SELECT status, json_extract(run_json, '$.resumed_from_time_s') FROM cases");
  ASSERT_EQ(from.size(), 1u);
  EXPECT_EQ(from[0].substr(0, 5), "done|");
  EXPECT_GT(std::stod(from[0].substr(5)), 0.0) << "the case started again from t = 0";
}

}  // namespace
}  // namespace crevasse
