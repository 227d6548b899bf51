#include "edm/modbus/server_registers.hpp"

#include <fmt/format.h>

#include <array>

#include "edm/runtime/log_escape.hpp"

namespace edm::modbus {

namespace {

constexpr std::size_t kNotedValues = 4;  // values named in one write's log line, then "+N more"
constexpr std::size_t kNoteMessageBytes = 160;

std::size_t table_index(Table t) noexcept { return static_cast<std::size_t>(t); }

}  // namespace

MapRegisters::MapRegisters(rt::VariableRegistry& vars, const std::vector<ServerEntry>& map)
    : vars_(vars), map_(map), index_(4, std::vector<std::int16_t>(65536, -1)) {
  for (std::size_t i = 0; i < map_.size(); ++i) {  // ≤ 4096 entries (server_config.cpp)
    const ServerEntry& e = map_[i];
    for (std::uint32_t w = 0; w < words_of(e.enc.type) && e.address + w <= 65535; ++w) {
      index_[table_index(e.table)][e.address + w] = static_cast<std::int16_t>(i);
    }
  }
}

const ServerEntry* MapRegisters::entry_at(Table t, std::uint32_t addr) const noexcept {
  if (addr > 65535) {
    return nullptr;
  }
  const int i = index_[table_index(t)][addr];
  return i < 0 ? nullptr : &map_[static_cast<std::size_t>(i)];
}

Exception MapRegisters::read(Table t, std::uint16_t addr, std::uint16_t nb,
                             std::uint16_t* out) noexcept {
  const std::uint32_t end = std::uint32_t{addr} + nb;
  try {
    for (std::uint32_t a = addr; a < end;) {
      const ServerEntry* e = entry_at(t, a);
      if (e == nullptr) {
        return Exception::kIllegalDataAddress;
      }
      const std::optional<double> v = vars_.read(e->var);
      if (!v) {
        return Exception::kDeviceFailure;
      }
      std::array<std::uint16_t, 2> w{};
      encode(*v, e->enc, w.data());
      // A read may start or end inside a 32-bit value: copy the words that fall in the request.
      for (std::uint32_t k = 0; k < words_of(e->enc.type); ++k) {
        const std::uint32_t at = e->address + k;
        if (at >= addr && at < end) {
          out[at - addr] = w[k];
        }
      }
      a = std::uint32_t{e->address} + words_of(e->enc.type);
    }
  } catch (...) {  // an allocation in the registry's lookup: the read failed, the server goes on
    return Exception::kDeviceFailure;
  }
  return Exception::kNone;
}

Exception MapRegisters::write(Table t, std::uint16_t addr, std::uint16_t nb,
                              const std::uint16_t* in) noexcept {
  note_ = {};
  try {
    return write_checked(t, addr, nb, in);
  } catch (...) {
    return Exception::kDeviceFailure;
  }
}

Exception MapRegisters::write_checked(Table t, std::uint16_t addr, std::uint16_t nb,
                                      const std::uint16_t* in) {
  const std::uint32_t end = std::uint32_t{addr} + nb;
  // The addresses first: a request with one address that is not writable writes nothing.
  for (std::uint32_t a = addr; a < end;) {
    const ServerEntry* e = entry_at(t, a);
    if (e == nullptr || !e->writable || e->address != a || a + words_of(e->enc.type) > end) {
      return Exception::kIllegalDataAddress;
    }
    a += words_of(e->enc.type);
  }
  std::size_t noted = 0;
  for (std::uint32_t a = addr; a < end; a += words_of(entry_at(t, a)->enc.type)) {
    const ServerEntry* e = entry_at(t, a);
    const double v = decode(in + (a - addr), e->enc);
    const rt::VarStatus s = vars_.write(e->var, v);
    if (!s) {
      // The values before this one are written (VariableRegistry has no dry run): the log says
      // which, the exception that this one was refused.
      note_.text += fmt::format("{}write {} = {} refused: {}", note_.text.empty() ? "" : "; ",
                                e->var, v, rt::log_quoted(s.message, kNoteMessageBytes));
      note_.refused = true;
      switch (s.result) {
        case rt::VarResult::kBusy: return Exception::kBusy;
        case rt::VarResult::kInvalid:
        case rt::VarResult::kTypeMismatch: return Exception::kIllegalDataValue;
        default: return Exception::kDeviceFailure;
      }
    }
    ++writes_;
    if (noted < kNotedValues) {
      note_.text += fmt::format("{}{} = {}", noted == 0 ? "wrote " : ", ", e->var, v);
    } else if (noted == kNotedValues) {
      note_.text += ", …";
    }
    ++noted;
  }
  return Exception::kNone;
}

MapRegisters::Note MapRegisters::take_note() noexcept {
  Note n = std::move(note_);
  note_ = {};
  return n;
}

}  // namespace edm::modbus
