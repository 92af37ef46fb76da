#include "study/memory_reserve.hpp"

#include <sys/mman.h>

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdlib>
#include <mutex>
#include <new>
#include <thread>

namespace crevasse {
namespace {

std::mutex g_mutex;
std::condition_variable g_handled;
std::atomic<bool> g_armed{false};
std::atomic<bool> g_ran_out{false};
std::atomic<bool> g_gate{false};  // other threads wait while the thread that ran out unwinds
// Guarded by g_mutex:
std::thread::id g_holder;
std::chrono::steady_clock::time_point g_ran_out_at;
void* g_mapped = nullptr;
std::size_t g_mapped_bytes = 0;
// Part of the reserve lives in the malloc heap: address space freed by munmap serves mmap and
// the stacks, but memory a failed case gave back to the heap stays there, and only heap blocks
// can be taken again from it.
constexpr std::size_t kBlocks = 64;
constexpr std::size_t kBlockBytes = 64u << 10;
void* g_blocks[kBlocks] = {};

// A wait is bounded: a failure handled where nobody calls rearm_memory_reserve(), or a thread
// that ran out waiting for one that waits for it, only costs this long.
constexpr auto kWaitLimit = std::chrono::seconds(2);

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

void wait_for_handling(std::unique_lock<std::mutex>& lock) {
  if (!g_gate || g_holder == std::this_thread::get_id()) return;
  if (!g_handled.wait_until(lock, g_ran_out_at + kWaitLimit, [] { return !g_gate.load(); }))
    g_gate = false;  // not handled in time: stop holding the others up
}

// malloc failed: returns to have the allocation retried, or throws std::bad_alloc.
void on_allocation_failure() {
  std::unique_lock<std::mutex> lock(g_mutex);
  if (g_gate && g_holder != std::this_thread::get_id()) {
    wait_for_handling(lock);
    return;
  }
  if (give_reserve_back()) {
    g_holder = std::this_thread::get_id();
    g_ran_out_at = std::chrono::steady_clock::now();
    g_ran_out = true;
    g_gate = true;
    return;
  }
  throw std::bad_alloc();
}

void* allocate(std::size_t n) {
  if (n == 0) n = 1;
  if (g_gate.load(std::memory_order_relaxed)) {
    std::unique_lock<std::mutex> lock(g_mutex);
    wait_for_handling(lock);
  }
  for (;;) {
    if (void* p = std::malloc(n)) return p;
    if (!g_armed.load(std::memory_order_relaxed)) throw std::bad_alloc();
    on_allocation_failure();
  }
}

}  // namespace

bool arm_memory_reserve(std::size_t bytes) {
  std::lock_guard<std::mutex> lock(g_mutex);
  if (!g_armed) g_mapped_bytes = bytes > kBlocks * kBlockBytes ? bytes - kBlocks * kBlockBytes : 0;
  take_reserve();
  g_armed = true;
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
  g_gate = false;
  g_holder = {};
  g_handled.notify_all();
}

}  // namespace crevasse

// The replaceable allocation functions ([new.delete.single], [new.delete.array]); libstdc++'s
// nothrow forms call these, and operator delete stays the library's (std::free). They replace
// the library's in every program that links this object (the runner references it). The
// aligned forms (align_val_t) keep the library's: nothing here allocates over-aligned types.
void* operator new(std::size_t n) { return crevasse::allocate(n); }
void* operator new[](std::size_t n) { return crevasse::allocate(n); }
