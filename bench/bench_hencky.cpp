// The 2D stress update's eigen-solve on its own: principal Hencky strain
// and Kirchhoff stress of 250,000 elastic deformation gradients like the engine's (strains of
// ~1e-3 in random frames, random rotations), per particle:
//   hencky/2d/eigen        Eigen's SelfAdjointEigenSolver::computeDirect of F Fᵀ − I and
//                          τ = U diag(τ_i) Uᵀ (the engine's path before the closed form);
//   hencky/2d/closed_form  principal_hencky<2> + kirchhoff_stress<2> (engine/hencky.hpp);
//   hencky/3d/eigen        the 3D path (Eigen's direct solver), for scale.
// One thread, the engine's flags. Counter ns_per_particle.
#include <benchmark/benchmark.h>

#include <Eigen/Eigenvalues>
#include <cmath>
#include <random>
#include <vector>

#include "engine/hencky.hpp"

namespace {

using namespace crevasse;
constexpr std::size_t kParticles = 250000;

template <int Dim>
std::vector<Mat<Dim>> elastic_gradients() {
  std::mt19937_64 rng(6);
  std::uniform_real_distribution<double> strain(-1e-3, 1e-3);
  std::vector<Mat<Dim>> f(kParticles);
  for (auto& F : f) {
    Mat<Dim> h;
    for (int i = 0; i < Dim; ++i)
      for (int j = 0; j < Dim; ++j) h(i, j) = strain(rng);
    const Mat<Dim> stretch = Mat<Dim>::Identity() + 0.5 * (h + h.transpose());
    // A rotation from the QR factor of a random matrix.
    Mat<Dim> g;
    for (int i = 0; i < Dim; ++i)
      for (int j = 0; j < Dim; ++j) g(i, j) = std::uniform_real_distribution<double>(-1, 1)(rng);
    Mat<Dim> q = Eigen::HouseholderQR<Mat<Dim>>(g).householderQ();
    if (q.determinant() < 0) q.col(0) *= -1.0;
    F = q * stretch;
  }
  return f;
}

template <int Dim>
Mat<Dim> eigen_stress(const ElasticModuli& m, const Mat<Dim>& F) {
  const Mat<Dim> b_minus_i = F * F.transpose() - Mat<Dim>::Identity();
  Eigen::SelfAdjointEigenSolver<Mat<Dim>> eig;
  eig.computeDirect(b_minus_i);
  Vec<Dim> eps;
  for (int a = 0; a < Dim; ++a) eps[a] = 0.5 * std::log1p(eig.eigenvalues()[a]);
  return eig.eigenvectors() * principal_kirchhoff<Dim>(m, eps).asDiagonal() *
         eig.eigenvectors().transpose();
}

template <int Dim, bool ClosedForm>
void run(benchmark::State& state) {
  const auto f = elastic_gradients<Dim>();
  const ElasticModuli m = ElasticModuli::from_young_poisson(1e9, 0.3);
  std::vector<Mat<Dim>> tau(kParticles);
  for (auto _ : state) {
    for (std::size_t p = 0; p < kParticles; ++p) {
      if constexpr (ClosedForm) {
        tau[p] = kirchhoff_stress<Dim>(m, principal_hencky<Dim>(f[p]));
      } else {
        tau[p] = eigen_stress<Dim>(m, f[p]);
      }
    }
    benchmark::DoNotOptimize(tau.data());
    benchmark::ClobberMemory();
  }
  state.counters["ns_per_particle"] = benchmark::Counter(
      static_cast<double>(kParticles) * state.iterations(),
      benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}

BENCHMARK(run<2, false>)->Name("hencky/2d/eigen")->Unit(benchmark::kMillisecond);
BENCHMARK(run<2, true>)->Name("hencky/2d/closed_form")->Unit(benchmark::kMillisecond);
BENCHMARK(run<3, false>)->Name("hencky/3d/eigen")->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
