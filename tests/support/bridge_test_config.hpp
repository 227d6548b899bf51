#pragma once
// The small machine the bridge tests and the protocol fuzzer serve: loopback I/O, one 1 kHz task,
// one Gain block (chain.g) between io.ai0 and io.ao0.

#include <string>

#include "support/test_machine.hpp"

namespace edm::test {

inline const std::string kBridgeTestConfig =
    test_machine("bridge-test", "{driver: loopback, task: fast, params: {channels: 2}}") + R"(tasks:
  - name: fast
    interval: 1ms
    priority: 0
    programs: [chain]
programs:
  - name: chain
    blocks:
      - {name: g, type: Gain, params: {k: 1.0, offset: 0.0}}
    wires:
      g.in: io.ai0
      io.ao0: g.out
)";

}  // namespace edm::test
