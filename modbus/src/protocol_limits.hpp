#pragma once
// The most a single Modbus request may carry (MODBUS Application Protocol 1.1b3, §6.1-6.4,
// 6.11, 6.12), for both ends this library has: the driver's client and the server's PDUs.

#include <cstdint>

namespace edm::modbus {

inline constexpr std::uint16_t kMaxReadBits = 2000;
inline constexpr std::uint16_t kMaxReadRegisters = 125;
inline constexpr std::uint16_t kMaxWriteBits = 1968;
inline constexpr std::uint16_t kMaxWriteRegisters = 123;

}  // namespace edm::modbus
