#include "edm/modbus/server_pdu.hpp"

#include <array>
#include <cstring>

#include "protocol_limits.hpp"

namespace edm::modbus {

namespace {

constexpr std::uint8_t kReadCoils = 0x01;
constexpr std::uint8_t kReadDiscreteInputs = 0x02;
constexpr std::uint8_t kReadHoldingRegisters = 0x03;
constexpr std::uint8_t kReadInputRegisters = 0x04;
constexpr std::uint8_t kWriteSingleCoil = 0x05;
constexpr std::uint8_t kWriteSingleRegister = 0x06;
constexpr std::uint8_t kWriteMultipleCoils = 0x0F;
constexpr std::uint8_t kWriteMultipleRegisters = 0x10;

std::uint16_t be16(const std::uint8_t* p) noexcept {
  return static_cast<std::uint16_t>((p[0] << 8) | p[1]);
}

void put16(std::uint8_t* p, std::uint16_t v) noexcept {
  p[0] = static_cast<std::uint8_t>(v >> 8);
  p[1] = static_cast<std::uint8_t>(v & 0xFF);
}

std::size_t exception(std::uint8_t fc, Exception e, std::uint8_t* rsp) noexcept {
  rsp[0] = static_cast<std::uint8_t>(fc | 0x80U);
  rsp[1] = static_cast<std::uint8_t>(e);
  return 2;
}

bool runs_past_65535(std::uint16_t addr, std::uint16_t nb) noexcept {
  return std::uint32_t{addr} + nb > 65536U;
}

std::size_t serve_read(std::uint8_t fc, const std::uint8_t* req, std::size_t n, std::uint8_t* rsp,
                       RegisterAccess& regs) noexcept {
  const Table t = fc == kReadCoils              ? Table::kCoil
                  : fc == kReadDiscreteInputs   ? Table::kDiscreteInput
                  : fc == kReadHoldingRegisters ? Table::kHoldingRegister
                                                : Table::kInputRegister;
  if (n != 5) {
    return exception(fc, Exception::kIllegalDataValue, rsp);
  }
  const std::uint16_t addr = be16(req + 1);
  const std::uint16_t nb = be16(req + 3);
  const std::uint16_t max = is_bit_table(t) ? kMaxReadBits : kMaxReadRegisters;
  if (nb < 1 || nb > max) {
    return exception(fc, Exception::kIllegalDataValue, rsp);
  }
  if (runs_past_65535(addr, nb)) {
    return exception(fc, Exception::kIllegalDataAddress, rsp);
  }
  std::array<std::uint16_t, kMaxReadBits> words{};
  if (const Exception e = regs.read(t, addr, nb, words.data()); e != Exception::kNone) {
    return exception(fc, e, rsp);
  }
  rsp[0] = fc;
  if (is_bit_table(t)) {
    const std::size_t bytes = (nb + 7U) / 8U;  // ≤ 250
    rsp[1] = static_cast<std::uint8_t>(bytes);
    std::memset(rsp + 2, 0, bytes);
    for (std::size_t k = 0; k < nb; ++k) {
      if (words[k] != 0) {
        rsp[2 + k / 8] = static_cast<std::uint8_t>(rsp[2 + k / 8] | (1U << (k % 8)));
      }
    }
    return 2 + bytes;
  }
  rsp[1] = static_cast<std::uint8_t>(2U * nb);  // ≤ 250
  for (std::size_t k = 0; k < nb; ++k) {
    put16(rsp + 2 + 2 * k, words[k]);
  }
  return 2 + 2U * nb;
}

std::size_t serve_write_single(std::uint8_t fc, const std::uint8_t* req, std::size_t n,
                               std::uint8_t* rsp, RegisterAccess& regs) noexcept {
  if (n != 5) {
    return exception(fc, Exception::kIllegalDataValue, rsp);
  }
  const std::uint16_t addr = be16(req + 1);
  const std::uint16_t value = be16(req + 3);
  std::uint16_t word = value;
  Table t = Table::kHoldingRegister;
  if (fc == kWriteSingleCoil) {
    if (value != 0xFF00 && value != 0x0000) {
      return exception(fc, Exception::kIllegalDataValue, rsp);
    }
    word = value != 0 ? 1 : 0;
    t = Table::kCoil;
  }
  if (const Exception e = regs.write(t, addr, 1, &word); e != Exception::kNone) {
    return exception(fc, e, rsp);
  }
  std::memcpy(rsp, req, 5);  // the reply echoes the request
  return 5;
}

std::size_t serve_write_multiple(std::uint8_t fc, const std::uint8_t* req, std::size_t n,
                                 std::uint8_t* rsp, RegisterAccess& regs) noexcept {
  const bool bits = fc == kWriteMultipleCoils;
  if (n < 6) {
    return exception(fc, Exception::kIllegalDataValue, rsp);
  }
  const std::uint16_t addr = be16(req + 1);
  const std::uint16_t nb = be16(req + 3);
  const std::uint16_t max = bits ? kMaxWriteBits : kMaxWriteRegisters;
  const std::size_t bytes = bits ? (nb + 7U) / 8U : 2U * nb;
  if (nb < 1 || nb > max || req[5] != bytes || n != 6 + bytes) {
    return exception(fc, Exception::kIllegalDataValue, rsp);
  }
  if (runs_past_65535(addr, nb)) {
    return exception(fc, Exception::kIllegalDataAddress, rsp);
  }
  std::array<std::uint16_t, kMaxWriteBits> words{};
  for (std::size_t k = 0; k < nb; ++k) {
    words[k] =
        bits ? static_cast<std::uint16_t>((req[6 + k / 8] >> (k % 8)) & 1U) : be16(req + 6 + 2 * k);
  }
  const Table t = bits ? Table::kCoil : Table::kHoldingRegister;
  if (const Exception e = regs.write(t, addr, nb, words.data()); e != Exception::kNone) {
    return exception(fc, e, rsp);
  }
  rsp[0] = fc;
  put16(rsp + 1, addr);
  put16(rsp + 3, nb);
  return 5;
}

}  // namespace

bool is_served_function(std::uint8_t fc) noexcept {
  switch (fc) {
    case kReadCoils:
    case kReadDiscreteInputs:
    case kReadHoldingRegisters:
    case kReadInputRegisters:
    case kWriteSingleCoil:
    case kWriteSingleRegister:
    case kWriteMultipleCoils:
    case kWriteMultipleRegisters: return true;
    default: return false;
  }
}

std::size_t serve_pdu(const std::uint8_t* req, std::size_t n, std::uint8_t* rsp,
                      RegisterAccess& regs) noexcept {
  const std::uint8_t fc = req[0];
  switch (fc) {
    case kReadCoils:
    case kReadDiscreteInputs:
    case kReadHoldingRegisters:
    case kReadInputRegisters: return serve_read(fc, req, n, rsp, regs);
    case kWriteSingleCoil:
    case kWriteSingleRegister: return serve_write_single(fc, req, n, rsp, regs);
    case kWriteMultipleCoils:
    case kWriteMultipleRegisters: return serve_write_multiple(fc, req, n, rsp, regs);
    default: return exception(fc, Exception::kIllegalFunction, rsp);
  }
}

}  // namespace edm::modbus
