// The the limit kernel: only the work no MLS-MPM step can avoid, for the particles of
// the benchmark scene (bench_scene.hpp, seeded by the engine itself, so the count and order
// are the same as bench_step's). Per step:
//  1. clear the grid (a fixed box around the particles, fitted once);
//  2. P2G: read x, v, C, τ, m, V0 of each particle once and scatter mass and MLS momentum to
//     its 3^Dim quadratic B-spline nodes (race-free: x-slabs of 4 cells in two colours);
//  3. grid update: momentum → velocity, plus gravity;
//  4. G2P: gather v and C from the same nodes, then write x, v, C, F ← (I + Δt C) F and τ once,
//     with the largest speed reduced on the fly for the next CFL time step.
// The stress is a linear stand-in (small-strain Hooke's law on F), not a material model: it
// only makes τ a function of F, written once. The storage layout is the engine's (one array of
// Eigen fixed-size vectors/matrices per field, double). Counters: particle_steps_per_s and
// state_B (bytes per particle of the state read and written); ns per particle-step of P2G (with
// the grid clear), the grid update and G2P.
// limit_averaging/… runs the same kernel with the ΔJ-bar volume average that the engine's
// default scheme adds (grid_to_particle_averaged): the least work of that scheme, with no
// material model. Both kernels use the engine's stencil code (AffineTerms, gather_apic).
#include <benchmark/benchmark.h>
#include <tbb/blocked_range.h>
#include <tbb/global_control.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <numeric>
#include <string>
#include <vector>

#include "bench/bench_main.hpp"
#include "bench/bench_scene.hpp"
#include "engine/bspline.hpp"
#include "engine/simulation.hpp"

namespace crevasse::bench {
namespace {

constexpr int kSlabCells = 4;
constexpr std::size_t kGrain = 1024;

template <int Dim>
class LimitKernel {
 public:
  // averaging: the ΔJ-bar volume average of the engine's default scheme as well (below).
  LimitKernel(const SceneConfig& scene, bool averaging)
      : averaging_(averaging),
        dx_(scene.dx),
        cfl_(scene.cfl),
        p_wave_speed_(scene.p_wave_speed()),
        moduli_(ElasticModuli::from_young_poisson(scene.youngs_modulus, scene.poisson_ratio)) {
    gravity_[up_axis<Dim>] = -scene.gravity;
    const Simulation<Dim> seeded(scene);
    const Particles<Dim>& P = seeded.particles();
    const std::size_t n = P.size();
    // Sorted by stencil base along x, so that each x-slab of P2G is one contiguous range.
    std::vector<std::uint32_t> order(n);
    std::iota(order.begin(), order.end(), 0u);
    const auto base_x = [&](std::size_t p) {
      return static_cast<int>(std::floor(P.x[p][0] / dx_ - 0.5));
    };
    std::stable_sort(order.begin(), order.end(),
                     [&](auto a, auto b) { return base_x(a) < base_x(b); });
    for (std::uint32_t p : order) {
      x_.push_back(P.x[p]);
      F_.push_back(P.F_e[p]);
      tau_.push_back(P.tau[p]);
      mass_.push_back(P.mass[p]);
      vol0_.push_back(P.vol0[p]);
    }
    v_.assign(n, Vec<Dim>::Zero());
    C_.assign(n, Mat<Dim>::Zero());

    // Grid box: the particles' stencils plus two cells of room on every side.
    IVec<Dim> lo = IVec<Dim>::Constant(std::numeric_limits<int>::max());
    IVec<Dim> hi = IVec<Dim>::Constant(std::numeric_limits<int>::min());
    for (const auto& x : x_) {
      for (int a = 0; a < Dim; ++a) {
        const int b = static_cast<int>(std::floor(x[a] / dx_ - 0.5));
        lo[a] = std::min(lo[a], b - 2);
        hi[a] = std::max(hi[a], b + 4);
      }
    }
    grid_lo_ = lo;
    grid_n_ = (hi - lo).array() + 1;
    std::size_t nodes = 1;
    for (int a = 0; a < Dim; ++a) nodes *= static_cast<std::size_t>(grid_n_[a]);
    grid_.assign(nodes, Node::Zero());
    if (averaging_) aux_.assign(nodes, 0.0);
    for (int a = Dim - 1; a >= 0; --a)
      stride_[a] = a == Dim - 1 ? 1 : stride_[a + 1] * static_cast<std::size_t>(grid_n_[a + 1]);

    // Slab s holds the particles with base_x − lo_x in [4s, 4s + 4): it writes node columns
    // 4s .. 4s + 5, two columns short of slab s + 2, so a particle may drift almost two cells
    // during a benchmark before slabs of one colour could share a node.
    const int slabs = (grid_n_[0] + kSlabCells - 1) / kSlabCells;
    slab_begin_.assign(static_cast<std::size_t>(slabs) + 1, n);
    slab_begin_[0] = 0;
    std::size_t p = 0;
    for (int s = 1; s <= slabs; ++s) {
      while (p < n && (base_x_of(x_[p]) - grid_lo_[0]) / kSlabCells < s) ++p;
      slab_begin_[static_cast<std::size_t>(s)] = p;
    }
    dt_ = cfl_ * dx_ / p_wave_speed_;
    d_inv_ = 4.0 / (dx_ * dx_);
  }

  std::size_t size() const { return x_.size(); }

  double state_bytes_per_particle() const {
    return sizeof(Vec<Dim>) * 2 + sizeof(Mat<Dim>) * 3 + sizeof(double) * 2;
  }

  void step() {
    using clock = std::chrono::steady_clock;
    const auto t0 = clock::now();
    clear_grid();
    particle_to_grid();
    const auto t1 = clock::now();
    grid_update();
    const auto t2 = clock::now();
    const double vmax = averaging_ ? grid_to_particle_averaged() : grid_to_particle();
    dt_ = cfl_ * dx_ / (p_wave_speed_ + vmax);
    const auto t3 = clock::now();
    phase_seconds_[0] += std::chrono::duration<double>(t1 - t0).count();
    phase_seconds_[1] += std::chrono::duration<double>(t2 - t1).count();
    phase_seconds_[2] += std::chrono::duration<double>(t3 - t2).count();
  }

  // Seconds spent in (grid clear + P2G, grid update, G2P) since the last reset.
  static constexpr std::array<const char*, 3> kPhases = {"p2g", "grid", "g2p"};
  const std::array<double, 3>& phase_seconds() const { return phase_seconds_; }
  void reset_phase_seconds() { phase_seconds_ = {}; }

 private:
  int base_x_of(const Vec<Dim>& x) const { return static_cast<int>(std::floor(x[0] / dx_ - 0.5)); }

  std::size_t flat(const IVec<Dim>& node) const {
    std::size_t f = 0;
    for (int a = 0; a < Dim; ++a) f += static_cast<std::size_t>(node[a] - grid_lo_[a]) * stride_[a];
    return f;
  }

  void clear_grid() {
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, grid_.size(), 16 * kGrain),
                      [&](const auto& r) {
                        std::fill(grid_.begin() + r.begin(), grid_.begin() + r.end(), Node::Zero());
                        if (averaging_) std::fill(aux_.begin() + r.begin(), aux_.begin() + r.end(), 0.0);
                      });
  }

  // Calls fn(p) for every particle, slab by slab in two colours: slabs of one colour share no
  // grid node, so they run in parallel and a scatter needs no atomics.
  template <class Fn>
  void for_each_coloured(Fn&& fn) {
    const int slabs = static_cast<int>(slab_begin_.size()) - 1;
    for (int colour = 0; colour < 2; ++colour) {
      tbb::parallel_for(0, (slabs + 1 - colour) / 2, [&](int half) {
        const std::size_t s = static_cast<std::size_t>(2 * half + colour);
        for (std::size_t p = slab_begin_[s]; p < slab_begin_[s + 1]; ++p) fn(p);
      });
    }
  }

  void particle_to_grid() {
    const double inv_dx = 1.0 / dx_;
    for_each_coloured([&](std::size_t p) {
      const Vec<Dim> xg = x_[p] * inv_dx;
      const StencilWeights<Dim> w(xg);
      const double m = mass_[p];
      const Mat<Dim> affine = m * C_[p] - (dt_ * d_inv_ * vol0_[p]) * tau_[p];
      const Vec<Dim> mv = m * v_[p];
      const AffineTerms<Dim> ad(affine, StencilOffsets<Dim>(w, xg, dx_));  // as the engine's P2G
      for_each_stencil_node<Dim>(w, flat(w.base()), stride_,
                                 [&](const IVec<Dim>& off, std::size_t f, double wt) {
        Node& g = grid_[f];
        g[0] += wt * m;
        g.template tail<Dim>() += wt * (mv + ad.at(off));
      });
    });
  }

  void grid_update() {
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, grid_.size(), 16 * kGrain),
                      [&](const auto& r) {
                        for (std::size_t f = r.begin(); f != r.end(); ++f) {
                          Node& g = grid_[f];
                          if (g[0] > 0.0)
                            g.template tail<Dim>() = g.template tail<Dim>() / g[0] + dt_ * gravity_;
                        }
                      });
  }

  // Gathers v and C of particle p (at grid coordinate xg, weights w) from the grid, as the
  // engine gathers (gather_apic).
  void gather(const StencilWeights<Dim>& w, const Vec<Dim>& xg, Vec<Dim>& vel, Mat<Dim>& c) const {
    Mat<Dim> b;
    gather_apic<Dim>(w, StencilOffsets<Dim>(w, xg, dx_), flat(w.base()), stride_,
                     [this](std::size_t f) { return grid_[f].template tail<Dim>(); }, vel, b);
    c = d_inv_ * b;
  }

  // Moves particle p and writes its F and τ: a linear stand-in for the stress,
  // τ = 2μ ε + λ tr(ε) I with ε = sym(F) − I (not a material model: τ only has to be a function
  // of F, written once). Returns |v|² for the time step's reduction.
  double move_and_write(std::size_t p, const Vec<Dim>& vel, const Mat<Dim>& f) {
    const Mat<Dim> eps = 0.5 * (f + f.transpose()) - Mat<Dim>::Identity();
    x_[p] += dt_ * vel;
    F_[p] = f;
    tau_[p] = 2.0 * moduli_.mu * eps + (moduli_.lambda * eps.trace()) * Mat<Dim>::Identity();
    return vel.squaredNorm();
  }

  // The largest speed over the particles of fn(p) (which returns |v|²), in parallel.
  template <class Fn>
  double max_speed(Fn&& fn) {
    const double v2 = tbb::parallel_reduce(
        tbb::blocked_range<std::size_t>(0, x_.size(), kGrain), 0.0,
        [&](const auto& r, double acc) {
          for (std::size_t p = r.begin(); p != r.end(); ++p) acc = std::max(acc, fn(p));
          return acc;
        },
        [](double a, double b) { return std::max(a, b); });
    return std::sqrt(v2);
  }

  // Returns the largest particle speed after the update.
  double grid_to_particle() {
    const double inv_dx = 1.0 / dx_;
    return max_speed([&](std::size_t p) {
      const Vec<Dim> xg = x_[p] * inv_dx;
      Vec<Dim> vel;
      Mat<Dim> c;
      gather(StencilWeights<Dim>(xg), xg, vel, c);
      v_[p] = vel;
      C_[p] = c;
      return move_and_write(p, vel, (Mat<Dim>::Identity() + dt_ * c) * F_[p]);
    });
  }

  // G2P with the ΔJ-bar volume average, in its least form: the unavoidable work the engine's
  // default scheme adds to the step above (no material model, no damage weighting). (1) In the
  // coloured slab order of P2G (it scatters), gather v and C, write them, and scatter
  // m·ΔJ, ΔJ = det(I + Δt C), with the same weights; (2) per node, divide by the node's mass;
  // (3) gather ΔJ̄ and write x, F ← (ΔJ̄/ΔJ)^(1/d)·(I + Δt C)·F and τ once. So one stencil
  // scatter and one stencil gather of a scalar more than grid_to_particle, and v, C read back.
  double grid_to_particle_averaged() {
    const double inv_dx = 1.0 / dx_;
    for_each_coloured([&](std::size_t p) {
      const Vec<Dim> xg = x_[p] * inv_dx;
      const StencilWeights<Dim> w(xg);
      gather(w, xg, v_[p], C_[p]);
      const double wdj = mass_[p] * (Mat<Dim>::Identity() + dt_ * C_[p]).determinant();
      for_each_stencil_node<Dim>(w, flat(w.base()), stride_,
                                 [&](const IVec<Dim>&, std::size_t f, double wt) { aux_[f] += wt * wdj; });
    });
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, grid_.size(), 16 * kGrain),
                      [&](const auto& r) {
                        for (std::size_t f = r.begin(); f != r.end(); ++f)
                          if (grid_[f][0] > 0.0) aux_[f] /= grid_[f][0];
                      });
    return max_speed([&](std::size_t p) {
      const StencilWeights<Dim> w(Vec<Dim>(x_[p] * inv_dx));
      double jbar = 0.0;
      for_each_stencil_node<Dim>(w, flat(w.base()), stride_,
                                 [&](const IVec<Dim>&, std::size_t f, double wt) { jbar += wt * aux_[f]; });
      const Mat<Dim> df = Mat<Dim>::Identity() + dt_ * C_[p];
      const double ratio = jbar / df.determinant();
      const double scale = Dim == 2 ? std::sqrt(ratio) : std::cbrt(ratio);
      return move_and_write(p, v_[p], scale * df * F_[p]);
    });
  }

  std::array<double, 3> phase_seconds_{};
  bool averaging_;
  double dx_, cfl_, p_wave_speed_;
  ElasticModuli moduli_;
  double dt_ = 0.0;
  double d_inv_ = 0.0;  // 4/dx², the MLS inertia's inverse
  Vec<Dim> gravity_ = Vec<Dim>::Zero();
  std::vector<Vec<Dim>> x_, v_;
  std::vector<Mat<Dim>> C_, F_, tau_;
  std::vector<double> mass_, vol0_;
  IVec<Dim> grid_lo_, grid_n_;
  // One node = (mass, momentum), velocity after the grid update: one cache line per node
  // touched instead of two arrays.
  using Node = Eigen::Matrix<double, Dim + 1, 1>;
  std::vector<Node> grid_;
  std::vector<double> aux_;  // per node: Σ w m ΔJ, then ΔJ̄ (averaging only)
  std::array<std::size_t, Dim> stride_{};
  std::vector<std::size_t> slab_begin_;
};

template <int Dim>
void limit_benchmark(benchmark::State& state, int threads, bool averaging) {
  tbb::global_control parallelism(tbb::global_control::max_allowed_parallelism,
                                  static_cast<std::size_t>(threads));
  LimitKernel<Dim> kernel(block_scene(Dim, Material::elastic), averaging);
  for (int i = 0; i < kWarmupSteps; ++i) kernel.step();
  kernel.reset_phase_seconds();
  std::int64_t psteps = 0;
  for (auto _ : state) {
    kernel.step();
    psteps += static_cast<std::int64_t>(kernel.size());
  }
  auto& c = state.counters;
  c["particles"] = static_cast<double>(kernel.size());
  c["particle_steps_per_s"] =
      benchmark::Counter(static_cast<double>(psteps), benchmark::Counter::kIsRate);
  c["state_B"] = kernel.state_bytes_per_particle();
  // ns per particle-step of each phase, as bench_step reports the engine's stages.
  for (std::size_t k = 0; k < LimitKernel<Dim>::kPhases.size(); ++k)
    c[std::string("ns_") + LimitKernel<Dim>::kPhases[k]] =
        1e9 * kernel.phase_seconds()[k] / static_cast<double>(psteps);
}

void register_all() {
  // limit/…: the limit kernel. limit_averaging/…: the same with the ΔJ-bar average
  // (grid_to_particle_averaged), what the engine's default scheme cannot avoid either.
  for (bool averaging : {false, true}) {
    for (int dim : {2, 3}) {
      for (int threads : {1, 2}) {
        const std::string name = std::string(averaging ? "limit_averaging/" : "limit/") +
                                 std::to_string(dim) + "d/threads:" + std::to_string(threads);
        auto* b = dim == 2 ? benchmark::RegisterBenchmark(name.c_str(), limit_benchmark<2>, threads, averaging)
                           : benchmark::RegisterBenchmark(name.c_str(), limit_benchmark<3>, threads, averaging);
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
