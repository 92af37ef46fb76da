#include "engine/checkpoint.hpp"

#include <algorithm>
#include <filesystem>
#include <fstream>

#include "engine/error.hpp"

namespace crevasse {

template <int Dim>
void save_checkpoint(const std::string& path, const SceneConfig& scene, const RunCounters& run,
                     const Particles<Dim>& P, const GateRecorder<Dim>& gate) {
  namespace ck = checkpoint;
  const std::string tmp = path + ".tmp";
  {
    std::ofstream o(tmp, std::ios::binary | std::ios::trunc);
    if (!o) throw SimulationError("checkpoint: cannot write " + tmp);
    ck::write_bytes(o, ck::kMagic, sizeof ck::kMagic);
    ck::put_string(o, CREVASSE_ENGINE_VERSION);
    ck::put_string(o, scene_to_json(scene).dump());
    ck::put(o, static_cast<std::int32_t>(Dim));
    ck::put(o, run.time); ck::put(o, run.dt); ck::put(o, run.steps); ck::put(o, run.particle_steps);
    ck::put(o, run.return_map_evaluations); ck::put(o, run.removed_mass); ck::put(o, run.front_x);
    ck::put(o, run.max_speed); ck::put(o, static_cast<std::uint8_t>(run.settled));
    ck::put(o, gate.passed_volume()); ck::put(o, run.inflow_mass); ck::put(o, run.inflow_columns);
    ck::put_vector(o, P.x); ck::put_vector(o, P.v); ck::put_vector(o, P.C); ck::put_vector(o, P.F_e);
    ck::put_vector(o, P.tau); ck::put_vector(o, P.mass); ck::put_vector(o, P.vol0);
    ck::put_vector(o, P.eps_v_p); ck::put_vector(o, P.drive_x0); ck::put_vector(o, P.x_ref);
    ck::put_vector(o, P.gate_eps); ck::put_vector(o, gate.archive().x); ck::put_vector(o, gate.archive().eps);
    ck::write_bytes(o, ck::kMagic, sizeof ck::kMagic);  // end marker: a truncated file is refused
    o.flush();
    if (!o) throw SimulationError("checkpoint: writing " + tmp + " failed (disk full?)");
  }
  std::error_code ec;
  std::filesystem::rename(tmp, path, ec);
  if (ec) throw SimulationError("checkpoint: cannot rename " + tmp + " to " + path + ": " + ec.message());
}

template <int Dim>
void load_checkpoint(const std::string& path, const SceneConfig& scene, RunCounters& run,
                     Particles<Dim>& particles, GateRecorder<Dim>& gate) {
  namespace ck = checkpoint;
  std::ifstream i(path, std::ios::binary);
  if (!i) throw SimulationError("checkpoint: cannot read " + path);
  auto bad = [&](const std::string& why) { return SimulationError("checkpoint " + path + ": " + why); };
  char magic[sizeof ck::kMagic] = {};
  ck::read_bytes(i, magic, sizeof magic);
  if (!i || !std::equal(magic, magic + sizeof magic, ck::kMagic)) throw bad("not a crevasse checkpoint");
  if (ck::get_string(i, 64) != CREVASSE_ENGINE_VERSION) throw bad("written by another engine version");
  if (ck::get_string(i, 1u << 24) != scene_to_json(scene).dump()) throw bad("written for another scene");
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
  r.settled = settled != 0;
  Particles<Dim> P;
  constexpr std::uint64_t kMax = std::uint64_t{1} << 34;
  const bool ok = ck::get_vector(i, P.x, kMax) && ck::get_vector(i, P.v, kMax) &&
                  ck::get_vector(i, P.C, kMax) && ck::get_vector(i, P.F_e, kMax) &&
                  ck::get_vector(i, P.tau, kMax) && ck::get_vector(i, P.mass, kMax) &&
                  ck::get_vector(i, P.vol0, kMax) && ck::get_vector(i, P.eps_v_p, kMax) &&
                  ck::get_vector(i, P.drive_x0, kMax) && ck::get_vector(i, P.x_ref, kMax) &&
                  ck::get_vector(i, P.gate_eps, kMax);
  typename GateRecorder<Dim>::Archive archive;
  const bool ok2 = ok && ck::get_vector(i, archive.x, kMax) && ck::get_vector(i, archive.eps, kMax);
  ck::read_bytes(i, magic, sizeof magic);
  if (!ok2 || !i || !std::equal(magic, magic + sizeof magic, ck::kMagic)) throw bad("truncated or corrupt");
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
