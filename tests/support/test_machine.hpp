#pragma once
// The start of a small test machine's config, shared by the suites that write their own machine:
// its name and I/O, the three axes (X, Y ±100 mm, Z -60..20 mm) and condition E1. Their tasks and
// programs follow it.

#include <string>
#include <string_view>

namespace edm::test {

/// "version: 1", `machine:` named `name` with the I/O `io` ("{driver: loopback, ...}"), the
/// axes and conditions; ends with a newline, at the top level.
inline std::string test_machine(std::string_view name, std::string_view io) {
  return "version: 1\nmachine:\n  name: " + std::string(name) + "\n  io: " + std::string(io) +
         R"(
  axes:
    - {name: X, min_mm: -100, max_mm: 100}
    - {name: Y, min_mm: -100, max_mm: 100}
    - {name: Z, min_mm: -60, max_mm: 20}
conditions:
  - {E: 1, name: rough}
)";
}

}  // namespace edm::test
