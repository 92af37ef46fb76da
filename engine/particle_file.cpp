#include "engine/particle_file.hpp"

#include <zlib.h>

#include <bit>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <iterator>
#include <stdexcept>

#include "engine/atomic_file.hpp"
#include "engine/error.hpp"

namespace crevasse {
namespace {

static_assert(std::endian::native == std::endian::little, "particle files are little-endian");

constexpr char kMagic[8] = {'C', 'R', 'V', 'P', 'T', 'C', 'L', '\n'};
constexpr char kEnd[8] = {'C', 'R', 'V', 'P', 'E', 'N', 'D', '\n'};
constexpr std::uint32_t kFormat = 1;

// Every per-particle and gate array, with the precision it is kept in: what the measurement
// reads in double, what is only drawn in single.
struct ArraySlot {
  const char* name;
  std::vector<double> ParticleSnapshot::*member;
  bool single;
};
constexpr ArraySlot kArrays[] = {
    {"x", &ParticleSnapshot::x, false},
    {"y", &ParticleSnapshot::y, false},
    {"z", &ParticleSnapshot::z, false},
    {"eps_v_p", &ParticleSnapshot::eps_v_p, false},
    {"vx", &ParticleSnapshot::vx, true},
    {"vy", &ParticleSnapshot::vy, true},
    {"vz", &ParticleSnapshot::vz, true},
    {"pressure_pa", &ParticleSnapshot::pressure_pa, true},
    {"von_mises_pa", &ParticleSnapshot::von_mises_pa, true},
    {"sigma_zz_pa", &ParticleSnapshot::sigma_zz_pa, true},
    {"volume_m3", &ParticleSnapshot::volume_m3, true},
    {"gate_x_ref", &ParticleSnapshot::gate_x_ref, false},
    {"gate_y_ref", &ParticleSnapshot::gate_y_ref, false},
    {"gate_z_ref", &ParticleSnapshot::gate_z_ref, false},
    {"gate_eps_v_p", &ParticleSnapshot::gate_eps_v_p, false},
};

template <class T>
void put(std::string& out, const T& v) {
  out.append(reinterpret_cast<const char*>(&v), sizeof v);
}

nlohmann::json scalars(const ParticleSnapshot& s) {
  return {{"dim", s.dim},
          {"time_s", s.time_s},
          {"dx_m", s.dx_m},
          {"softening_zeta", s.softening_zeta},
          {"tensile_strength_pa", s.tensile_strength_pa},
          {"ice_thickness_m", s.ice_thickness_m},
          {"step_top_x_m", s.step_top_x_m},
          {"step_foot_x_m", s.step_foot_x_m},
          {"particle_spacing_m", s.particle_spacing_m},
          {"bed_profile", s.bed_profile},
          {"gate_x_m", s.gate_x_m},
          {"gate_passed_length_m", s.gate_passed_length_m},
          {"ice_front_x_m", s.ice_front_x_m},
          {"upstream_ice_front_x_m", s.upstream_ice_front_x_m}};
}

// JSON text keeps a double exactly only through its shortest round-trip form, which
// nlohmann::json writes; the scalars are read back bit for bit.
void read_scalars(const nlohmann::json& j, ParticleSnapshot& s) {
  s.dim = j.at("dim").get<int>();
  s.time_s = j.at("time_s").get<double>();
  s.dx_m = j.at("dx_m").get<double>();
  s.softening_zeta = j.at("softening_zeta").get<double>();
  s.tensile_strength_pa = j.at("tensile_strength_pa").get<double>();
  s.ice_thickness_m = j.at("ice_thickness_m").get<double>();
  s.step_top_x_m = j.at("step_top_x_m").get<double>();
  s.step_foot_x_m = j.at("step_foot_x_m").get<double>();
  s.particle_spacing_m = j.at("particle_spacing_m").get<double>();
  s.bed_profile = j.at("bed_profile").get<std::vector<std::array<double, 2>>>();
  s.gate_x_m = j.at("gate_x_m").get<double>();
  s.gate_passed_length_m = j.at("gate_passed_length_m").get<double>();
  s.ice_front_x_m = j.at("ice_front_x_m").get<double>();
  s.upstream_ice_front_x_m = j.at("upstream_ice_front_x_m").get<double>();
}

}  // namespace

void write_particle_file(const std::filesystem::path& path, const ParticleSnapshot& s,
                         const nlohmann::json& metadata) {
  nlohmann::json header = scalars(s);
  header["metadata"] = metadata;
  header["arrays"] = nlohmann::json::array();
  std::string raw;
  for (const ArraySlot& a : kArrays) {
    const std::vector<double>& v = s.*(a.member);
    header["arrays"].push_back({{"name", a.name}, {"count", v.size()}, {"type", a.single ? "f32" : "f64"}});
    for (double d : v) {
      if (a.single)
        put(raw, static_cast<float>(d));
      else
        put(raw, d);
    }
  }
  uLongf packed_size = compressBound(raw.size());
  std::string packed(packed_size, '\0');
  if (compress2(reinterpret_cast<Bytef*>(packed.data()), &packed_size,
                reinterpret_cast<const Bytef*>(raw.data()), raw.size(), 6) != Z_OK)
    throw std::runtime_error("cannot compress the particles for " + path.string());
  packed.resize(packed_size);
  const std::uint32_t crc = crc32(0L, reinterpret_cast<const Bytef*>(raw.data()), raw.size());

  const std::string header_text = header.dump();
  std::string out(kMagic, sizeof kMagic);
  put(out, kFormat);
  put(out, static_cast<std::uint64_t>(header_text.size()));
  out += header_text;
  put(out, static_cast<std::uint64_t>(raw.size()));
  put(out, static_cast<std::uint64_t>(packed.size()));
  put(out, crc);
  out += packed;
  out.append(kEnd, sizeof kEnd);
  write_file_atomically(path, out);
}

namespace {

// Opens a particle file and reads its prelude (magic, format, header size, header JSON text),
// leaving the stream at the sizes that follow. Both readers share it, and so its refusals.
std::string open_and_read_header(const std::filesystem::path& path, const std::string& where, std::ifstream& f) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec))
    throw InputError(where + ": no such particle file (a regular file)");
  const auto file_size = std::filesystem::file_size(path, ec);
  f.open(path, std::ios::binary);
  if (ec || !f) throw InputError(where + ": cannot read the particle file");
  char magic[sizeof kMagic];
  if (!f.read(magic, sizeof magic) || std::memcmp(magic, kMagic, sizeof kMagic) != 0)
    throw InputError(where + ": not a crevasse particle file");
  std::uint32_t format = 0;
  std::uint64_t header_size = 0;
  if (!f.read(reinterpret_cast<char*>(&format), sizeof format))
    throw InputError(where + ": truncated particle file");
  if (format != kFormat)
    throw InputError(where + ": particle file format " + std::to_string(format) +
                     " (this crevasse reads format " + std::to_string(kFormat) + ")");
  if (!f.read(reinterpret_cast<char*>(&header_size), sizeof header_size) || header_size > file_size)
    throw InputError(where + ": truncated particle file");
  std::string header_text(header_size, '\0');
  if (!f.read(header_text.data(), static_cast<std::streamsize>(header_size)))
    throw InputError(where + ": truncated particle file");
  return header_text;
}

}  // namespace

ParticleFile read_particle_file(const std::filesystem::path& path) {
  const std::string where = path.string();
  std::ifstream f;
  const std::string header_text = open_and_read_header(path, where, f);
  const std::string bytes((std::istreambuf_iterator<char>(f)), std::istreambuf_iterator<char>());
  if (!f.eof() && f.fail()) throw InputError(where + ": cannot read the particle file");
  std::size_t at = 0;
  auto need = [&](std::size_t n) {
    if (n > bytes.size() - at)
      throw InputError(where + ": truncated particle file");
  };
  auto get = [&]<class T>(T& v) {
    need(sizeof v);
    std::memcpy(&v, bytes.data() + at, sizeof v);
    at += sizeof v;
  };
  std::uint64_t raw_size = 0, packed_size = 0;
  std::uint32_t crc = 0;
  get(raw_size);
  get(packed_size);
  get(crc);
  need(packed_size);
  const std::size_t packed_at = at;
  at += packed_size;
  need(sizeof kEnd);
  if (std::memcmp(bytes.data() + at, kEnd, sizeof kEnd) != 0 || at + sizeof kEnd != bytes.size())
    throw InputError(where + ": damaged particle file (no end marker where its sizes put it)");

  ParticleFile out;
  std::string raw(raw_size, '\0');
  uLongf unpacked = raw_size;
  if (uncompress(reinterpret_cast<Bytef*>(raw.data()), &unpacked,
                 reinterpret_cast<const Bytef*>(bytes.data() + packed_at), packed_size) != Z_OK ||
      unpacked != raw_size ||
      crc32(0L, reinterpret_cast<const Bytef*>(raw.data()), raw.size()) != crc)
    throw InputError(where + ": damaged particle file (its arrays fail their checksum)");
  try {
    const nlohmann::json header = nlohmann::json::parse(header_text);
    read_scalars(header, out.snapshot);
    out.metadata = header.at("metadata");
    std::size_t pos = 0;
    for (const ArraySlot& a : kArrays) {
      const nlohmann::json* entry = nullptr;
      for (const auto& e : header.at("arrays"))
        if (e.at("name").get<std::string>() == a.name) entry = &e;
      if (!entry) throw std::runtime_error(std::string("array ") + a.name + " missing");
      const std::size_t count = entry->at("count").get<std::size_t>();
      const bool single = entry->at("type").get<std::string>() == "f32";
      const std::size_t width = single ? sizeof(float) : sizeof(double);
      if (count > (raw.size() - pos) / width) throw std::runtime_error(std::string("array ") + a.name + " overruns");
      std::vector<double>& v = out.snapshot.*(a.member);
      v.resize(count);
      for (std::size_t i = 0; i < count; ++i, pos += width) {
        if (single) {
          float x;
          std::memcpy(&x, raw.data() + pos, sizeof x);
          v[i] = x;
        } else {
          std::memcpy(&v[i], raw.data() + pos, sizeof(double));
        }
      }
    }
    if (pos != raw.size()) throw std::runtime_error("arrays do not fill the payload");
  } catch (const std::exception& e) {
    throw InputError(where + ": damaged particle file (" + e.what() + ")");
  }
  const ParticleSnapshot& s = out.snapshot;
  const std::size_t n = s.x.size();
  for (const auto* v : {&s.z, &s.eps_v_p})
    if (v->size() != n) throw InputError(where + ": damaged particle file (arrays of unequal length)");
  return out;
}

nlohmann::json read_particle_file_metadata(const std::filesystem::path& path) {
  const std::string where = path.string();
  std::ifstream f;
  const std::string header_text = open_and_read_header(path, where, f);
  try {
    return nlohmann::json::parse(header_text).at("metadata");
  } catch (const std::exception& e) {
    throw InputError(where + ": damaged particle file (" + e.what() + ")");
  }
}

}  // namespace crevasse
