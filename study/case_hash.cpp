#include "study/case_hash.hpp"

#include <array>
#include <cstdint>

namespace crevasse {
namespace {

// SHA-256 round constants and initial hash values are the first 32 fractional bits of the cube
// and square roots of the first primes (FIPS 180-4 §4.2.2, §5.3.3). They are computed here with
// exact integer roots instead of being typed in as tables.
using u128 = unsigned __int128;

std::array<std::uint32_t, 64> first_primes() {
  std::array<std::uint32_t, 64> p{};
  std::uint32_t n = 2;
  for (auto& out : p) {
    for (;; ++n) {
      bool prime = true;
      for (std::uint32_t d = 2; d * d <= n; ++d)
        if (n % d == 0) {
          prime = false;
          break;
        }
      if (prime) break;
    }
    out = n++;
  }
  return p;
}

// Largest x with x^k ≤ p·2^(32k): x = floor(root_k(p)·2^32); its low 32 bits are the fraction.
std::uint32_t root_fraction_bits(std::uint32_t p, int k) {
  const u128 target = static_cast<u128>(p) << (32 * k);
  std::uint64_t lo = 0, hi = std::uint64_t{1} << 36;
  while (hi - lo > 1) {
    const std::uint64_t mid = lo + (hi - lo) / 2;
    u128 v = 1;
    for (int i = 0; i < k; ++i) v *= mid;
    (v <= target ? lo : hi) = mid;
  }
  return static_cast<std::uint32_t>(lo);
}

struct Sha256Constants {
  std::array<std::uint32_t, 64> k{};
  std::array<std::uint32_t, 8> h0{};
  Sha256Constants() {
    const auto p = first_primes();
    for (int i = 0; i < 64; ++i) k[i] = root_fraction_bits(p[i], 3);
    for (int i = 0; i < 8; ++i) h0[i] = root_fraction_bits(p[i], 2);
  }
};

const Sha256Constants& constants() {
  static const Sha256Constants c;  // immutable after construction
  return c;
}

constexpr std::uint32_t rotr(std::uint32_t x, int n) { return (x >> n) | (x << (32 - n)); }

void compress(std::array<std::uint32_t, 8>& h, const unsigned char* block) {
  const auto& K = constants().k;
  std::uint32_t w[64];
  for (int t = 0; t < 16; ++t)
    w[t] = (std::uint32_t{block[4 * t]} << 24) | (std::uint32_t{block[4 * t + 1]} << 16) |
           (std::uint32_t{block[4 * t + 2]} << 8) | std::uint32_t{block[4 * t + 3]};
  for (int t = 16; t < 64; ++t) {
    const std::uint32_t s0 = rotr(w[t - 15], 7) ^ rotr(w[t - 15], 18) ^ (w[t - 15] >> 3);
    const std::uint32_t s1 = rotr(w[t - 2], 17) ^ rotr(w[t - 2], 19) ^ (w[t - 2] >> 10);
    w[t] = w[t - 16] + s0 + w[t - 7] + s1;
  }
  std::uint32_t a = h[0], b = h[1], c = h[2], d = h[3], e = h[4], f = h[5], g = h[6], hh = h[7];
  for (int t = 0; t < 64; ++t) {
    const std::uint32_t t1 =
        hh + (rotr(e, 6) ^ rotr(e, 11) ^ rotr(e, 25)) + ((e & f) ^ (~e & g)) + K[t] + w[t];
    const std::uint32_t t2 =
        (rotr(a, 2) ^ rotr(a, 13) ^ rotr(a, 22)) + ((a & b) ^ (a & c) ^ (b & c));
    hh = g;
    g = f;
    f = e;
    e = d + t1;
    d = c;
    c = b;
    b = a;
    a = t1 + t2;
  }
  h[0] += a;
  h[1] += b;
  h[2] += c;
  h[3] += d;
  h[4] += e;
  h[5] += f;
  h[6] += g;
  h[7] += hh;
}

}  // namespace

std::string sha256_hex(const std::string& text) {
  std::array<std::uint32_t, 8> h = constants().h0;
  std::string msg = text;
  const std::uint64_t bit_length = static_cast<std::uint64_t>(text.size()) * 8;
  msg.push_back(static_cast<char>(0x80));
  while (msg.size() % 64 != 56) msg.push_back('\0');
  for (int i = 7; i >= 0; --i) msg.push_back(static_cast<char>((bit_length >> (8 * i)) & 0xff));
  for (std::size_t off = 0; off < msg.size(); off += 64)
    compress(h, reinterpret_cast<const unsigned char*>(msg.data() + off));
  static const char* digits = "0123456789abcdef";
  std::string out;
  for (std::uint32_t word : h)
    for (int shift = 28; shift >= 0; shift -= 4) out.push_back(digits[(word >> shift) & 0xf]);
  return out;
}

nlohmann::json case_identity(const SceneConfig& scene, const nlohmann::json& measurement_settings,
                             const std::string& engine_version) {
  return {{"engine_version", engine_version},
          {"scene", scene_results_json(scene)},
          {"measurement", measurement_settings}};
}

std::string case_hash(const SceneConfig& scene, const nlohmann::json& measurement_settings,
                      const std::string& engine_version) {
  return sha256_hex(case_identity(scene, measurement_settings, engine_version).dump());
}

}  // namespace crevasse
