// Throughput of the engine's full step: particle-steps per second of
// Simulation<Dim>::step() on the benchmark block (bench_scene.hpp), 2D and 3D, elastic and
// softening, at 1 and 2 threads. Counters per case:
//  * particle_steps_per_s (rate over wall time) and ns_<stage>: wall nanoseconds per
//    particle-step of each named stage of the step (Simulation::stages());
//  * particle_B / grid_B: bytes per particle of the per-particle arrays of Particles<Dim>
//    (capacity × element size) and of the background grid (GridNode per node);
//  * sortstep/…: sort_step_peak_heap_B, the peak heap per particle during step 100 (a later
//    sorting step, arrays at their steady size), against heap_B just before it;
//  * heap_B / peak_heap_B / first_step_peak_heap_B: live heap held by the simulation after the
//    measured steps, its peak during them, and its peak during the first step (which sorts
//    the particles), per particle (everything: particles, grid, scratch, bed table);
//  * allocs_per_step / alloc_B_per_step: operator new calls and bytes during the measured
//    steps, per step. This program replaces the global operator new to count them.
#include <benchmark/benchmark.h>
#include <malloc.h>
#include <tbb/global_control.h>

#include <atomic>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <new>
#include <string>
#include <vector>

#include "bench/bench_main.hpp"
#include "bench/bench_scene.hpp"
#include "bench/shipped_scene.hpp"
#include "engine/simulation.hpp"

namespace {

// Heap accounting for every operator new/delete in the process (engine, TBB's users of
// std containers, the benchmark library). Sizes are the allocator's usable sizes, so live
// bytes are what the process really holds.
std::atomic<std::int64_t> g_alloc_count{0};
std::atomic<std::int64_t> g_alloc_bytes{0};
std::atomic<std::int64_t> g_live_bytes{0};
std::atomic<std::int64_t> g_peak_bytes{0};

void record_alloc(void* p) {
  const auto size = static_cast<std::int64_t>(malloc_usable_size(p));
  g_alloc_count.fetch_add(1, std::memory_order_relaxed);
  g_alloc_bytes.fetch_add(size, std::memory_order_relaxed);
  const std::int64_t live = g_live_bytes.fetch_add(size, std::memory_order_relaxed) + size;
  std::int64_t peak = g_peak_bytes.load(std::memory_order_relaxed);
  while (live > peak &&
         !g_peak_bytes.compare_exchange_weak(peak, live, std::memory_order_relaxed)) {
  }
}

void record_free(void* p) {
  if (p)
    g_live_bytes.fetch_sub(static_cast<std::int64_t>(malloc_usable_size(p)),
                           std::memory_order_relaxed);
}

void* counted_new(std::size_t size, std::size_t align) {
  if (size == 0) size = 1;
  void* p = align <= alignof(std::max_align_t)
                ? std::malloc(size)
                : std::aligned_alloc(align, (size + align - 1) / align * align);
  if (!p) throw std::bad_alloc();
  record_alloc(p);
  return p;
}

void counted_delete(void* p) {
  record_free(p);
  std::free(p);
}

}  // namespace

// libstdc++'s array, nothrow and sized forms forward to these four.
void* operator new(std::size_t size) { return counted_new(size, alignof(std::max_align_t)); }
void* operator new(std::size_t size, std::align_val_t align) {
  return counted_new(size, static_cast<std::size_t>(align));
}
void operator delete(void* p) noexcept { counted_delete(p); }
void operator delete(void* p, std::align_val_t) noexcept { counted_delete(p); }
void operator delete(void* p, std::size_t) noexcept { counted_delete(p); }
void operator delete(void* p, std::size_t, std::align_val_t) noexcept { counted_delete(p); }

namespace crevasse::bench {
namespace {

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
  const std::int64_t heap_before = g_live_bytes.load();
  Simulation<Dim> sim(scene);
  // The first step sorts the particles (as every 100th does) while the arrays still have the
  // spare capacity of seeding: its peak is reported on its own.
  g_peak_bytes.store(g_live_bytes.load());
  sim.step();
  const double first_peak = static_cast<double>(g_peak_bytes.load() - heap_before);
  for (int i = 1; i < kWarmupSteps; ++i) sim.step();
  g_peak_bytes.store(g_live_bytes.load());

  const std::vector<StageStats> stages_before = sim.stages();
  const std::int64_t psteps_before = sim.particle_steps();
  const std::int64_t steps_before = sim.steps();
  const std::int64_t allocs_before = g_alloc_count.load();
  const std::int64_t alloc_bytes_before = g_alloc_bytes.load();

  for (auto _ : state) sim.step();

  const double steps = static_cast<double>(sim.steps() - steps_before);
  const double allocs = static_cast<double>(g_alloc_count.load() - allocs_before);
  const double alloc_bytes = static_cast<double>(g_alloc_bytes.load() - alloc_bytes_before);
  const double peak = static_cast<double>(g_peak_bytes.load() - heap_before);
  const double heap = static_cast<double>(g_live_bytes.load() - heap_before);
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
  c["heap_B"] = heap / n;
  c["peak_heap_B"] = peak / n;
  c["first_step_peak_heap_B"] = first_peak / n;
  c["allocs_per_step"] = allocs / steps;
  c["alloc_B_per_step"] = alloc_bytes / steps;
  if (sim.particles().has_plastic_state()) {
    double yielded = 0.0;
    for (double e : sim.particles().eps_v_p) yielded += e > 0.0 ? 1.0 : 0.0;
    c["yielded_fraction"] = yielded / n;
  }
}

// Peak heap of a later sorting step (step 100: the particles are re-sorted every 100 steps),
// once the arrays have their steady size: the steady heap plus the sort's own temporaries.
template <int Dim>
void sort_step_benchmark(benchmark::State& state, const SceneConfig& scene) {
  const std::int64_t heap_before = g_live_bytes.load();
  Simulation<Dim> sim(scene);
  for (auto _ : state) {
    while (sim.steps() < 100) sim.step();  // steps 0..99; step 100 sorts again
    g_peak_bytes.store(g_live_bytes.load());
    const double steady = static_cast<double>(g_live_bytes.load() - heap_before);
    sim.step();
    const double n = static_cast<double>(sim.particles().size());
    state.counters["heap_B"] = steady / n;
    state.counters["sort_step_peak_heap_B"] = static_cast<double>(g_peak_bytes.load() - heap_before) / n;
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
