#pragma once
// Who keeps a connection slot of the Modbus server when a new connection comes
// (docs/modbus.md "Connections"). A connection is, from least to most useful:
//   kNew      — no complete request yet (since: when it connected);
//   kStuck    — a frame begun and not complete, or a reply the client has not taken (since: when
//               that began);
//   kServing  — between requests (since: its last complete request).
// The newcomer from address A:
//   1. A already has max_per_address connections: the least useful of A's goes (the newest
//      connection of an address is the live one: a client that rebooted leaves a half-open
//      socket behind), and the newcomer is admitted;
//   2. else all max_total slots are taken: the least useful kNew or kStuck connection of any
//      address goes; when every slot is kServing the newcomer is refused;
//   3. else it is admitted.
// "Least useful": the lowest kind, then the oldest `since`. So clients that trickle partial
// frames, or connect and say nothing, can never keep a slot from a client that sends whole
// requests, and one address never holds more than max_per_address slots.
//
// Pure function: RT-safe in itself (no allocation), used on the server's thread only.

#include <chrono>
#include <cstddef>
#include <cstdint>
#include <span>

namespace edm::modbus {

struct SlotState {
  enum class Use : std::uint8_t { kNew, kStuck, kServing };
  std::uint32_t peer{0};  // IPv4 address, host order
  Use use{Use::kNew};
  std::chrono::steady_clock::time_point since{};
};

struct Admission {
  enum class Kind : std::uint8_t { kAdmit, kEvictAndAdmit, kRefuse };
  Kind kind{Kind::kAdmit};
  std::size_t victim{0};  // kEvictAndAdmit: the index in `slots`
};

/// The decision for a newcomer from `peer` (max_total ≥ 1, max_per_address ≥ 1).
[[nodiscard]] Admission admit(std::span<const SlotState> slots, std::uint32_t peer,
                              std::size_t max_total, std::size_t max_per_address) noexcept;

}  // namespace edm::modbus
