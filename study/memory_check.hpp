#pragma once
// The check before a case starts: its expected memory against what the machine, the cgroup
// and the address-space limit (ulimit -v) still allow. A case that cannot fit is refused
// before any work, with one line, instead of being killed by the OOM killer (which prints
// nothing) or failing part-way.
#include <cstdint>
#include <filesystem>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "engine/scene.hpp"

namespace crevasse {

// Not enough memory for what was asked: the CLI prints it on one line and exits with 1.
class OutOfMemoryError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// What this process can still take, from each place that can refuse it; empty: no limit there.
struct MemoryHeadroom {
  std::optional<double> available_bytes;  // MemAvailable (/proc/meminfo)
  std::optional<double> cgroup_bytes;     // the tightest cgroup limit on the way up, less its usage
  std::optional<double> address_space_bytes;  // RLIMIT_AS less the address space already mapped
};

// Reads the headroom from a proc file system and a cgroup mount (v2 memory.max/current, or
// v1 memory.limit_in_bytes/usage_in_bytes); the roots are parameters so tests can give others.
MemoryHeadroom read_memory_headroom(const std::filesystem::path& proc = "/proc",
                                    const std::filesystem::path& cgroup_root = "/sys/fs/cgroup");

// Peak memory of one case of this scene (resolved), from the measured bytes per particle.
double case_memory_bytes(const SceneConfig& scene);

// Throws OutOfMemoryError when the cases `at_once` (run together) cannot fit in `headroom`; the
// message starts with `what` ("the scene", "case LABEL …") and says how much they need, which
// limit refuses it and what to do.
void check_memory_fits(const std::vector<const SceneConfig*>& at_once, const std::string& what,
                       const MemoryHeadroom& headroom);

}  // namespace crevasse
