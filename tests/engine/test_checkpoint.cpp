// Checkpoints: a simulation restored from a checkpoint continues bit for bit
// as the uninterrupted one; a run cancelled and started again with the same checkpoint path ends
// in the same state as a run never interrupted; a checkpoint of another scene or a truncated
// file is refused.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include <unistd.h>

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
    EXPECT_NE(std::string(e.what()).find("truncated or corrupt"), std::string::npos) << e.what();
  }
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
  bool cancelled() override { return cancel_after_ > 0 && reports_ >= cancel_after_; }

 private:
  fs::path file_;
  int cancel_after_;
  int reports_ = 0;
};

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
  EXPECT_EQ(second.steps, whole.steps);
  expect_same_state(whole.final_snapshot, second.final_snapshot);
  EXPECT_FALSE(fs::exists(file)) << "the checkpoint of a finished run is deleted";
}

}  // namespace
}  // namespace crevasse
