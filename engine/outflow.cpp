#include "engine/outflow.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_reduce.h>

#include <algorithm>
#include <vector>

namespace crevasse {

template <int Dim>
bool Outflow<Dim>::remove(Particles<Dim>& P, GateRecorder<Dim>* gate, std::optional<double> front) {
  constexpr std::size_t kGrain = 1024;
  const double x_out = x_line_;
  if (front && *front < x_out) return false;
  // The particles are sorted with x slowest, so those past the line sit near the end and
  // everything before the first stays where it is.
  const std::size_t n = P.size();
  const std::size_t first = tbb::parallel_reduce(
      tbb::blocked_range<std::size_t>(0, n, kGrain), n,
      [&](const auto& r, std::size_t found) {
        for (std::size_t p = r.begin(); p != r.end() && p < found; ++p)
          if (!(P.x[p][0] < x_out)) found = p;
        return found;
      },
      [](std::size_t a, std::size_t b) { return std::min(a, b); });
  if (first == n) return false;
  std::vector<char> keep(n, 1);
  for (std::size_t p = first; p < n; ++p) keep[p] = P.x[p][0] < x_out;
  if (gate) gate->archive_removed(P, keep, first);
  removed_mass_ += P.compact(keep, first);
  return true;
}

template class Outflow<2>;
template class Outflow<3>;

}  // namespace crevasse
