#pragma once
// The fuzz entry functions (docs/testing.md, "Fuzzing and sanitizers"). Each tests/fuzz/fuzz_*.cpp
// defines one; built with EDM_LIBFUZZER it also defines LLVMFuzzerTestOneInput around it (the
// libFuzzer executables of build-fuzz/), and without it the same source is linked into the
// GoogleTest replay of tests/fuzz/regressions/ and tests/fuzz/corpus/ (replay_test.cpp).
//
// Contract of an entry: any bytes are a normal input. An entry returns 0 for every input; a bug
// (a crash, an exception the API does not allow, a broken invariant) ends the process through
// EDM_FUZZ_CHECK, so libFuzzer records a reproducer and the replay test fails.
// Not RT-safe; not thread-safe (entries keep function-local state built on first use).

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>

namespace edm::fuzz {

/// G-code interpreter (hmi/): the bytes as a part program against config/machines/drill-sim.yaml.
int gcode_one_input(const std::uint8_t* data, std::size_t size);
/// Config loader and validator (runtime/): the bytes as a config file, parsed and built.
int config_one_input(const std::uint8_t* data, std::size_t size);
/// Retain file reader (runtime/): the bytes as a retain file.
int retain_one_input(const std::uint8_t* data, std::size_t size);
/// Bridge protocol (hmi_bridge/): the bytes as the lines a client sends.
int protocol_one_input(const std::uint8_t* data, std::size_t size);
/// The page's WebSocket handler (hmi/): the bytes as a browser's messages, cut at 0xFF.
int page_one_input(const std::uint8_t* data, std::size_t size);

/// Ends the process with a message when an invariant of the code under test is broken.
[[noreturn]] inline void fail(const char* file, int line, const char* what) {
  std::fprintf(stderr, "%s:%d: fuzz invariant broken: %s\n", file, line, what);
  std::abort();
}

}  // namespace edm::fuzz

#define EDM_FUZZ_CHECK(cond)                        \
  do {                                              \
    if (!(cond)) {                                  \
      ::edm::fuzz::fail(__FILE__, __LINE__, #cond); \
    }                                               \
  } while (false)

// The libFuzzer entry point of one executable; expands to nothing in the replay test.
#ifdef EDM_LIBFUZZER
#define EDM_FUZZ_MAIN(entry)                                                          \
  extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) { \
    return entry(data, size);                                                         \
  }
#else
#define EDM_FUZZ_MAIN(entry)
#endif
