#pragma once
// Binary checkpoints of a running simulation (docs/reliability.md, "Checkpoints"): everything
// that the next step reads, so that a run restored from a checkpoint continues bit for bit as
// the uninterrupted run would (same thread count not required: the step is deterministic).
// The file starts with a magic string, the engine version and the canonical scene JSON, and ends
// with a checksum over everything between the magic strings; a checkpoint of another scene or
// engine version, or one whose checksum does not match, is refused.
#include <cstdint>
#include <optional>
#include <istream>
#include <ostream>
#include <string>
#include <vector>

#include "engine/gate_recorder.hpp"
#include "engine/particles.hpp"
#include "engine/scene.hpp"

namespace crevasse {

// The run's scalar state that a checkpoint carries besides the particles and the gate.
struct RunCounters {
  double time = 0.0, dt = 0.0;
  std::int64_t steps = 0, particle_steps = 0, return_map_evaluations = 0;
  double removed_mass = 0.0, front_x = 0.0, max_speed = 0.0;
  bool settled = false;
  double inflow_mass = 0.0;
  std::int64_t inflow_columns = 0;
  // Wall seconds the run had taken when the checkpoint was written, over all its sittings, so
  // that a resumed run reports its whole cost. Unknown (nullopt) for a format 2 file, and for
  // every later checkpoint of a run resumed from one; written as NaN.
  std::optional<double> wall_s = 0.0;
};

// Written atomically (temporary file, then rename); SimulationError when it cannot be, and then
// no temporary file is left behind.
template <int Dim>
void save_checkpoint(const std::string& path, const SceneConfig& scene, const RunCounters& run,
                     const Particles<Dim>& particles, const GateRecorder<Dim>& gate);
// Throws SimulationError when the file is not a regular file (checked before it is opened, so a
// FIFO never blocks), is not a checkpoint of this scene, dimension and engine version, is
// truncated, fails its checksum, or its arrays disagree with what `particles` holds (plastic state,
// piston layer, gate records); run, particles and gate change only when the whole file is good.
template <int Dim>
void load_checkpoint(const std::string& path, const SceneConfig& scene, RunCounters& run,
                     Particles<Dim>& particles, GateRecorder<Dim>& gate);

}  // namespace crevasse

namespace crevasse::checkpoint {

// Format 2 added the checksum, format 3 the wall time (RunCounters::wall_s). Format 2 is still
// read, so that a study paused before format 3 continues where it stopped.
inline constexpr char kMagic[8] = {'C', 'R', 'V', 'C', 'K', 'P', 'T', '3'};
inline constexpr char kFormat2 = '2';

// 64-bit FNV-1a over 8-byte words (then the tail bytes): cheap next to writing the file, and
// any flipped bit changes it.
std::uint64_t checksum(const char* data, std::size_t n);

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
// max_bytes bounds the allocation by what the file can hold.
template <class T>
bool get_vector(std::istream& i, std::vector<T>& v, std::uint64_t max_bytes) {
  std::uint64_t n = 0;
  get(i, n);
  if (!i || n > max_bytes / sizeof(T)) return false;
  v.resize(n);
  if (n) read_bytes(i, v.data(), n * sizeof(T));
  return static_cast<bool>(i);
}

}  // namespace crevasse::checkpoint
