#pragma once
// One Modbus request PDU served against a register map (docs/modbus.md "Exceptions"), by the
// rules of the MODBUS Application Protocol 1.1b3 (§6, §7): functions 1-4 (reads), 5, 6, 15, 16
// (writes); exception 01 for every other function code, 0x80-0xFF included, always with the
// request's function byte | 0x80 (0x83 is answered 0x83 01, never wrapped to 0x03). Checks in
// the specification's order: function (01), quantity and length (03), address (02), then the
// access itself (02, 03, 04, 06 from RegisterAccess). No sockets and no MBAP: server.cpp frames.
//
// Not RT (the server's thread); no allocation. Thread-safety: serve_pdu() is reentrant and only
// calls the RegisterAccess it is given.

#include <cstddef>
#include <cstdint>

#include "edm/modbus/pin_map.hpp"

namespace edm::modbus {

inline constexpr std::size_t kMaxPduBytes = 253;

enum class Exception : std::uint8_t {
  kNone = 0,
  kIllegalFunction = 1,
  kIllegalDataAddress = 2,
  kIllegalDataValue = 3,
  kDeviceFailure = 4,
  kBusy = 6,
};

/// The values behind the four tables.
class RegisterAccess {
 public:
  virtual ~RegisterAccess() = default;
  /// [addr, addr + nb) of table t into out[0, nb) (bits as 0/1); addr + nb ≤ 65536, 1 ≤ nb ≤
  /// 2000.
  virtual Exception read(Table t, std::uint16_t addr, std::uint16_t nb,
                         std::uint16_t* out) noexcept = 0;
  /// Writes [addr, addr + nb) of coils or holding registers from in[0, nb) (bits as 0/1).
  virtual Exception write(Table t, std::uint16_t addr, std::uint16_t nb,
                          const std::uint16_t* in) noexcept = 0;
};

/// Whether function code fc is served: 1, 2, 3, 4, 5, 6, 15, 16.
[[nodiscard]] bool is_served_function(std::uint8_t fc) noexcept;

/// Serves the request PDU req[0, n) (n ≥ 1, the function code first) into rsp, which has room
/// for kMaxPduBytes; returns the response PDU's length (2 for an exception: fc | 0x80, code).
std::size_t serve_pdu(const std::uint8_t* req, std::size_t n, std::uint8_t* rsp,
                      RegisterAccess& regs) noexcept;

}  // namespace edm::modbus
