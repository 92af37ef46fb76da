#include "engine/checkpoint.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "engine/error.hpp"

namespace crevasse {

namespace checkpoint {

std::uint64_t checksum(const char* data, std::size_t n) {
  constexpr std::uint64_t kPrime = 0x100000001b3ull;
  std::uint64_t h = 0xcbf29ce484222325ull;
  std::size_t k = 0;
  for (; k + 8 <= n; k += 8) {
    std::uint64_t w;
    std::memcpy(&w, data + k, 8);
    h = (h ^ w) * kPrime;
  }
  for (; k < n; ++k) h = (h ^ static_cast<unsigned char>(data[k])) * kPrime;
  return h;
}

// The scene a checkpoint belongs to. The wall-time limit is left out: a run stopped by it
// continues under a larger one.
static std::string scene_identity(SceneConfig scene) {
  scene.wall_time_limit = 0.0;
  return scene_to_json(scene).dump();
}

}  // namespace checkpoint

template <int Dim>
void save_checkpoint(const std::string& path, const SceneConfig& scene, const RunCounters& run,
                     const Particles<Dim>& P, const GateRecorder<Dim>& gate) {
  namespace ck = checkpoint;
  // The payload is assembled in memory first, so that its checksum can follow it.
  std::ostringstream o(std::ios::binary);
  ck::put_string(o, CREVASSE_ENGINE_VERSION);
  ck::put_string(o, ck::scene_identity(scene));
  ck::put(o, static_cast<std::int32_t>(Dim));
  ck::put(o, run.time); ck::put(o, run.dt); ck::put(o, run.steps); ck::put(o, run.particle_steps);
  ck::put(o, run.return_map_evaluations); ck::put(o, run.removed_mass); ck::put(o, run.front_x);
  ck::put(o, run.max_speed); ck::put(o, static_cast<std::uint8_t>(run.settled));
  ck::put(o, gate.passed_volume()); ck::put(o, run.inflow_mass); ck::put(o, run.inflow_columns);
  ck::put(o, run.wall_s.value_or(std::numeric_limits<double>::quiet_NaN()));
  ck::put_vector(o, P.x); ck::put_vector(o, P.v); ck::put_vector(o, P.C); ck::put_vector(o, P.F_e);
  ck::put_vector(o, P.tau); ck::put_vector(o, P.mass); ck::put_vector(o, P.vol0);
  ck::put_vector(o, P.eps_v_p); ck::put_vector(o, P.drive_x0); ck::put_vector(o, P.x_ref);
  ck::put_vector(o, P.gate_eps); ck::put_vector(o, gate.archive().x); ck::put_vector(o, gate.archive().eps);
  const std::string payload = std::move(o).str();
  const std::uint64_t sum = ck::checksum(payload.data(), payload.size());

  const std::string tmp = path + ".tmp";
  std::error_code ec;
  auto fail = [&](const std::string& why) {
    // A failed write leaves nothing behind (but what is not a file of ours stays).
    if (std::filesystem::is_regular_file(std::filesystem::symlink_status(tmp, ec))) std::filesystem::remove(tmp, ec);
    return SimulationError("checkpoint: " + why);
  };
  {
    std::ofstream f(tmp, std::ios::binary | std::ios::trunc);
    if (!f) throw fail("cannot write " + tmp);
    ck::write_bytes(f, ck::kMagic, sizeof ck::kMagic);
    ck::write_bytes(f, payload.data(), payload.size());
    ck::put(f, sum);
    ck::write_bytes(f, ck::kMagic, sizeof ck::kMagic);  // end marker: a truncated file is refused
    f.flush();
    if (!f) throw fail("writing " + tmp + " failed (disk full?)");
    f.close();
    if (!f) throw fail("writing " + tmp + " failed (disk full?)");
  }
  std::filesystem::rename(tmp, path, ec);
  if (ec) {
    const std::string why = ec.message();
    throw fail("cannot rename " + tmp + " to " + path + ": " + why);
  }
}

template <int Dim>
void load_checkpoint(const std::string& path, const SceneConfig& scene, RunCounters& run,
                     Particles<Dim>& particles, GateRecorder<Dim>& gate) {
  namespace ck = checkpoint;
  auto bad = [&](const std::string& why) { return SimulationError("checkpoint " + path + ": " + why); };
  // stat before open: opening a FIFO for reading blocks until a writer appears.
  std::error_code ec;
  const auto st = std::filesystem::status(path, ec);
  if (ec) throw bad("cannot read it (" + ec.message() + ")");
  if (!std::filesystem::is_regular_file(st)) throw bad("not a regular file");
  const auto size = std::filesystem::file_size(path, ec);
  constexpr std::uintmax_t kTail = sizeof(std::uint64_t) + sizeof ck::kMagic;
  if (ec || size < sizeof ck::kMagic + kTail) throw bad("truncated or empty");
  std::string bytes(size, '\0');
  {
    std::ifstream f(path, std::ios::binary);
    if (!f) throw bad("cannot read it");
    ck::read_bytes(f, bytes.data(), bytes.size());
    if (!f) throw bad("truncated (it changed while being read)");
  }
  const char* end_magic = bytes.data() + bytes.size() - sizeof ck::kMagic;
  if (bytes.compare(0, 7, ck::kMagic, 7) != 0) throw bad("not a crevasse checkpoint");
  const char format = bytes[7];
  if (format != ck::kMagic[7] && format != ck::kFormat2) throw bad("written in another checkpoint format");
  if (!std::equal(bytes.data(), bytes.data() + sizeof ck::kMagic, end_magic)) throw bad("truncated");
  std::uint64_t stored_sum = 0;
  std::memcpy(&stored_sum, end_magic - sizeof stored_sum, sizeof stored_sum);
  const std::size_t payload_size = bytes.size() - sizeof ck::kMagic - kTail;
  if (ck::checksum(bytes.data() + sizeof ck::kMagic, payload_size) != stored_sum)
    throw bad("checksum mismatch (the file is corrupt)");
  std::istringstream i(bytes.substr(sizeof ck::kMagic, payload_size), std::ios::binary);
  bytes.clear();
  if (ck::get_string(i, 64) != CREVASSE_ENGINE_VERSION) throw bad("written by another engine version");
  if (ck::get_string(i, 1u << 24) != ck::scene_identity(scene)) throw bad("written for another scene");
  std::int32_t dim = 0;
  ck::get(i, dim);
  if (dim != Dim) throw bad("written for another dimension");
  RunCounters r;
  double gate_volume = 0;
  std::uint8_t settled = 0;
  ck::get(i, r.time); ck::get(i, r.dt); ck::get(i, r.steps); ck::get(i, r.particle_steps);
  ck::get(i, r.return_map_evaluations); ck::get(i, r.removed_mass); ck::get(i, r.front_x);
  ck::get(i, r.max_speed); ck::get(i, settled); ck::get(i, gate_volume);
  ck::get(i, r.inflow_mass); ck::get(i, r.inflow_columns);
  r.wall_s.reset();
  if (format != ck::kFormat2) {
    double wall = 0.0;
    ck::get(i, wall);
    if (!std::isnan(wall)) r.wall_s = wall;
  }
  r.settled = settled != 0;
  Particles<Dim> P;
  const std::uint64_t kMax = payload_size;
  const bool ok = ck::get_vector(i, P.x, kMax) && ck::get_vector(i, P.v, kMax) &&
                  ck::get_vector(i, P.C, kMax) && ck::get_vector(i, P.F_e, kMax) &&
                  ck::get_vector(i, P.tau, kMax) && ck::get_vector(i, P.mass, kMax) &&
                  ck::get_vector(i, P.vol0, kMax) && ck::get_vector(i, P.eps_v_p, kMax) &&
                  ck::get_vector(i, P.drive_x0, kMax) && ck::get_vector(i, P.x_ref, kMax) &&
                  ck::get_vector(i, P.gate_eps, kMax);
  typename GateRecorder<Dim>::Archive archive;
  const bool ok2 = ok && ck::get_vector(i, archive.x, kMax) && ck::get_vector(i, archive.eps, kMax);
  if (!ok2 || !i || i.peek() != std::char_traits<char>::eof()) throw bad("truncated or corrupt");
  const std::size_t n = P.x.size();
  const bool gated = !particles.gate_eps.empty();
  auto size_ok = [&](std::size_t got, bool present) { return got == (present ? n : 0); };
  if (P.v.size() != n || P.C.size() != n || P.F_e.size() != n || P.tau.size() != n ||
      P.mass.size() != n || P.vol0.size() != n || !size_ok(P.eps_v_p.size(), particles.has_plastic_state()) ||
      !size_ok(P.drive_x0.size(), !particles.drive_x0.empty()) ||
      !size_ok(P.x_ref.size(), gated) || !size_ok(P.gate_eps.size(), gated) ||
      archive.x.size() != archive.eps.size())
    throw bad("array sizes disagree");
  particles = std::move(P);
  gate.restore(gate_volume, std::move(archive));
  run = r;
}

template void save_checkpoint<2>(const std::string&, const SceneConfig&, const RunCounters&,
                                 const Particles<2>&, const GateRecorder<2>&);
template void save_checkpoint<3>(const std::string&, const SceneConfig&, const RunCounters&,
                                 const Particles<3>&, const GateRecorder<3>&);
template void load_checkpoint<2>(const std::string&, const SceneConfig&, RunCounters&, Particles<2>&,
                                 GateRecorder<2>&);
template void load_checkpoint<3>(const std::string&, const SceneConfig&, RunCounters&, Particles<3>&,
                                 GateRecorder<3>&);

}  // namespace crevasse
