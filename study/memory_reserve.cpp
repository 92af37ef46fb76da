#include "study/memory_reserve.hpp"

#include <sys/mman.h>

#include <atomic>
#include <chrono>
#include <cstdlib>
#include <mutex>
#include <new>
#include <thread>

namespace crevasse {
namespace {

// Taken only by the new-handler and the functions below, never by an allocation that succeeds.
std::mutex g_mutex;
std::atomic<bool> g_armed{false};
std::atomic<bool> g_ran_out{false};
// Guarded by g_mutex:
std::chrono::steady_clock::time_point g_ran_out_at;
void* g_mapped = nullptr;
std::size_t g_mapped_bytes = 0;
// Part of the reserve lives in the malloc heap: address space freed by munmap serves mmap and
// the stacks, but memory a failed case gave back to the heap stays there, and only heap blocks
// can be taken again from it.
constexpr std::size_t kBlocks = 64;
constexpr std::size_t kBlockBytes = 64u << 10;
void* g_blocks[kBlocks] = {};

// Another thread that runs out while the reserve is already given back retries for this long:
// the case that took it fails at its next poll (twice a second) and frees its memory.
constexpr auto kRetryLimit = std::chrono::seconds(2);
constexpr auto kRetryPause = std::chrono::milliseconds(10);

void take_reserve() {
  if (!g_mapped && g_mapped_bytes > 0) {
    // PROT_NONE, never touched: counts against ulimit -v, costs no RAM.
    void* p = ::mmap(nullptr, g_mapped_bytes, PROT_NONE, MAP_PRIVATE | MAP_ANONYMOUS | MAP_NORESERVE, -1, 0);
    g_mapped = p == MAP_FAILED ? nullptr : p;
  }
  for (void*& b : g_blocks)
    if (!b) b = std::malloc(kBlockBytes);
}

// True when anything was given back.
bool give_reserve_back() {
  bool gave = false;
  if (g_mapped) {
    ::munmap(g_mapped, g_mapped_bytes);
    g_mapped = nullptr;
    gave = true;
  }
  for (void*& b : g_blocks) {
    if (!b) continue;
    std::free(b);
    b = nullptr;
    gave = true;
  }
  return gave;
}

// The new-handler ([new.handler]): operator new (every form) calls it when malloc fails and
// retries when it returns. It frees room or throws std::bad_alloc.
void on_allocation_failure() {
  std::unique_lock<std::mutex> lock(g_mutex);
  if (give_reserve_back()) {
    g_ran_out_at = std::chrono::steady_clock::now();
    g_ran_out = true;
    return;
  }
  if (g_ran_out && std::chrono::steady_clock::now() - g_ran_out_at < kRetryLimit) {
    lock.unlock();
    std::this_thread::sleep_for(kRetryPause);
    return;
  }
  throw std::bad_alloc();
}

}  // namespace

bool arm_memory_reserve(std::size_t bytes) {
  std::lock_guard<std::mutex> lock(g_mutex);
  if (!g_armed) g_mapped_bytes = bytes > kBlocks * kBlockBytes ? bytes - kBlocks * kBlockBytes : 0;
  take_reserve();
  g_armed = true;
  std::set_new_handler(on_allocation_failure);
  bool whole = g_mapped || g_mapped_bytes == 0;
  for (void* b : g_blocks) whole = whole && b;
  return whole;
}

bool memory_ran_out() { return g_ran_out.load(std::memory_order_relaxed); }

void throw_if_memory_ran_out() {
  if (memory_ran_out()) throw std::bad_alloc();
}

void top_up_memory_reserve() {
  if (!g_armed) return;
  std::lock_guard<std::mutex> lock(g_mutex);
  if (!g_ran_out) take_reserve();
}

void rearm_memory_reserve() {
  if (!g_armed) return;
  std::lock_guard<std::mutex> lock(g_mutex);
  take_reserve();
  g_ran_out = false;
}

}  // namespace crevasse
