// Measuring again is as safe as simulating (docs/reliability.md, "Measuring again"): every
// measurement setting is bounded by the run's own scales and the measurement stops for the case's
// clock and signal; a particle file is checked whole; no output of a command is one of its
// inputs; every output is checked before any work; a busy or full database is an error of the
// machine, not of the input; a damaged or stray particle file costs at most its own case.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <iterator>
#include <thread>

#include "../analysis/synthetic_slab.hpp"
#include "study/engine_case.hpp"
#include "../study/study_test_support.hpp"

namespace crevasse {
namespace {

namespace fs = std::filesystem;
using test::run_cli;
using Result = test::CliResult;

std::string slurp(const fs::path& p) {
  std::ifstream f(p, std::ios::binary);
  return std::string((std::istreambuf_iterator<char>(f)), std::istreambuf_iterator<char>());
}

void spill(const fs::path& p, const std::string& bytes) {
  std::ofstream(p, std::ios::binary | std::ios::trunc) << bytes;
}

std::size_t lines(const std::string& s) { return static_cast<std::size_t>(std::count(s.begin(), s.end(), '\n')); }

// `n` tiny cases (one: Π = 0.3).
nlohmann::json tiny_cases(int n, const std::string& name) {
  nlohmann::json study = test::tiny_study(std::max(n, 2), 200, name);
  if (n == 1) study["sweep"] = {{"cohesion_ratio", {0.3}}};
  return study;
}

// A finished study of `n` tiny cases that kept its particles in kept.db.particles/, and
// other.json, the same study measured otherwise.
void kept_study(const test::ScratchDir& dir, int n) {
  test::write_text(dir / "kept.json", tiny_cases(n, "kept").dump(2));
  const Result r = run_cli(dir.path(), "study kept.json --db kept.db --keep-particles --quiet");
  ASSERT_EQ(r.code, 0) << r.err;
  nlohmann::json other = tiny_cases(n, "other");
  other["measurement"] = {{"min_depth_over_dx", 1.0}};
  test::write_text(dir / "other.json", other.dump(2));
}

// Class 1. Settings far from the run's scales are refused with exit 2 and one line naming the
// setting, before anything is simulated or measured: by a study before its database exists, and
// by `measure` before it prints anything. Settings inside the range are measured.
TEST(Remeasure, SettingsOutsideTheRunsScalesAreRefusedBeforeAnyWork) {
  test::ScratchDir dir("remeasure_scales");
  // tiny scene: dx = 10 m, 2 particles per cell axis (spacing 5 m), H_i = 40 m
  for (const auto& [key, value] : std::vector<std::pair<std::string, double>>{
           {"particle_spacing_m", 100.0}, {"ice_thickness_m", 1e5}, {"dx_m", 2.0}}) {
    nlohmann::json study = tiny_cases(1, "scales");
    study["measurement"] = {{key, value}};
    test::write_text(dir / "s.json", study.dump(2));
    const Result r = run_cli(dir.path(), "study s.json --db s.db --quiet");
    EXPECT_EQ(r.code, 2) << key << ": " << r.err;
    EXPECT_NE(r.err.find("measurement." + key), std::string::npos) << r.err;
    EXPECT_EQ(lines(r.err), 1u) << r.err;
    EXPECT_FALSE(fs::exists(dir / "s.db")) << key << ": refused, yet the study began";
  }
  kept_study(dir, 1);
  const std::string file = "kept.db.particles/case_000_particles.bin";
  for (const std::string set : {"particle_spacing_m=1e-9", "ice_thickness_m=9", "dx_m=41",
                                "surface_bridge_half_width_over_h=5"}) {
    const auto t0 = std::chrono::steady_clock::now();
    const Result r = run_cli(dir.path(), "measure " + file + " --set " + set + " --out m");
    const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    EXPECT_EQ(r.code, 2) << set << ": " << r.err;
    EXPECT_NE(r.err.find(set.substr(0, set.find('='))), std::string::npos) << r.err;
    EXPECT_EQ(lines(r.err), 1u) << r.err;
    EXPECT_TRUE(r.out.empty()) << set << ": " << r.out;
    EXPECT_LT(s, 10.0) << set;
  }
  EXPECT_FALSE(fs::exists(dir / "m"));
  // The edges of the range: a quarter and four times the run's cell.
  for (const std::string set : {"dx_m=2.5", "dx_m=40", "ice_thickness_m=160"}) {
    const Result r = run_cli(dir.path(), "measure " + file + " --set " + set);
    EXPECT_EQ(r.code, 0) << set << ": " << r.err;
  }
}

// Class 1. The measurement honours the case's time limit and the stop signal as the run does: a
// case whose limit has passed when its measurement starts fails "while measuring", and one
// stopped by the signal stays pending, instead of measuring to the end.
TEST(Remeasure, MeasurementHonoursTheTimeLimitAndTheStopSignal) {
  test::ScratchDir dir("remeasure_clock");
  test::SlabSpec spec;
  const ParticleSnapshot slab = test::make_slab(spec, {{500.0, 40.0, 10.0}, {900.0, 60.0, 10.0}});
  const Study study = test::parse(tiny_cases(1, "clock"));
  std::atomic<bool> stop{false};
  RunnerOptions o;
  o.db_path = dir / "s.db";
  o.jobs = 1;
  o.threads_per_case = 1;
  o.case_time_limit_s = 0.05;
  o.interrupt = &stop;
  o.case_function = [&](const StudyCase& c, CaseContext& ctx) {
    std::this_thread::sleep_for(std::chrono::milliseconds(100));  // past the limit: a long run
    CaseOutcome out;
    out.stop_reason = "fake";
    measure_final_state(c, ctx, slab, out);
    return out;
  };
  RunnerReport r = run_study(study, o);
  EXPECT_EQ(r.failed, 1u);
  const auto reason = test::dump_rows(o.db_path, "SELECT status, failure_reason FROM cases");
  ASSERT_EQ(reason.size(), 1u);
  EXPECT_NE(reason[0].find("failed|time limit: 0.05 s"), std::string::npos) << reason[0];
  EXPECT_NE(reason[0].find("while measuring"), std::string::npos) << reason[0];

  o.db_path = dir / "t.db";
  o.case_time_limit_s = 0.0;
  o.case_function = [&](const StudyCase& c, CaseContext& ctx) {
    stop.store(true);  // the first SIGTERM, as the handler raises it
    CaseOutcome out;
    out.stop_reason = "fake";
    measure_final_state(c, ctx, slab, out);
    return out;
  };
  r = run_study(study, o);
  EXPECT_EQ(r.done, 0u);
  EXPECT_EQ(r.failed, 0u);
  EXPECT_EQ(test::dump_rows(o.db_path, "SELECT status FROM cases"), std::vector<std::string>{"pending"});
}

// Class 3. No output of a command is one of its inputs, however the path is spelt: a symbolic
// link, a hard link or a path through a linked folder names the same file.
TEST(Remeasure, NoOutputIsAnInput) {
  test::ScratchDir dir("remeasure_overlap");
  kept_study(dir, 1);
  const fs::path particles = dir / "kept.db.particles";
  const std::string kept_bytes = slurp(particles / "case_000_particles.bin");
  fs::create_symlink(particles / "case_000_particles.bin", dir / "link.vtu");
  fs::create_hard_link(dir / "kept.db", dir / "hard.db");
  fs::create_directory_symlink(particles, dir / "alias");
  auto refused = [&](const std::string& args, const std::string& names) {
    const Result r = run_cli(dir.path(), args);
    EXPECT_EQ(r.code, 2) << args << ": " << r.err;
    EXPECT_NE(r.err.find(names), std::string::npos) << args << ": " << r.err;
    EXPECT_EQ(lines(r.err), 1u) << args << ": " << r.err;
    EXPECT_TRUE(r.out.empty()) << args << ": " << r.out;
  };
  refused("measure kept.db.particles/case_000_particles.bin --vtu link.vtu", "--vtu");
  refused("measure kept.db.particles/case_000_particles.bin --vtu alias/case_000_particles.bin", "--vtu");
  refused("study other.json --db hard.db --remeasure kept.db --particles-from kept.db.particles --quiet", "--db");
  refused("study other.json --db new.db --remeasure kept.db --particles-from kept.db.particles --particles-dir alias "
          "--quiet",
          "--particles-dir");
  refused("study other.json --db new.db --remeasure kept.db --particles-from alias --views kept.db.particles --quiet",
          "--views");
  EXPECT_EQ(slurp(particles / "case_000_particles.bin"), kept_bytes);
  EXPECT_FALSE(fs::exists(dir / "new.db"));
  // Its own folder for the new particles is fine.
  const Result ok = run_cli(dir.path(), "study other.json --db new.db --remeasure kept.db --particles-from alias "
                                        "--keep-particles --quiet");
  EXPECT_EQ(ok.code, 0) << ok.err;
  EXPECT_TRUE(fs::exists(dir / "new.db.particles" / "case_000_particles.bin"));
  EXPECT_EQ(slurp(particles / "case_000_particles.bin"), kept_bytes);
}

// Class 4. `measure` checks every output before it reads a particle: a folder it cannot write
// (sysfs refuses even root) is refused with exit 2 before anything is printed or written, and a
// --vtu whose folders do not exist yet gets them.
TEST(Remeasure, MeasureChecksEveryOutputBeforeAnyWork) {
  test::ScratchDir dir("remeasure_outputs");
  kept_study(dir, 1);
  const std::string file = "kept.db.particles/case_000_particles.bin";
  for (const std::string outputs : {"--out m --vtu /sys/x.vtu", "--out /sys/m --vtu v.vtu"}) {
    const Result r = run_cli(dir.path(), "measure " + file + " " + outputs);
    EXPECT_EQ(r.code, 2) << outputs << ": " << r.err;
    EXPECT_NE(r.err.find("/sys"), std::string::npos) << r.err;
    EXPECT_EQ(lines(r.err), 1u) << r.err;
    EXPECT_TRUE(r.out.empty()) << outputs << ": printed before the refusal: " << r.out;
  }
  EXPECT_FALSE(fs::exists(dir / "m"));
  EXPECT_FALSE(fs::exists(dir / "v.vtu"));
  const Result deep = run_cli(dir.path(), "measure " + file + " --vtu a/b/c/x.vtu --out a/b/m");
  EXPECT_EQ(deep.code, 0) << deep.err;
  EXPECT_TRUE(fs::exists(dir / "a/b/c/x.vtu"));
  EXPECT_TRUE(fs::exists(dir / "a/b/m/measurement.json"));
}

// Class 2 and 4. A remeasure whose folder holds a file with one flipped bit in its header, a
// truncated file and a stray file that belongs to no case: the intact case is measured, each
// damaged file fails its own case (exit 1) naming the file and the damage, and the stray file is
// named in a warning.
TEST(Remeasure, ADamagedFileFailsOnlyItsCaseAndAStrayFileIsAWarning) {
  test::ScratchDir dir("remeasure_damage");
  kept_study(dir, 3);
  const fs::path p = dir / "kept.db.particles";
  std::string bytes = slurp(p / "case_001_particles.bin");
  const std::string field = "\"ice_front_x_m\":";
  const std::size_t at = bytes.find(field);
  ASSERT_NE(at, std::string::npos);
  ASSERT_TRUE(std::isdigit(bytes[at + field.size() + 1])) << bytes.substr(at, 40);
  bytes[at + field.size() + 1] ^= 0x01;  // its second digit: valid JSON, another front
  spill(p / "case_001_particles.bin", bytes);
  bytes = slurp(p / "case_002_particles.bin");
  spill(p / "case_002_particles.bin", bytes.substr(0, bytes.size() / 2));
  spill(p / "notes_particles.bin", "not particles\n");
  const Result r = run_cli(dir.path(), "study other.json --db again.db --remeasure kept.db --particles-from "
                                       "kept.db.particles --quiet");
  EXPECT_EQ(r.code, 1) << r.err;
  EXPECT_NE(r.err.find("warning: kept.db.particles/notes_particles.bin"), std::string::npos) << r.err;
  const auto rows = test::dump_rows(dir / "again.db", "SELECT case_index, status, failure_reason FROM cases "
                                                      "ORDER BY case_index");
  ASSERT_EQ(rows.size(), 3u);
  EXPECT_EQ(rows[0], "0|done|NULL");
  EXPECT_NE(rows[1].find("1|failed|"), std::string::npos) << rows[1];
  EXPECT_NE(rows[1].find("case_001_particles.bin: damaged particle file"), std::string::npos) << rows[1];
  EXPECT_NE(rows[2].find("2|failed|"), std::string::npos) << rows[2];
  EXPECT_NE(rows[2].find("case_002_particles.bin: truncated"), std::string::npos) << rows[2];
}

// Class 4. A busy database (another crevasse process writes it) and a full disk are errors of the
// machine: one line naming the database and the remedy, exit 1, never the 2 of bad input.
TEST(Remeasure, BusyAndFullDatabasesAreOneLineWithThePathAndTheRemedy) {
  test::ScratchDir dir("remeasure_busy");
  test::write_text(dir / "s.json", test::tiny_study(2, 200, "busy").dump(2));
  ASSERT_EQ(run_cli(dir.path(), "study s.json --db s.db --quiet").code, 0);
  {
    Store writer = Store::open_writer(dir / "s.db");  // another study writing it (waited for 10 s)
    const Result r = run_cli(dir.path(), "study s.json --db s.db --quiet");
    EXPECT_EQ(r.code, 1) << r.err;
    EXPECT_NE(r.err.find("s.db"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("run the same command again"), std::string::npos) << r.err;
    EXPECT_EQ(lines(r.err), 1u) << r.err;
  }
  // A merge into a new database whose WAL cannot grow past 4 KiB, as on a full disk.
  const Result full = test::run_cli_on_full_disk(dir.path(), "merge m.db s.db", 4);
  EXPECT_EQ(full.code, 1);
  const std::string& err = full.err;
  EXPECT_EQ(lines(err), 1u) << err;
  EXPECT_NE(err.find("m.db"), std::string::npos) << err;
  EXPECT_NE(err.find("the disk may be full"), std::string::npos) << err;
  EXPECT_FALSE(fs::exists(dir / "m.db"));
}

}  // namespace
}  // namespace crevasse
