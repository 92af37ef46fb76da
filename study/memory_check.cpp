#include "study/memory_check.hpp"

#include <algorithm>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <vector>

namespace crevasse {
namespace fs = std::filesystem;
namespace {

// Peak resident memory of a case per particle seeded, measured (docs/reliability.md, "Faults
// never cost a case"): whole 2D glacier cases (11,200 to 179,200 particles, the inflow adding a
// quarter more by the end) peak at 980 B per particle, and a 3D particle's state and grid cost
// 1.5 times a 2D one's. The process itself takes 12-16 MB.
constexpr double kBytesPerParticle2d = 1000.0;
constexpr double kBytesPerParticle3d = 1500.0;
constexpr double kBytesPerCase = 16e6;

// Values from files such as /proc/meminfo ("MemAvailable:   1234 kB"): the number after `key`.
std::optional<double> field_of(const fs::path& file, const std::string& key) {
  std::ifstream f(file);
  std::string line;
  while (std::getline(f, line)) {
    if (line.rfind(key, 0) != 0) continue;
    std::istringstream rest(line.substr(key.size()));
    double value = 0;
    std::string unit;
    if (!(rest >> value)) return std::nullopt;
    rest >> unit;
    return unit == "kB" ? value * 1024.0 : value;
  }
  return std::nullopt;
}

// A cgroup limit file: "max", a number, or (v1) a number so large it means none.
std::optional<double> limit_in(const fs::path& file) {
  std::ifstream f(file);
  std::string text;
  if (!(f >> text) || text == "max") return std::nullopt;
  try {
    const double v = std::stod(text);
    return v >= 0x1p60 ? std::nullopt : std::optional<double>(v);
  } catch (const std::exception&) {
    return std::nullopt;
  }
}

std::optional<double> number_in(const fs::path& file) {
  std::ifstream f(file);
  double v = 0;
  return f >> v ? std::optional<double>(v) : std::nullopt;
}

void keep_smaller(std::optional<double>& a, double b) {
  if (!a || b < *a) a = b;
}

// The tightest limit − usage from `mount` / `path` up to `mount` (a container sees its own
// cgroup at the mount itself: then only that level is read).
void cgroup_headroom(const fs::path& mount, const std::string& path, const char* limit_file,
                     const char* usage_file, std::optional<double>& out) {
  if (!fs::is_directory(mount)) return;
  std::vector<fs::path> levels = {mount};
  fs::path dir = mount;
  for (const auto& part : fs::path(path).relative_path()) {
    dir /= part;
    levels.push_back(dir);
  }
  if (!fs::is_directory(dir)) levels = {mount};
  for (const fs::path& level : levels) {
    const std::optional<double> limit = limit_in(level / limit_file);
    if (!limit) continue;
    keep_smaller(out, *limit - number_in(level / usage_file).value_or(0.0));
  }
}

std::string bytes_text(double b) {
  char buf[32];
  if (b >= 1e9)
    std::snprintf(buf, sizeof buf, "%.1f GB", b / 1e9);
  else
    std::snprintf(buf, sizeof buf, "%.0f MB", b / 1e6);
  return buf;
}

}  // namespace

MemoryHeadroom read_memory_headroom(const fs::path& proc, const fs::path& cgroup_root) {
  MemoryHeadroom h;
  h.available_bytes = field_of(proc / "meminfo", "MemAvailable:");
  // /proc/self/limits: "Max address space   SOFT   HARD   bytes", SOFT a number or "unlimited".
  std::ifstream limits(proc / "self" / "limits");
  std::string line;
  while (std::getline(limits, line)) {
    if (line.rfind("Max address space", 0) != 0) continue;
    std::istringstream rest(line.substr(17));
    std::string soft;
    rest >> soft;
    if (soft != "unlimited") {
      const double mapped = field_of(proc / "self" / "status", "VmSize:").value_or(0.0);
      h.address_space_bytes = std::stod(soft) - mapped;
    }
  }
  // /proc/self/cgroup: "0::PATH" (v2), "N:CONTROLLERS:PATH" (v1, memory among the controllers).
  std::ifstream groups(proc / "self" / "cgroup");
  while (std::getline(groups, line)) {
    const auto c1 = line.find(':');
    const auto c2 = line.find(':', c1 + 1);
    if (c1 == std::string::npos || c2 == std::string::npos) continue;
    const std::string controllers = "," + line.substr(c1 + 1, c2 - c1 - 1) + ",";
    const std::string path = line.substr(c2 + 1);
    if (line.compare(0, c1, "0") == 0 && controllers == ",,")
      cgroup_headroom(cgroup_root, path, "memory.max", "memory.current", h.cgroup_bytes);
    else if (controllers.find(",memory,") != std::string::npos)
      cgroup_headroom(cgroup_root / "memory", path, "memory.limit_in_bytes",
                      "memory.usage_in_bytes", h.cgroup_bytes);
  }
  return h;
}

double case_memory_bytes(const SceneConfig& scene) {
  return kBytesPerCase +
         (scene.dim == 3 ? kBytesPerParticle3d : kBytesPerParticle2d) * scene.expected_particles();
}

void check_memory_fits(const std::vector<const SceneConfig*>& at_once, const std::string& what,
                       const MemoryHeadroom& headroom) {
  double need = 0.0, particles = 0.0;
  for (const SceneConfig* s : at_once) {
    need += case_memory_bytes(*s);
    particles += s->expected_particles();
  }
  const std::pair<const std::optional<double>*, const char*> limits[] = {
      {&headroom.available_bytes, "the machine has"},
      {&headroom.cgroup_bytes, "the cgroup's memory limit leaves"},
      {&headroom.address_space_bytes, "the address-space limit (ulimit -v) leaves"},
  };
  for (const auto& [room, says] : limits) {
    if (!*room || need <= **room) continue;
    char detail[96];
    std::snprintf(detail, sizeof detail, "%.3g particles", particles);
    throw OutOfMemoryError(what + " needs about " + bytes_text(need) + " (" + detail + ") but " +
                           says + " " + bytes_text(std::max(0.0, **room)) +
                           ": use a coarser numerics.dx or a smaller scene" +
                           (at_once.size() > 1 ? ", run fewer cases at once (--jobs)" : "") +
                           ", or free memory or raise the limit, then run the same command again");
  }
}

}  // namespace crevasse
