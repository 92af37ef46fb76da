#pragma once
// Binary checkpoints of a running simulation (docs/reliability.md, "Checkpoints"): everything
// that the next step reads, so that a run restored from a checkpoint continues bit for bit as
// the uninterrupted run would (same thread count not required: the step is deterministic).
// The file starts with a magic string, the engine version and the canonical scene JSON; a
// checkpoint of another scene or engine version is refused.
#include <cstdint>
#include <istream>
#include <ostream>
#include <string>
#include <vector>

namespace crevasse::checkpoint {

inline constexpr char kMagic[8] = {'C', 'R', 'V', 'C', 'K', 'P', 'T', '1'};

inline void write_bytes(std::ostream& o, const void* p, std::size_t n) {
  o.write(static_cast<const char*>(p), static_cast<std::streamsize>(n));
}
inline void read_bytes(std::istream& i, void* p, std::size_t n) {
  i.read(static_cast<char*>(p), static_cast<std::streamsize>(n));
}
template <class T>
void put(std::ostream& o, const T& v) { write_bytes(o, &v, sizeof v); }
template <class T>
void get(std::istream& i, T& v) { read_bytes(i, &v, sizeof v); }

inline void put_string(std::ostream& o, const std::string& s) {
  put(o, static_cast<std::uint64_t>(s.size()));
  write_bytes(o, s.data(), s.size());
}
inline std::string get_string(std::istream& i, std::uint64_t max_size) {
  std::uint64_t n = 0;
  get(i, n);
  if (!i || n > max_size) return {};
  std::string s(n, '\0');
  read_bytes(i, s.data(), n);
  return s;
}

// Trivially copyable element types only (Eigen fixed-size matrices, arrays of float/double).
template <class T>
void put_vector(std::ostream& o, const std::vector<T>& v) {
  put(o, static_cast<std::uint64_t>(v.size()));
  if (!v.empty()) write_bytes(o, v.data(), v.size() * sizeof(T));
}
template <class T>
bool get_vector(std::istream& i, std::vector<T>& v, std::uint64_t max_size) {
  std::uint64_t n = 0;
  get(i, n);
  if (!i || n > max_size) return false;
  v.resize(n);
  if (n) read_bytes(i, v.data(), n * sizeof(T));
  return static_cast<bool>(i);
}

}  // namespace crevasse::checkpoint
