// Checkpoints: a simulation restored from a checkpoint continues bit for bit
// as the uninterrupted one; a run cancelled and started again with the same checkpoint path ends
// in the same state as a run never interrupted; a checkpoint of another scene or a truncated
// file is refused.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include <sys/stat.h>
#include <unistd.h>

#include <cstring>
#include <iterator>

#include "engine/checkpoint.hpp"
#include "engine/error.hpp"
#include "engine/run.hpp"
#include "engine/simulation.hpp"
#include "scene_builders.hpp"

namespace crevasse {
namespace {

namespace fs = std::filesystem;

fs::path scratch(const std::string& name) {
  const fs::path p = fs::temp_directory_path() / ("crevasse_ckpt_" + name + "_" + std::to_string(::getpid()));
  fs::remove(p);
  return p;
}

// Exact equality: the restored run must take the same floating-point path.
void expect_same_state(const ParticleSnapshot& a, const ParticleSnapshot& b) {
  EXPECT_EQ(a.time_s, b.time_s);
  ASSERT_EQ(a.size(), b.size());
  EXPECT_EQ(a.x, b.x);
  EXPECT_EQ(a.z, b.z);
  EXPECT_EQ(a.vx, b.vx);
  EXPECT_EQ(a.vz, b.vz);
  EXPECT_EQ(a.eps_v_p, b.eps_v_p);
  EXPECT_EQ(a.pressure_pa, b.pressure_pa);
  EXPECT_EQ(a.gate_eps_v_p, b.gate_eps_v_p);
  EXPECT_EQ(a.gate_x_ref, b.gate_x_ref);
  EXPECT_EQ(a.gate_passed_length_m, b.gate_passed_length_m);
}

void expect_restored_run_continues_bit_for_bit(const std::string& scene_file) {
  const SceneConfig scene = scene_from_json(test::shipped_scene_json(scene_file));
  const fs::path file = scratch("sim");
  Simulation<2> a(scene);
  // 2,050 steps: past a particle re-sort (every 100 steps) on both sides of the checkpoint, and
  // far enough (t ≈ 8 s) that the drive has started.
  while (a.steps() < 2050) a.step();
  a.save_checkpoint(file.string());
  while (a.steps() < 4050) a.step();

  Simulation<2> b(scene);
  b.load_checkpoint(file.string());
  EXPECT_EQ(b.steps(), 2050);
  while (b.steps() < 4050) b.step();
  expect_same_state(a.snapshot(), b.snapshot());
  EXPECT_EQ(a.removed_mass(), b.removed_mass());
  EXPECT_EQ(a.inflow_mass(), b.inflow_mass());
  EXPECT_EQ(a.gate_passed_length(), b.gate_passed_length());
  fs::remove(file);
}

TEST(Checkpoint, RestoredSimulationContinuesBitForBit) { expect_restored_run_continues_bit_for_bit("glacier_2d.json"); }

// The inflow's state (columns entered, mass entered) is in the checkpoint: the restored run seeds
// the same columns at the same steps (each 1.25 s here, so six before and seven after the save).
TEST(Checkpoint, RestoredInflowContinuesBitForBit) {
  expect_restored_run_continues_bit_for_bit("flowing_inflow_2d.json");
}

TEST(Checkpoint, OtherSceneAndTruncatedFilesAreRefused) {
  const SceneConfig scene = scene_from_json(test::shipped_scene_json());
  const fs::path file = scratch("refuse");
  Simulation<2> a(scene);
  a.step();
  a.save_checkpoint(file.string());

  nlohmann::json other = test::shipped_scene_json();
  other["ice"]["tensile_strength"] = 2.0e5;
  Simulation<2> b(scene_from_json(other));
  try {
    b.load_checkpoint(file.string());
    FAIL() << "a checkpoint of another scene was loaded";
  } catch (const SimulationError& e) {
    EXPECT_NE(std::string(e.what()).find("another scene"), std::string::npos) << e.what();
  }

  fs::resize_file(file, fs::file_size(file) / 2);
  Simulation<2> c(scene);
  try {
    c.load_checkpoint(file.string());
    FAIL() << "a truncated checkpoint was loaded";
  } catch (const SimulationError& e) {
    EXPECT_NE(std::string(e.what()).find("truncated"), std::string::npos) << e.what();
  }
  fs::remove(file);
}

std::string slurp(const fs::path& p) {
  std::ifstream f(p, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(f), {});
}
void spit(const fs::path& p, const std::string& bytes) {
  std::ofstream(p, std::ios::binary | std::ios::trunc) << bytes;
}

// The reason load_checkpoint gives for `file`, or "" when it loads.
std::string refusal(const SceneConfig& scene, const fs::path& file) {
  Simulation<2> sim(scene);
  try {
    sim.load_checkpoint(file.string());
  } catch (const SimulationError& e) {
    EXPECT_EQ(sim.time(), 0.0) << "a refused checkpoint changed the simulation";
    return e.what();
  }
  return "";
}

// A checkpoint keeps the wall time the run had cost, for the next sitting to add to. A format 2
// file (written before it did) is still read, with no earlier wall time: a study paused then
// continues from it.
// The format 2 file of a format 3 one: the same payload without the wall time, its checksum
// and both markers. `wall` receives the wall time the format 3 file held.
std::string to_format2(const std::string& three, double& wall) {
  std::size_t at = 8;
  for (int k = 0; k < 2; ++k) {  // engine version, scene
    std::uint64_t n = 0;
    std::memcpy(&n, three.data() + at, sizeof n);
    at += sizeof n + n;
  }
  // dim; time, dt; three step counts; removed mass, front, top speed; settled; gate volume,
  // inflow mass and columns. Then the wall time.
  at += 4 + 2 * 8 + 3 * 8 + 3 * 8 + 1 + 3 * 8;
  std::memcpy(&wall, three.data() + at, sizeof wall);
  std::string two = three.substr(0, at) + three.substr(at + 8);
  two[7] = '2';
  two[two.size() - 1] = '2';
  const std::size_t payload = two.size() - 8 - 8 - 8;
  const std::uint64_t sum = checkpoint::checksum(two.data() + 8, payload);
  std::memcpy(two.data() + 8 + payload, &sum, sizeof sum);
  return two;
}

// The wall time spent is kept; a format 2 file, which did not keep it, is read with the wall
// time unknown, and an unknown wall time stays unknown when written again.
TEST(Checkpoint, KeepsTheWallTimeAndReadsFormat2) {
  const SceneConfig scene = scene_from_json(test::shipped_scene_json());
  const fs::path file = scratch("wall");
  Simulation<2> a(scene);
  a.step();
  a.save_checkpoint(file.string(), 1234.5);
  Simulation<2> b(scene);
  EXPECT_EQ(b.load_checkpoint(file.string()), std::optional<double>(1234.5));
  EXPECT_EQ(b.steps(), 1);

  double wall = 0.0;
  spit(file, to_format2(slurp(file), wall));
  ASSERT_EQ(wall, 1234.5) << "the wall time is not where format 3 puts it";
  Simulation<2> c(scene);
  EXPECT_EQ(c.load_checkpoint(file.string()), std::nullopt);
  EXPECT_EQ(c.steps(), 1);
  expect_same_state(a.snapshot(), c.snapshot());

  c.save_checkpoint(file.string(), std::nullopt);
  Simulation<2> d(scene);
  EXPECT_EQ(d.load_checkpoint(file.string()), std::nullopt);
  fs::remove(file);
}

// Every way a checkpoint can be unusable is refused with its reason: one flipped byte of the
// state (the checksum), another engine version (with a valid checksum), an older format,
// an empty file, a directory and a FIFO (refused without being opened, so it cannot block).
TEST(Checkpoint, CorruptForeignAndNonRegularFilesAreRefused) {
  const SceneConfig scene = scene_from_json(test::shipped_scene_json());
  const fs::path file = scratch("unusable");
  Simulation<2> a(scene);
  a.step();
  a.save_checkpoint(file.string());
  const std::string good = slurp(file);
  ASSERT_EQ(refusal(scene, file), "");

  std::string flipped = good;
  flipped[good.size() / 2] ^= 0x10;  // inside the particle arrays
  spit(file, flipped);
  EXPECT_NE(refusal(scene, file).find("checksum"), std::string::npos) << refusal(scene, file);

  // Another engine version, its checksum recomputed: refused for the version itself.
  std::string other = good;
  const std::size_t v = other.find(CREVASSE_ENGINE_VERSION);
  ASSERT_NE(v, std::string::npos);
  other[v] = other[v] == '9' ? '8' : '9';
  const std::size_t payload = other.size() - 8 - 8 - 8;
  const std::uint64_t sum = checkpoint::checksum(other.data() + 8, payload);
  std::memcpy(other.data() + 8 + payload, &sum, sizeof sum);
  spit(file, other);
  EXPECT_NE(refusal(scene, file).find("another engine version"), std::string::npos) << refusal(scene, file);

  std::string old_format = good;
  old_format[7] = '1';
  spit(file, old_format);
  EXPECT_NE(refusal(scene, file).find("another checkpoint format"), std::string::npos);

  spit(file, "");
  EXPECT_NE(refusal(scene, file).find("truncated or empty"), std::string::npos);

  fs::remove(file);
  fs::create_directory(file);
  EXPECT_NE(refusal(scene, file).find("not a regular file"), std::string::npos);
  fs::remove(file);
  ASSERT_EQ(::mkfifo(file.c_str(), 0600), 0);
  EXPECT_NE(refusal(scene, file).find("not a regular file"), std::string::npos);
  fs::remove(file);
}

class CheckpointingObserver : public RunObserver {
 public:
  CheckpointingObserver(fs::path file, int cancel_after_reports)
      : file_(std::move(file)), cancel_after_(cancel_after_reports) {}
  std::string checkpoint_path() const override { return file_.string(); }
  double checkpoint_interval_s() const override { return 0.2; }
  double progress_interval_s() const override { return 0.3; }
  void on_progress(const RunProgress&) override { ++reports_; }
  bool cancelled() override { return cancel_now || (cancel_after_ > 0 && reports_ >= cancel_after_); }
  bool cancel_now = false;
  void on_warning(const std::string& m) override { warnings.push_back(m); }
  std::vector<std::string> warnings;
  void on_resumed(double fraction, std::optional<double> earlier_wall_s) override {
    resumed_fraction = fraction;
    resumed_wall_s = earlier_wall_s;
  }
  double resumed_fraction = -1.0;
  std::optional<double> resumed_wall_s = -1.0;

 private:
  fs::path file_;
  int cancel_after_;
  int reports_ = 0;
};

// A checkpoint can only help: a run given an unusable checkpoint says so, removes it and runs
// from t = 0 to the uninterrupted result; a run whose checkpoints cannot be written says so and
// ends with the uninterrupted result, leaving no temporary file.
TEST(Checkpoint, UnusableOrUnwritableCheckpointsCostNothing) {
  nlohmann::json j = test::shipped_scene_json();
  j["run"] = {{"max_steps", 400}};
  const SceneConfig scene = scene_from_json(j);
  const RunSummary whole = run_scene(scene);

  const fs::path file = scratch("dropped");
  for (const std::string bytes : {std::string(), std::string("CRVCKPT3 but nothing else"), std::string(5000, 'x')}) {
    spit(file, bytes);
    CheckpointingObserver obs(file, 0);
    const RunSummary r = run_scene(scene, &obs);
    EXPECT_EQ(r.resumed_from_time_s, -1.0);
    EXPECT_EQ(r.steps, whole.steps);
    expect_same_state(whole.final_snapshot, r.final_snapshot);
    ASSERT_FALSE(obs.warnings.empty());
    EXPECT_NE(obs.warnings[0].find("removed it; the case runs from t = 0"), std::string::npos) << obs.warnings[0];
    EXPECT_FALSE(fs::exists(file));
  }

  // The folder does not exist: every write fails.
  const fs::path nowhere = scratch("no_such_dir") / "c.ckpt";
  struct SlowCheckpoints : CheckpointingObserver {
    using CheckpointingObserver::CheckpointingObserver;
    double checkpoint_interval_s() const override { return 0.0; }  // after every step
  } obs(nowhere, 0);
  const RunSummary r = run_scene(scene, &obs);
  EXPECT_EQ(r.stop_reason, "max_steps");
  expect_same_state(whole.final_snapshot, r.final_snapshot);
  ASSERT_FALSE(obs.warnings.empty());
  EXPECT_NE(obs.warnings[0].find("the case goes on without it"), std::string::npos) << obs.warnings[0];
  EXPECT_FALSE(fs::exists(nowhere.string() + ".tmp"));
}

// The settling phase is a phase like the run: it pauses when asked, a checkpoint written while
// settling continues bit for bit, run_scene stops it on cancellation with a checkpoint, and the
// wall-time limit ends it.
TEST(Checkpoint, SettlingPausesCheckpointsAndContinuesBitForBit) {
  nlohmann::json j = test::shipped_scene_json();
  j["ice"]["settle_time"] = 2.0;  // about 500 steps
  j["run"] = {{"max_steps", 50}};
  const SceneConfig scene = scene_from_json(j);
  Simulation<2> a(scene);
  a.settle();
  while (a.steps() < 50) a.step();

  const fs::path file = scratch("settling");
  Simulation<2> b(scene);
  int steps = 0;
  EXPECT_FALSE(b.settle([&] { return ++steps < 120; }));
  EXPECT_FALSE(b.settled());
  EXPECT_GT(b.time(), 0.0);
  b.save_checkpoint(file.string());
  Simulation<2> c(scene);
  c.load_checkpoint(file.string());
  EXPECT_FALSE(c.settled());
  EXPECT_TRUE(c.settle());
  while (c.steps() < 50) c.step();
  expect_same_state(a.snapshot(), c.snapshot());

  // run_scene: cancelled while settling (the observer's first poll), with a checkpoint to go on from.
  fs::remove(file);
  struct Stopper : CheckpointingObserver {
    using CheckpointingObserver::CheckpointingObserver;
    double progress_interval_s() const override { return 0.0; }  // asked after every step
  } stopper(file, 0);
  stopper.cancel_now = true;
  const RunSummary first = run_scene(scene, &stopper);
  EXPECT_EQ(first.stop_reason, "cancelled");
  EXPECT_GT(first.sim_time_s, 0.0);
  EXPECT_LT(first.sim_time_s, 2.0) << "stopped only after settling";
  ASSERT_TRUE(fs::exists(file));
  Simulation<2> probe(scene);
  probe.load_checkpoint(file.string());
  EXPECT_FALSE(probe.settled()) << "the run was stopped only after settling";
  CheckpointingObserver resume(file, 0);
  const RunSummary second = run_scene(scene, &resume);
  EXPECT_EQ(second.resumed_from_time_s, first.sim_time_s);
  expect_same_state(a.snapshot(), second.final_snapshot);
  fs::remove(file);

  // The wall-time limit ends a long settling phase, not its end.
  nlohmann::json long_settle = j;
  long_settle["ice"]["settle_time"] = 300.0;  // about 70,000 steps, many seconds
  long_settle["run"]["wall_time_limit"] = 0.5;
  try {
    run_scene(scene_from_json(long_settle));
    FAIL() << "the time limit did not fire";
  } catch (const SimulationError& e) {
    EXPECT_NE(std::string(e.what()).find("while settling"), std::string::npos) << e.what();
  }
}

TEST(Checkpoint, CancelledRunResumesToTheUninterruptedResult) {
  nlohmann::json j = test::shipped_scene_json();
  j["run"]["gate_length"] = 100.0;  // a short run, a few seconds
  const SceneConfig scene = scene_from_json(j);
  const RunSummary whole = run_scene(scene);
  ASSERT_EQ(whole.stop_reason, "gate_length");

  const fs::path file = scratch("run");
  CheckpointingObserver killer(file, 2);  // cancelled after ~0.6 s of wall time
  const RunSummary first = run_scene(scene, &killer);
  ASSERT_EQ(first.stop_reason, "cancelled") << "the run finished before it could be interrupted";
  ASSERT_TRUE(fs::exists(file));
  EXPECT_LT(first.sim_time_s, whole.sim_time_s);

  CheckpointingObserver resume(file, 0);
  const RunSummary second = run_scene(scene, &resume);
  EXPECT_EQ(second.stop_reason, "gate_length");
  EXPECT_EQ(second.resumed_from_time_s, first.sim_time_s);
  // It says where it resumed, and the wall time of the first sitting, up to its checkpoint.
  EXPECT_GT(resume.resumed_fraction, 0.0);
  EXPECT_LT(resume.resumed_fraction, 1.0);
  ASSERT_TRUE(resume.resumed_wall_s.has_value());
  EXPECT_GT(*resume.resumed_wall_s, 0.0);
  EXPECT_LE(*resume.resumed_wall_s, first.wall_s);
  EXPECT_EQ(second.steps, whole.steps);
  expect_same_state(whole.final_snapshot, second.final_snapshot);
  EXPECT_FALSE(fs::exists(file)) << "the checkpoint of a finished run is deleted";
}

// A run resumed from a format 2 checkpoint says that the earlier wall time is not known, and
// the checkpoints it writes keep it unknown (not 0, which would understate the case's cost).
TEST(Checkpoint, AFormat2ResumeReportsTheEarlierWallTimeAsUnknown) {
  nlohmann::json j = test::shipped_scene_json();
  j["run"]["gate_length"] = 100.0;
  const SceneConfig scene = scene_from_json(j);
  const fs::path file = scratch("format2");
  CheckpointingObserver killer(file, 2);
  ASSERT_EQ(run_scene(scene, &killer).stop_reason, "cancelled");
  double wall = 0.0;
  spit(file, to_format2(slurp(file), wall));

  CheckpointingObserver again(file, 2);
  ASSERT_EQ(run_scene(scene, &again).stop_reason, "cancelled");
  EXPECT_GT(again.resumed_fraction, 0.0);
  EXPECT_EQ(again.resumed_wall_s, std::nullopt);
  ASSERT_TRUE(fs::exists(file));
  EXPECT_EQ(slurp(file)[7], '3') << "the checkpoint is rewritten in the current format";
  CheckpointingObserver last(file, 0);
  EXPECT_EQ(run_scene(scene, &last).stop_reason, "gate_length");
  EXPECT_EQ(last.resumed_wall_s, std::nullopt);
}

// A run stopped by run.wall_time_limit saves its checkpoint as it stops (none is due by the
// interval here), and the same scene under a larger limit continues from it to the
// uninterrupted result: the limit is not part of the scene a checkpoint belongs to.
TEST(Checkpoint, ARunOutOfTimeSavesItsCheckpointAndContinuesUnderALargerLimit) {
  nlohmann::json j = test::shipped_scene_json();
  j["run"]["gate_length"] = 100.0;  // a few seconds of wall time
  const SceneConfig scene = scene_from_json(j);
  const RunSummary whole = run_scene(scene);
  ASSERT_EQ(whole.stop_reason, "gate_length");

  const fs::path file = scratch("out_of_time");
  struct NoPeriodicCheckpoints : CheckpointingObserver {
    using CheckpointingObserver::CheckpointingObserver;
    double checkpoint_interval_s() const override { return 1e9; }
  } limited_obs(file, 0);
  SceneConfig limited = scene;
  limited.wall_time_limit = 0.5;
  double stopped_at = -1.0;
  try {
    run_scene(limited, &limited_obs);
    FAIL() << "the run finished before its 0.5 s limit";
  } catch (const TimeLimitError& e) {
    EXPECT_EQ(e.limit_s, 0.5);
    stopped_at = e.sim_time_s;
  }
  ASSERT_TRUE(fs::exists(file)) << "no checkpoint saved at the time limit";
  ASSERT_GT(stopped_at, 0.0);
  EXPECT_LT(stopped_at, whole.sim_time_s);

  CheckpointingObserver resume(file, 0);
  const RunSummary second = run_scene(scene, &resume);
  EXPECT_TRUE(resume.warnings.empty()) << resume.warnings[0];
  EXPECT_EQ(second.resumed_from_time_s, stopped_at);
  EXPECT_EQ(second.stop_reason, "gate_length");
  expect_same_state(whole.final_snapshot, second.final_snapshot);
}

// An observer of gate marks (RunObserver::gate_marks): it records each call, and can cancel the
// run at a simulated time or at a mark, leaving a checkpoint on either side of it.
class MarkObserver : public CheckpointingObserver {
 public:
  MarkObserver(fs::path file, std::vector<double> marks)
      : CheckpointingObserver(std::move(file), 0), marks_(std::move(marks)) {}
  std::vector<double> gate_marks() const override { return marks_; }
  void on_gate_mark(double mark_m, const RunSummary& at) override {
    calls.emplace_back(mark_m, at);
    if (cancel_at_mark) cancel_now = true;
  }
  double snapshot_interval_s() const override { return cancel_at_time_s > 0 ? 0.5 : 0.0; }
  void on_snapshot(const ParticleSnapshot& s) override {
    if (s.time_s >= cancel_at_time_s) cancel_now = true;
  }
  std::vector<std::pair<double, RunSummary>> calls;
  bool cancel_at_mark = false;
  double cancel_at_time_s = 0.0;

 private:
  std::vector<double> marks_;
};

nlohmann::json gate_scene(double gate_length_m) {
  nlohmann::json j = test::shipped_scene_json();
  j["run"]["gate_length"] = gate_length_m;
  return j;
}

// One run serves a shorter protocol: at each mark the observer gets, bit for bit, what a run with
// run.gate_length = that mark ends with, and the run goes on to its own stop.
TEST(GateMark, IsWhatARunStoppedThereEndsWith) {
  const RunSummary shorter = run_scene(scene_from_json(gate_scene(30.0)));
  ASSERT_EQ(shorter.stop_reason, "gate_length");
  MarkObserver obs("", {30.0, 15.0});  // in any order
  const RunSummary longer = run_scene(scene_from_json(gate_scene(45.0)), &obs);
  ASSERT_EQ(longer.stop_reason, "gate_length");
  ASSERT_EQ(obs.calls.size(), 2u);
  EXPECT_EQ(obs.calls[0].first, 15.0);
  EXPECT_EQ(obs.calls[1].first, 30.0);
  const RunSummary& at = obs.calls[1].second;
  EXPECT_EQ(at.stop_reason, "gate_length");
  EXPECT_EQ(at.steps, shorter.steps);
  EXPECT_EQ(at.particle_steps, shorter.particle_steps);
  EXPECT_EQ(at.return_map_evaluations, shorter.return_map_evaluations);
  EXPECT_EQ(at.sim_time_s, shorter.sim_time_s);
  EXPECT_EQ(at.initial_mass, shorter.initial_mass);
  EXPECT_EQ(at.final_mass, shorter.final_mass);
  EXPECT_EQ(at.removed_mass, shorter.removed_mass);
  EXPECT_EQ(at.final_particles, shorter.final_particles);
  EXPECT_EQ(at.final_ice_front_x, shorter.final_ice_front_x);
  expect_same_state(shorter.final_snapshot, at.final_snapshot);
  EXPECT_GT(longer.steps, at.steps) << "the run stopped at the mark: the test shows nothing";
  EXPECT_GT(obs.calls[1].second.steps, obs.calls[0].second.steps);
}

// A resumed run calls a mark it had not reached before its checkpoint once, with the state the
// uninterrupted run had there, and one it had reached (and called) not again.
TEST(GateMark, AResumedRunCallsEachMarkOnce) {
  const SceneConfig scene = scene_from_json(gate_scene(50.0));
  MarkObserver whole("", {35.0});
  ASSERT_EQ(run_scene(scene, &whole).stop_reason, "gate_length");
  ASSERT_EQ(whole.calls.size(), 1u);
  const RunSummary& ref = whole.calls[0].second;

  const fs::path before = scratch("mark_before");
  MarkObserver a(before, {35.0});
  a.cancel_at_time_s = 1.0;
  ASSERT_EQ(run_scene(scene, &a).stop_reason, "cancelled");
  ASSERT_TRUE(a.calls.empty()) << "cancelled only after the mark: the test shows nothing";
  MarkObserver b(before, {35.0});
  ASSERT_EQ(run_scene(scene, &b).stop_reason, "gate_length");
  ASSERT_EQ(b.calls.size(), 1u);
  EXPECT_EQ(b.calls[0].second.steps, ref.steps);
  expect_same_state(ref.final_snapshot, b.calls[0].second.final_snapshot);

  const fs::path after = scratch("mark_after");
  MarkObserver c(after, {35.0});
  c.cancel_at_mark = true;
  const RunSummary cut = run_scene(scene, &c);
  ASSERT_EQ(cut.stop_reason, "cancelled") << "the run ended before it could be interrupted";
  ASSERT_EQ(c.calls.size(), 1u);
  EXPECT_GE(cut.steps, c.calls[0].second.steps);  // its checkpoint at the mark's step or later
  MarkObserver d(after, {35.0});
  ASSERT_EQ(run_scene(scene, &d).stop_reason, "gate_length");
  EXPECT_TRUE(d.calls.empty()) << "called again after the resume";
}

}  // namespace
}  // namespace crevasse
