#include "analysis/damage_clusters.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <stdexcept>
#include <string>

namespace crevasse::analysis {

namespace {

class DisjointSets {
 public:
  explicit DisjointSets(std::size_t n) : parent_(n), size_(n, 1) {
    std::iota(parent_.begin(), parent_.end(), 0u);
  }
  std::uint32_t find(std::uint32_t a) {
    while (parent_[a] != a) {
      parent_[a] = parent_[parent_[a]];  // path halving keeps trees shallow
      a = parent_[a];
    }
    return a;
  }
  void unite(std::uint32_t a, std::uint32_t b) {
    a = find(a);
    b = find(b);
    if (a == b) return;
    if (size_[a] < size_[b]) std::swap(a, b);
    parent_[b] = a;
    size_[a] += size_[b];
  }

 private:
  std::vector<std::uint32_t> parent_;
  std::vector<std::uint32_t> size_;
};

}  // namespace

DamageClusters find_damage_clusters(std::span<const double> x, std::span<const double> z,
                                    std::span<const std::uint8_t> damaged, double link_distance_m,
                                    const std::function<void()>& poll) {
  if (x.size() != z.size() || x.size() != damaged.size()) {
    throw std::invalid_argument("damage clusters: x, z and damage arrays differ in length");
  }
  if (!(link_distance_m > 0.0) || !std::isfinite(link_distance_m)) {
    throw std::invalid_argument("damage clusters: link distance must be > 0 m, got " +
                                std::to_string(link_distance_m));
  }
  DamageClusters result;
  result.label.assign(x.size(), DamageClusters::kNone);

  std::vector<std::uint32_t> members;  // indices of damaged particles
  for (std::size_t p = 0; p < x.size(); ++p) {
    if (damaged[p]) members.push_back(static_cast<std::uint32_t>(p));
  }
  if (members.empty()) return result;

  // Cells of side = link distance: every partner of a particle lies in its 3×3 block.
  double x_min = x[members[0]], z_min = z[members[0]];
  for (auto p : members) {
    x_min = std::min(x_min, x[p]);
    z_min = std::min(z_min, z[p]);
  }
  const double inv = 1.0 / link_distance_m;
  auto cell_of = [&](std::uint32_t p) {
    const auto ix = static_cast<std::uint64_t>((x[p] - x_min) * inv);
    const auto iz = static_cast<std::uint64_t>((z[p] - z_min) * inv);
    return (ix << 32) | iz;
  };
  std::vector<std::uint64_t> key(members.size());
  std::vector<std::uint32_t> order(members.size());
  for (std::size_t k = 0; k < members.size(); ++k) key[k] = cell_of(members[k]);
  std::iota(order.begin(), order.end(), 0u);
  std::sort(order.begin(), order.end(), [&](auto a, auto b) { return key[a] < key[b]; });
  std::vector<std::uint64_t> sorted_key(members.size());
  for (std::size_t k = 0; k < order.size(); ++k) sorted_key[k] = key[order[k]];

  const double link2 = link_distance_m * link_distance_m;
  DisjointSets sets(members.size());
  // i, j: positions in the cell-sorted order.
  auto link_if_close = [&](std::size_t i, std::size_t j) {
    const auto a = members[order[i]], b = members[order[j]];
    const double ddx = x[a] - x[b], ddz = z[a] - z[b];
    if (ddx * ddx + ddz * ddz <= link2) sets.unite(order[i], order[j]);
  };
  // Each unordered pair of cells is visited once: the cell itself and four forward neighbours.
  constexpr int kForward[4][2] = {{0, 1}, {1, -1}, {1, 0}, {1, 1}};
  std::size_t begin = 0;
  for (std::size_t cells = 0; begin < order.size(); ++cells) {
    if (poll && cells % 1024 == 0) poll();
    std::size_t end = begin;
    while (end < order.size() && sorted_key[end] == sorted_key[begin]) ++end;
    for (std::size_t i = begin; i < end; ++i) {
      for (std::size_t j = i + 1; j < end; ++j) link_if_close(i, j);
    }
    const auto ix = static_cast<std::int64_t>(sorted_key[begin] >> 32);
    const auto iz = static_cast<std::int64_t>(sorted_key[begin] & 0xffffffffu);
    for (const auto& d : kForward) {
      const std::int64_t nx = ix + d[0], nz = iz + d[1];
      if (nz < 0) continue;
      const std::uint64_t nk =
          (static_cast<std::uint64_t>(nx) << 32) | static_cast<std::uint64_t>(nz);
      auto lo = std::lower_bound(sorted_key.begin(), sorted_key.end(), nk);
      for (auto it = lo; it != sorted_key.end() && *it == nk; ++it) {
        const auto j = static_cast<std::size_t>(it - sorted_key.begin());
        for (std::size_t i = begin; i < end; ++i) link_if_close(i, j);
      }
    }
    begin = end;
  }

  std::vector<std::int32_t> root_label(members.size(), DamageClusters::kNone);
  for (std::size_t k = 0; k < members.size(); ++k) {
    const auto r = sets.find(static_cast<std::uint32_t>(k));
    if (root_label[r] == DamageClusters::kNone) {
      root_label[r] = static_cast<std::int32_t>(result.count++);
    }
    result.label[members[k]] = root_label[r];
  }
  return result;
}

}  // namespace crevasse::analysis
