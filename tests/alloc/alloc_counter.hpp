#pragma once
// The allocation counter of edm_alloc_tests (test code only): global operator new/delete are
// replaced in this executable (alloc_test.cpp) and count the allocations made on a thread
// while that thread's t_counting is set. A test sets it around its cycle calls on the thread
// that runs them, so a driver's own non-RT thread (the Modbus exchange: libmodbus, spdlog) may
// allocate while the cycles run without being counted.
//
// Thread-safety: t_counting is per thread; the counters are atomics. Only operator new is seen:
// malloc/calloc/realloc called directly (C libraries) are not counted. A `new` the compiler
// removed (-O2 allocation DCE of a pair whose object never escapes) is not counted either: it
// does not happen.

#include <atomic>
#include <cstddef>

namespace edm::test {

/// Set by a test on the thread that runs the cycles, around the cycle calls.
inline thread_local bool t_counting = false;
/// Allocations made on a thread while its t_counting was set.
inline std::atomic<std::size_t> g_allocations{0};
/// Every allocation through operator new, any thread, counted or not (guards the guard).
inline std::atomic<std::size_t> g_all_allocations{0};

/// Runs fn() with this thread's allocations counted; how many it made.
template <class Fn>
std::size_t allocations_in(Fn&& fn) {
  g_allocations = 0;
  t_counting = true;
  fn();
  t_counting = false;
  return g_allocations.load();
}

}  // namespace edm::test
