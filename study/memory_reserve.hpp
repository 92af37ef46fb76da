#pragma once
// Memory set aside for running out of it. A failed allocation inside a noexcept function
// (nlohmann::json's destructor allocates) ends the process with SIGABRT whatever catches
// std::bad_alloc further up, so the first failure does not throw: the program's new-handler
// (std::set_new_handler) gives the reserve back, operator new retries and succeeds, and
// memory_ran_out() turns true. A case polls it where throwing is safe and fails "out of
// memory"; the reserve is taken again once that failure has been handled. Nothing runs on the
// allocation path while memory is plentiful: the handler is called only when malloc fails.
#include <cstddef>

namespace crevasse {

// Sets `bytes` aside for the whole process (address space and heap blocks whose pages are
// never touched: no RAM) and installs the new-handler. Returns false when not all of it could
// be had.
bool arm_memory_reserve(std::size_t bytes);

// True from the failure that gave the reserve back until rearm_memory_reserve().
bool memory_ran_out();

// Where throwing is safe (a run's progress poll, the end of a case): throws std::bad_alloc
// when memory ran out. Memory is the process's, so the first case to poll fails and frees its
// own, whichever thread took the reserve.
void throw_if_memory_ran_out();

// Takes back any part of the reserve that is missing, unless a failure is being handled (a
// case start, where the previous case's memory is freed).
void top_up_memory_reserve();

// Called where an out-of-memory failure has been handled and its owner's memory freed: takes
// the reserve again. Does nothing when none was armed.
void rearm_memory_reserve();

}  // namespace crevasse
