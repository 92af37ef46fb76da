// bench_case [STEPS] [THICKNESS] [STUDY]: the production case's throughput, as a study runs it.
// The case is the one of STUDY (default studies/whole_case_cost.json, the pushed glacier at
// dx = 10 m as the decisive studies run it) with that H_i (default 400 m), read through the
// study loader so that it is exactly the case the study runs. After one settling, saved and
// reloaded from a checkpoint, it times STEPS steps (default 400):
//   (a) one case on 1 and on 2 engine threads, in particle-steps per second, and how the
//       2-thread step splits over the engine's stages;
//   (c) two cases at once, one engine thread each, against one case on one thread;
// and the resident memory of one case per particle. The whole-case wall times are those of the
// study itself (results/whole_case_cost.db; docs/performance.md).
#include <tbb/global_control.h>
#include <tbb/task_arena.h>

#include <chrono>
#include <cstdlib>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <thread>

#include <unistd.h>

#include "engine/simulation.hpp"
#include "study/study_file.hpp"

namespace {

using crevasse::SceneConfig;
using crevasse::Simulation;

double resident_bytes() {
  std::ifstream f("/proc/self/status");
  std::string key;
  while (f >> key) {
    if (key == "VmRSS:") {
      double kb = 0;
      f >> kb;
      return kb * 1024.0;
    }
    std::getline(f, key);
  }
  return 0.0;
}

// Steps a simulation restored from the settled checkpoint on `threads` engine threads; returns
// particle-steps per second.
double run(const SceneConfig& scene, const std::string& checkpoint, long steps, int threads,
           bool print_stages = false) {
  tbb::task_arena arena(threads);
  double rate = 0.0;
  arena.execute([&] {
    Simulation<2> sim(scene);
    sim.load_checkpoint(checkpoint);
    const std::int64_t before = sim.particle_steps();
    const auto t0 = std::chrono::steady_clock::now();
    for (long s = 0; s < steps; ++s) sim.step();
    const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    rate = static_cast<double>(sim.particle_steps() - before) / wall;
    if (!print_stages) return;
    // The stage clocks restart with the restored simulation: they cover exactly these steps.
    for (const auto& st : sim.stages())
      std::printf("    %-22s %5.1f %%  %7.1f ns/particle-step\n", st.name.c_str(), 100.0 * st.seconds / wall,
                  1e9 * st.seconds / static_cast<double>(sim.particle_steps() - before));
  });
  return rate;
}

}  // namespace

// A positive number, or exit 2 with a usage line (no uncaught exception on --help or a typo).
double positive_arg(const char* text, const char* what) {
  char* end = nullptr;
  const double v = std::strtod(text, &end);
  if (end == text || *end != '\0' || !(v > 0.0) || v > 1e9) {
    std::fprintf(stderr, "bench_case: %s '%s' is not a positive number\n"
                         "usage: bench_case [STEPS (default 400)] [THICKNESS_M (default 400)] [STUDY.json]\n",
                 what, text);
    std::exit(2);
  }
  return v;
}

int main(int argc, char** argv) {
  const long steps = argc > 1 ? static_cast<long>(positive_arg(argv[1], "STEPS")) : 400;
  const double thickness = argc > 2 ? positive_arg(argv[2], "THICKNESS") : 400.0;
  const std::filesystem::path study_file =
      argc > 3 ? std::filesystem::path(argv[3])
               : std::filesystem::path(CREVASSE_SOURCE_DIR) / "studies/whole_case_cost.json";
  const crevasse::Study study = crevasse::load_study_file(study_file);
  const crevasse::StudyCase* chosen = nullptr;
  for (const auto& c : study.cases)
    if (c.scene.ice_thickness == thickness) chosen = &c;
  if (!chosen) {
    std::fprintf(stderr, "bench_case: %s has no case with H_i = %g m\n", study_file.string().c_str(), thickness);
    return 2;
  }
  const SceneConfig& scene = chosen->scene;
  tbb::global_control parallelism(tbb::global_control::max_allowed_parallelism, 2);

  const std::string checkpoint =
      (std::filesystem::temp_directory_path() / ("bench_case_" + std::to_string(::getpid()) + ".ckpt")).string();
  std::size_t particles = 0;
  double bytes_per_particle = 0.0;
  {
    const double rss0 = resident_bytes();
    Simulation<2> sim(scene);
    sim.settle();
    sim.step();  // the step's scratch (grid, colouring) allocated
    bytes_per_particle = (resident_bytes() - rss0) / static_cast<double>(sim.particles().size());
    particles = sim.particles().size();
    sim.save_checkpoint(checkpoint);
  }
  std::printf("case %s (%s): H_i = %g m, dx = %g m, %zu particles, %ld steps per figure\n",
              chosen->case_id.substr(0, 16).c_str(), chosen->label.c_str(), scene.ice_thickness, scene.dx,
              particles, steps);
  std::printf("memory: %.0f B resident per particle (one case, after its first step)\n", bytes_per_particle);

  const double one = run(scene, checkpoint, steps, 1);
  std::printf("(a) one case, 1 thread : %6.2f M particle-steps/s\n", one / 1e6);
  std::printf("(a) one case, 2 threads, by stage:\n");
  const double two_threads = run(scene, checkpoint, steps, 2, true);
  std::printf("(a) one case, 2 threads: %6.2f M particle-steps/s (x%.2f)\n", two_threads / 1e6, two_threads / one);
  double a = 0.0, b = 0.0;
  std::thread first([&] { a = run(scene, checkpoint, steps, 1); });
  std::thread second([&] { b = run(scene, checkpoint, steps, 1); });
  first.join();
  second.join();
  std::printf("(c) two cases at once, 1 thread each: %6.2f M particle-steps/s together (x%.2f one case)\n",
              (a + b) / 1e6, (a + b) / one);
  std::filesystem::remove(checkpoint);
  return 0;
}
