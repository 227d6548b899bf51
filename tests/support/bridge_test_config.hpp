#pragma once
// The small machine the bridge tests and the protocol fuzzer serve: loopback I/O, one 1 kHz task,
// one Gain block (chain.g) between io.ai0 and io.ao0.

namespace edm::test {

inline constexpr const char* kBridgeTestConfig = R"(version: 1
machine:
  name: bridge-test
  io: {driver: loopback, task: fast, params: {channels: 2}}
  axes:
    - {name: X, min_mm: -100, max_mm: 100}
    - {name: Y, min_mm: -100, max_mm: 100}
    - {name: Z, min_mm: -60, max_mm: 20}
conditions:
  - {E: 1, name: rough}
tasks:
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
