// Throughput of the engine's full step: particle-steps per second of
// Simulation<Dim>::step() on the benchmark block (bench_scene.hpp), 2D and 3D, elastic and
// softening, at 1 and 2 threads. Counters per case:
//  * particle_steps_per_s (rate over wall time) and ns_<stage>: wall nanoseconds per
//    particle-step of each named stage of the step (Simulation::stages());
//  * particle_B / grid_B: bytes per particle of the per-particle arrays of Particles<Dim>
//    (capacity × element size) and of the background grid (GridNode per node);
//  * sortstep/…: heap_B just before step 100 (a later sorting step, arrays at their steady
//    size) and sort_step_peak_B, the peak per particle during it;
//  * heap_B: heap the simulation holds after the measured steps, per particle (everything:
//    particles, grid, scratch, bed table), from glibc's own count of bytes in use (mallinfo2);
//  * peak_B / first_step_peak_B: the peak during the measured steps and during the first step
//    (which sorts the particles), per particle: the heap held when they start plus what they
//    make resident beyond what was resident then (the kernel's high-water mark VmHWM, restarted
//    through /proc/self/clear_refs), so that a temporary buffer counts once it is touched;
//  * heap_growth_B_per_step: heap in use after the measured steps minus before them, per step
//    (0 when a step gives back all it takes; allocations themselves are not counted).
#include <benchmark/benchmark.h>
#include <malloc.h>
#include <tbb/global_control.h>

#include <cmath>
#include <fstream>
#include <limits>
#include <string>
#include <vector>

#include "bench/bench_main.hpp"
#include "bench/bench_scene.hpp"
#include "bench/shipped_scene.hpp"
#include "engine/simulation.hpp"

namespace crevasse::bench {
namespace {

// Bytes malloc has handed out and not had back, over all arenas and mmapped chunks.
double heap_in_use() {
  const struct mallinfo2 m = mallinfo2();
  return static_cast<double>(m.uordblks + m.hblkhd);
}

// A "Vm…:" line of /proc/self/status in bytes (NaN when absent).
double status_bytes(const std::string& key) {
  std::ifstream status("/proc/self/status");
  for (std::string line; std::getline(status, line);)
    if (line.rfind(key + ":", 0) == 0) return 1024.0 * std::stod(line.substr(key.size() + 1));
  return std::numeric_limits<double>::quiet_NaN();
}

// Hands freed memory back to the kernel (so that reusing it counts as touching it) and restarts
// the resident high-water mark at the resident size. Returns that size (bytes), or NaN where the
// mark cannot be restarted (the peaks then read NaN, not the process's lifetime peak).
double restart_peak() {
  malloc_trim(0);
  std::ofstream clear_refs("/proc/self/clear_refs");
  clear_refs << "5" << std::flush;
  return clear_refs ? status_bytes("VmRSS") : std::numeric_limits<double>::quiet_NaN();
}

// Bytes made resident since restart_peak() returned `rss_at_restart`, at their peak.
double resident_growth(double rss_at_restart) { return status_bytes("VmHWM") - rss_at_restart; }

template <class T>
double vector_bytes(const std::vector<T>& v) {
  return static_cast<double>(v.capacity() * sizeof(T));
}

template <int Dim>
double particle_array_bytes(const Particles<Dim>& P) {
  return vector_bytes(P.x) + vector_bytes(P.v) + vector_bytes(P.C) + vector_bytes(P.F_e) +
         vector_bytes(P.tau) + vector_bytes(P.mass) + vector_bytes(P.vol0) +
         vector_bytes(P.eps_v_p) + vector_bytes(P.drive_x0);
}

// Nodes of the grid box the engine fits to the particles' stencils (Grid<Dim>: one GridNode of
// mass, intact mass and velocity per node).
template <int Dim>
double grid_bytes(const Particles<Dim>& P, double dx) {
  IVec<Dim> lo = IVec<Dim>::Constant(std::numeric_limits<int>::max());
  IVec<Dim> hi = IVec<Dim>::Constant(std::numeric_limits<int>::min());
  for (std::size_t p = 0; p < P.size(); ++p) {
    for (int a = 0; a < Dim; ++a) {
      const int b = static_cast<int>(std::floor(P.x[p][a] / dx - 0.5));
      lo[a] = std::min(lo[a], b);
      hi[a] = std::max(hi[a], b + 2);
    }
  }
  double nodes = 1.0;
  for (int a = 0; a < Dim; ++a) nodes *= hi[a] - lo[a] + 1;
  return nodes * sizeof(GridNode<Dim>);
}

template <int Dim>
void step_benchmark(benchmark::State& state, Material material, int threads) {
  tbb::global_control parallelism(tbb::global_control::max_allowed_parallelism,
                                  static_cast<std::size_t>(threads));
  const SceneConfig scene = block_scene(Dim, material);
  const double heap_before = heap_in_use();
  Simulation<Dim> sim(scene);
  // The first step sorts the particles (as every 100th does) while the arrays still have the
  // spare capacity of seeding: its peak is reported on its own.
  double rss = restart_peak();
  const double first_heap = heap_in_use() - heap_before;
  sim.step();
  const double first_growth = resident_growth(rss);
  for (int i = 1; i < kWarmupSteps; ++i) sim.step();
  rss = restart_peak();

  const std::vector<StageStats> stages_before = sim.stages();
  const std::int64_t psteps_before = sim.particle_steps();
  const std::int64_t steps_before = sim.steps();
  const double heap_at_start = heap_in_use();

  for (auto _ : state) sim.step();

  const double steps = static_cast<double>(sim.steps() - steps_before);
  const double heap_at_end = heap_in_use();
  const double peak = heap_at_start - heap_before + resident_growth(rss);
  const double psteps = static_cast<double>(sim.particle_steps() - psteps_before);
  const double n = static_cast<double>(sim.particles().size());

  auto& c = state.counters;
  c["particles"] = n;
  c["particle_steps_per_s"] = benchmark::Counter(psteps, benchmark::Counter::kIsRate);
  for (std::size_t s = 0; s < sim.stages().size(); ++s) {
    const double sec = sim.stages()[s].seconds - stages_before[s].seconds;
    c["ns_" + sim.stages()[s].name] = 1e9 * sec / psteps;
  }
  c["particle_B"] = particle_array_bytes(sim.particles()) / n;
  c["grid_B"] = grid_bytes(sim.particles(), scene.dx) / n;
  c["heap_B"] = (heap_at_end - heap_before) / n;
  c["peak_B"] = peak / n;
  c["first_step_peak_B"] = (first_heap + first_growth) / n;
  c["heap_growth_B_per_step"] = (heap_at_end - heap_at_start) / steps;
  if (sim.particles().has_plastic_state()) {
    double yielded = 0.0;
    for (double e : sim.particles().eps_v_p) yielded += e > 0.0 ? 1.0 : 0.0;
    c["yielded_fraction"] = yielded / n;
  }
}

// Peak memory of a later sorting step (step 100: the particles are re-sorted every 100 steps),
// once the arrays have their steady size: the steady heap plus the sort's own temporaries.
template <int Dim>
void sort_step_benchmark(benchmark::State& state, const SceneConfig& scene) {
  const double heap_before = heap_in_use();
  Simulation<Dim> sim(scene);
  for (auto _ : state) {
    while (sim.steps() < 100) sim.step();  // steps 0..99; step 100 sorts again
    const double steady = heap_in_use() - heap_before;
    const double rss = restart_peak();
    sim.step();
    const double n = static_cast<double>(sim.particles().size());
    state.counters["heap_B"] = steady / n;
    state.counters["sort_step_peak_B"] = (steady + resident_growth(rss)) / n;
  }
}

// The shipped H_i = 300 m glacier (18,000 particles), which also carries the gate records and
// the piston marker, and whose grid box includes the air above the step.
SceneConfig glacier_scene() { return scene_from_json(shipped_scene_json("glacier_2d_H300.json")); }

void register_all() {
  for (int dim : {2, 3}) {
    const std::string name = "sortstep/" + std::to_string(dim) + "d/softening";
    auto* b = dim == 2 ? benchmark::RegisterBenchmark(name.c_str(), sort_step_benchmark<2>,
                                                      block_scene(2, Material::softening))
                       : benchmark::RegisterBenchmark(name.c_str(), sort_step_benchmark<3>,
                                                      block_scene(3, Material::softening));
    b->Iterations(1)->Repetitions(1)->UseRealTime()->Unit(benchmark::kMillisecond);
  }
  benchmark::RegisterBenchmark("sortstep/2d/glacier_H300", sort_step_benchmark<2>, glacier_scene())
      ->Iterations(1)->Repetitions(1)->UseRealTime()->Unit(benchmark::kMillisecond);
  for (int dim : {2, 3}) {
    for (Material m : {Material::elastic, Material::softening}) {
      for (int threads : {1, 2}) {
        const std::string name = "step/" + std::to_string(dim) + "d/" + material_name(m) +
                                 "/threads:" + std::to_string(threads);
        auto* b = dim == 2
                      ? benchmark::RegisterBenchmark(name.c_str(), step_benchmark<2>, m, threads)
                      : benchmark::RegisterBenchmark(name.c_str(), step_benchmark<3>, m, threads);
        b->Iterations(measured_steps(dim))->UseRealTime()->Unit(benchmark::kMillisecond);
      }
    }
  }
}

}  // namespace
}  // namespace crevasse::bench

int main(int argc, char** argv) {
  return crevasse::bench::run_benchmarks(argc, argv, crevasse::bench::register_all);
}
