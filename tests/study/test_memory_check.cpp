// The check before a case starts (study/memory_check.hpp): the headroom read from each place
// that can refuse memory, and the refusal naming the one that does.
#include <gtest/gtest.h>
#include <sys/resource.h>

#include <memory>
#include <new>
#include <vector>

#include "study/memory_check.hpp"
#include "study/memory_reserve.hpp"
#include "study_test_support.hpp"

namespace crevasse {
namespace {

namespace fs = std::filesystem;

void write(const fs::path& p, const std::string& text) {
  fs::create_directories(p.parent_path());
  test::write_text(p, text);
}

// A proc tree with 6 GB available and the given address-space limit and cgroup line.
void fake_proc(const fs::path& proc, const std::string& as_limit, const std::string& cgroup_line) {
  write(proc / "meminfo", "MemTotal:       8000000 kB\nMemAvailable:   6000000 kB\n");
  write(proc / "self" / "status", "Name:\tcrevasse\nVmSize:\t  100000 kB\nVmRSS:\t 5000 kB\n");
  write(proc / "self" / "limits",
        "Limit                     Soft Limit           Hard Limit           Units\n"
        "Max stack size            8388608              unlimited            bytes\n"
        "Max address space         " +
            as_limit + "            unlimited            bytes\n");
  write(proc / "self" / "cgroup", cgroup_line + "\n");
}

TEST(MemoryCheck, ReadsMemAvailableAndTheAddressSpaceLeft) {
  test::ScratchDir dir("mem_proc");
  fake_proc(dir / "proc", "unlimited", "0::/");
  MemoryHeadroom h = read_memory_headroom(dir / "proc", dir / "cgroup");
  EXPECT_DOUBLE_EQ(*h.available_bytes, 6000000.0 * 1024);
  EXPECT_FALSE(h.address_space_bytes);
  EXPECT_FALSE(h.cgroup_bytes);
  fake_proc(dir / "proc", "1073741824", "0::/");
  h = read_memory_headroom(dir / "proc", dir / "cgroup");
  ASSERT_TRUE(h.address_space_bytes);
  EXPECT_DOUBLE_EQ(*h.address_space_bytes, 1073741824.0 - 100000.0 * 1024);  // less VmSize
}

// cgroup v2: the tightest of the process's group and its parents, each less its usage; "max"
// is no limit.
TEST(MemoryCheck, TakesTheTightestCgroupV2LimitOnTheWayUp) {
  test::ScratchDir dir("mem_cg2");
  fake_proc(dir / "proc", "unlimited", "0::/jobs/case");
  write(dir / "cg" / "memory.max", "max\n");
  write(dir / "cg" / "jobs" / "memory.max", "3000000000\n");
  write(dir / "cg" / "jobs" / "memory.current", "1000000000\n");
  write(dir / "cg" / "jobs" / "case" / "memory.max", "max\n");
  write(dir / "cg" / "jobs" / "case" / "memory.current", "500000000\n");
  const MemoryHeadroom h = read_memory_headroom(dir / "proc", dir / "cg");
  ASSERT_TRUE(h.cgroup_bytes);
  EXPECT_DOUBLE_EQ(*h.cgroup_bytes, 2e9);
}

// cgroup v1 (the memory controller's own hierarchy); a container sees its own group at the
// mount, whatever path /proc/self/cgroup names; a limit near 2^63 is none.
TEST(MemoryCheck, ReadsCgroupV1AndAContainersOwnGroup) {
  test::ScratchDir dir("mem_cg1");
  fake_proc(dir / "proc", "unlimited", "4:memory:/host/side/path\n0::/");
  write(dir / "cg" / "memory" / "memory.limit_in_bytes", "2000000000\n");
  write(dir / "cg" / "memory" / "memory.usage_in_bytes", "1500000000\n");
  MemoryHeadroom h = read_memory_headroom(dir / "proc", dir / "cg");
  ASSERT_TRUE(h.cgroup_bytes);
  EXPECT_DOUBLE_EQ(*h.cgroup_bytes, 5e8);
  write(dir / "cg" / "memory" / "memory.limit_in_bytes", "9223372036854771712\n");
  h = read_memory_headroom(dir / "proc", dir / "cg");
  EXPECT_FALSE(h.cgroup_bytes);
}

TEST(MemoryCheck, RefusesNamingTheLimitAndFitsUnderIt) {
  const SceneConfig scene = scene_from_json(test::tiny_scene());
  const double one = case_memory_bytes(scene);
  EXPECT_GT(one, 1000.0 * scene.expected_particles());
  MemoryHeadroom h;
  h.available_bytes = 1.5 * one;
  EXPECT_NO_THROW(check_memory_fits({&scene}, "the scene", h));
  try {
    check_memory_fits({&scene, &scene}, "case x", h);
    FAIL() << "two cases at once fit in 1.5 cases' memory";
  } catch (const OutOfMemoryError& e) {
    const std::string what = e.what();
    EXPECT_EQ(what.rfind("case x needs about", 0), 0u) << what;
    EXPECT_NE(what.find("the machine has"), std::string::npos) << what;
    EXPECT_NE(what.find("--jobs"), std::string::npos) << what;
  }
  h.address_space_bytes = 0.5 * one;
  try {
    check_memory_fits({&scene}, "the scene", h);
    FAIL() << "a case fit in half its memory";
  } catch (const OutOfMemoryError& e) {
    EXPECT_NE(std::string(e.what()).find("ulimit -v"), std::string::npos) << e.what();
  }
}

// The address space this process has mapped (VmSize).
double mapped_bytes() {
  std::ifstream f("/proc/self/status");
  std::string key;
  double kb = 0;
  while (f >> key)
    if (key == "VmSize:" && f >> kb) break;
  return kb * 1024;
}

// Allocates 1 MB blocks inside a noexcept function, where a std::bad_alloc would end the
// process (nlohmann::json's destructor allocates so), until memory runs out.
void fill_noexcept(std::vector<std::unique_ptr<char[]>>& held) noexcept {
  while (!memory_ran_out()) held.emplace_back(new char[1u << 20]);
}

// Mid-run, past the check: the allocation that finds no memory gets through on the reserve
// the new-handler gives back, memory_ran_out() turns true, the next poll throws std::bad_alloc
// where throwing is safe, and once the memory is freed the reserve is taken again.
TEST(MemoryReserve, TheNewHandlerGetsTheFailingAllocationThroughAndThePollThrows) {
  if (test::kSanitized)
    GTEST_SKIP() << "a sanitizer's shadow memory does not fit under an address-space limit";
  EXPECT_EXIT(
      {
        rlimit limit{};
        ::getrlimit(RLIMIT_AS, &limit);
        limit.rlim_cur = static_cast<rlim_t>(mapped_bytes()) + (256u << 20);
        ::setrlimit(RLIMIT_AS, &limit);
        arm_memory_reserve(16u << 20);
        std::vector<std::unique_ptr<char[]>> held;
        held.reserve(4096);
        fill_noexcept(held);
        bool threw = false;
        try {
          throw_if_memory_ran_out();
        } catch (const std::bad_alloc&) {
          threw = true;
        }
        held.clear();
        rearm_memory_reserve();
        std::_Exit(threw && !memory_ran_out() ? 0 : 3);
      },
      ::testing::ExitedWithCode(0), "");
}

}  // namespace
}  // namespace crevasse
