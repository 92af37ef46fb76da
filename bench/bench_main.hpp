#pragma once
// main() of a benchmark program whose cases are registered at run time (names built from the
// dimension, material and thread count).
#include <benchmark/benchmark.h>

namespace crevasse::bench {

template <class Register>
int run_benchmarks(int argc, char** argv, Register&& register_all) {
  register_all();
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}

}  // namespace crevasse::bench
