#include "engine/run.hpp"

#include <algorithm>
#include <cmath>
#include <chrono>
#include <cstdio>
#include <filesystem>

#include "engine/error.hpp"
#include "engine/simulation.hpp"

namespace crevasse {
namespace {

template <int Dim>
RunSummary run_dim(const SceneConfig& scene, RunObserver* obs) {
  using clock = std::chrono::steady_clock;
  const auto t0 = clock::now();
  Simulation<Dim> sim(scene);
  RunSummary out;
  out.initial_mass = sim.total_mass();
  out.initial_particles = sim.particles().size();
  const std::string checkpoint = obs ? obs->checkpoint_path() : std::string();
  std::optional<double> earlier_wall_s = 0.0;  // of the sittings before the checkpoint resumed
  std::error_code exists_ec;
  // symlink_status: a dangling link or a FIFO is still "there" and must be dropped, not opened.
  if (!checkpoint.empty() && std::filesystem::exists(std::filesystem::symlink_status(checkpoint, exists_ec))) {
    try {
      earlier_wall_s = sim.load_checkpoint(checkpoint);  // changes nothing unless the whole file is good
      out.resumed_from_time_s = sim.time();
    } catch (const SimulationError& e) {
      std::error_code ec;
      std::filesystem::remove(checkpoint, ec);
      obs->on_warning(std::string(e.what()) + "; " +
                      (ec || std::filesystem::exists(std::filesystem::symlink_status(checkpoint, ec))
                           ? "could not remove it; "
                           : "removed it; ") +
                      "the case runs from t = 0");
    }
  }
  const auto wall_now = [&] { return std::chrono::duration<double>(clock::now() - t0).count(); };
  // The summary of the state the run is in: at its stop, and at each gate mark.
  const auto summarize = [&](RunSummary& o) {
    o.steps = sim.steps();
    o.particle_steps = sim.particle_steps();
    o.return_map_evaluations = sim.return_map_evaluations();
    o.sim_time_s = sim.time();
    o.final_mass = sim.total_mass();
    o.removed_mass = sim.removed_mass();
    o.inflow_mass = sim.inflow_mass();
    o.final_particles = sim.particles().size();
    o.final_snapshot = sim.snapshot();
    o.final_ice_front_x = sim.ice_front_x();
    o.stage_seconds = nlohmann::json::object();
    for (const auto& s : sim.stages()) o.stage_seconds[s.name] = {{"seconds", s.seconds}, {"calls", s.calls}};
    o.wall_s = wall_now();
  };
  double last_checkpoint_wall = 0.0;
  // A checkpoint that cannot be written costs only the time it would have saved.
  auto save_checkpoint = [&] {
    try {
      sim.save_checkpoint(checkpoint, earlier_wall_s ? std::optional<double>(*earlier_wall_s + wall_now())
                                                     : std::nullopt);
    } catch (const SimulationError& e) {
      obs->on_warning(std::string(e.what()) + "; the case goes on without it");
    }
  };
  auto check_time_limit = [&](double wall, double done) {
    if (scene.wall_time_limit > 0 && wall > scene.wall_time_limit) {
      char msg[240];
      std::snprintf(msg, sizeof msg, "time limit: run.wall_time_limit = %g s reached %s%.6g s, step %lld (%d%% done)",
                    scene.wall_time_limit, sim.settled() ? "at t = " : "while settling, at settling time ",
                    sim.time(), static_cast<long long>(sim.steps()), static_cast<int>(100 * done));
      if (!checkpoint.empty()) save_checkpoint();
      throw TimeLimitError(msg, scene.wall_time_limit, sim.time(), done, sim.settled());
    }
  };
  // The front that counts is that of the connected ice, not of debris thrown ahead of it.
  double ice_front = sim.ice_front_x();
  const double front0 = ice_front;
  const double target_front = scene.step_foot_x() + scene.front_past_step;

  auto fraction = [&] {
    double f = 0.0;
    if (scene.end_time > 0) f = std::max(f, sim.time() / scene.end_time);
    if (scene.front_past_step > 0 && target_front > front0)
      f = std::max(f, (ice_front - front0) / (target_front - front0));
    if (scene.gate_length > 0) f = std::max(f, sim.gate_passed_length() / scene.gate_length);
    if (scene.max_steps > 0) f = std::max(f, static_cast<double>(sim.steps()) / scene.max_steps);
    return std::clamp(f, 0.0, 1.0);
  };
  if (obs && out.resumed_from_time_s >= 0.0) obs->on_resumed(fraction(), earlier_wall_s);

  int output_index = 0;
  double next_output = 0.0;
  double last_output_time = -1.0;
  auto maybe_output = [&] {
    if (!obs || scene.vtu_interval <= 0) return;
    if (sim.time() + 1e-12 >= next_output) {
      obs->on_output(sim.snapshot(), output_index++);
      last_output_time = sim.time();
      while (next_output <= sim.time() + 1e-12) next_output += scene.vtu_interval;
    }
  };
  maybe_output();
  const double snap_interval = obs ? obs->snapshot_interval_s() : 0.0;
  // On the same grid of times whether the run started fresh or from a checkpoint.
  double next_snap = snap_interval > 0.0 ? snap_interval * (std::floor(sim.time() / snap_interval + 1e-9) + 1.0) : 0.0;

  const bool watch_stall = scene.gate_length > 0 && scene.has(Effect::drive) && scene.drive_speed > 0;
  GateStallWatch stall;
  if (watch_stall) {
    stall.window_s = 2.0 * scene.ice_thickness / scene.drive_speed;
    stall.min_growth_m = scene.dx;
    stall.ramp_s = scene.drive_ramp_time;
  }

  std::vector<double> marks = obs ? obs->gate_marks() : std::vector<double>();
  std::sort(marks.begin(), marks.end());
  // A resumed run reached these before its checkpoint was written, and called them then.
  std::size_t next_mark = 0;
  while (next_mark < marks.size() && marks[next_mark] <= sim.gate_passed_length() && out.resumed_from_time_s >= 0.0)
    ++next_mark;
  const auto call_marks = [&] {
    while (next_mark < marks.size() && sim.gate_passed_length() >= marks[next_mark]) {
      RunSummary at = out;
      at.stop_reason = "gate_length";
      summarize(at);
      obs->on_gate_mark(marks[next_mark++], at);
    }
  };

  // The settling phase is polled between its steps like the run: time limit, checkpoints and
  // cancellation, so that neither a signal nor the limit waits for it to end.
  {
    double last_poll = 0.0;
    const bool settled = sim.settle([&] {
      const double wall = wall_now();
      check_time_limit(wall, 0.0);
      if (!checkpoint.empty() && wall - last_checkpoint_wall >= obs->checkpoint_interval_s()) {
        save_checkpoint();
        last_checkpoint_wall = wall;
      }
      if (obs && wall - last_poll >= obs->progress_interval_s()) {
        last_poll = wall;
        if (obs->cancelled()) return false;
      }
      return true;
    });
    if (!settled) {
      if (!checkpoint.empty()) save_checkpoint();
      out.stop_reason = "cancelled";
      out.steps = sim.steps();
      out.sim_time_s = sim.time();
      out.initial_mass = out.final_mass = sim.total_mass();
      out.wall_s = wall_now();
      return out;
    }
  }
  double last_report = 0.0;
  std::int64_t last_steps = 0, last_psteps = 0;
  while (true) {
    if (scene.end_time > 0 && sim.time() >= scene.end_time) { out.stop_reason = "end_time"; break; }
    // O(particles): every 20 steps, and only when the stop rule needs it (progress reads it
    // when it reports).
    if (scene.front_past_step > 0 && sim.steps() % 20 == 0) ice_front = sim.ice_front_x();
    if (scene.front_past_step > 0 && ice_front >= target_front) { out.stop_reason = "front_past_step"; break; }
    if (scene.gate_length > 0 && sim.gate_passed_length() >= scene.gate_length) { out.stop_reason = "gate_length"; break; }
    if (watch_stall && stall.stalled(sim.time(), sim.gate_passed_length())) { out.stop_reason = "gate_stalled"; break; }
    if (scene.max_steps > 0 && sim.steps() >= scene.max_steps) { out.stop_reason = "max_steps"; break; }
    if (sim.particles().size() == 0) { out.stop_reason = "no_ice_left"; break; }
    sim.step();
    call_marks();
    maybe_output();
    if (snap_interval > 0.0 && sim.time() + 1e-12 >= next_snap) {
      obs->on_snapshot(sim.snapshot());
      while (next_snap <= sim.time() + 1e-12) next_snap += snap_interval;
    }
    const double wall = wall_now();
    check_time_limit(wall, fraction());
    if (!checkpoint.empty() && wall - last_checkpoint_wall >= obs->checkpoint_interval_s()) {
      save_checkpoint();
      last_checkpoint_wall = wall;
    }
    if (obs && wall - last_report >= obs->progress_interval_s()) {
      if (scene.front_past_step <= 0) ice_front = sim.ice_front_x();
      RunProgress pr;
      const double span = wall - last_report;
      pr.sim_time_s = sim.time();
      pr.fraction_done = fraction();
      pr.steps = sim.steps();
      pr.particles = sim.particles().size();
      pr.steps_per_second = (sim.steps() - last_steps) / span;
      pr.particle_steps_per_second = (sim.particle_steps() - last_psteps) / span;
      pr.eta_s = pr.fraction_done > 0 ? wall * (1.0 - pr.fraction_done) / pr.fraction_done : 0.0;
      pr.front_x_m = ice_front;
      pr.wall_s = wall;
      obs->on_progress(pr);
      last_report = wall;
      last_steps = sim.steps();
      last_psteps = sim.particle_steps();
      if (obs->cancelled()) {
        if (!checkpoint.empty()) save_checkpoint();
        out.stop_reason = "cancelled";
        break;
      }
    }
  }
  if (!checkpoint.empty() && out.stop_reason != "cancelled") {
    std::error_code ec;
    std::filesystem::remove(checkpoint, ec);
  }
  summarize(out);
  // The last state is always among the snapshots, unless the last interval just wrote it.
  if (obs && scene.vtu_interval > 0 && last_output_time < sim.time())
    obs->on_output(out.final_snapshot, output_index++);
  return out;
}

}  // namespace

RunSummary run_scene(const SceneConfig& scene, RunObserver* observer) {
  return scene.dim == 3 ? run_dim<3>(scene, observer) : run_dim<2>(scene, observer);
}

}  // namespace crevasse
