#pragma once
// The Modbus server's register map over the variable registry (docs/modbus.md): a read takes
// VariableRegistry::read() — lock-free loads of pins, parameters from their shadow copies — the
// path of the bridge's var.read; a write goes through VariableRegistry::write() (validated,
// queued to the owning task, applied at the start of its next cycle), only to entries marked
// writable. Exceptions: 02 for an unmapped address, a value not writable or half of a 32-bit
// value written alone; 03 for a value the parameter refuses; 04 when a variable cannot be read;
// 06 when the task's write queue is full.
//
// Not RT: called on the server's thread only. The registry is thread-safe for non-RT callers;
// the RT tasks see a write only through their own bounded queue (Task::post_param_write).
// Thread-safety: one thread at a time.

#include <cstdint>
#include <string>
#include <vector>

#include "edm/modbus/server_config.hpp"
#include "edm/modbus/server_pdu.hpp"
#include "edm/runtime/variables.hpp"

namespace edm::modbus {

class MapRegisters final : public RegisterAccess {
 public:
  MapRegisters(rt::VariableRegistry& vars, const std::vector<ServerEntry>& map);

  Exception read(Table t, std::uint16_t addr, std::uint16_t nb,
                 std::uint16_t* out) noexcept override;
  Exception write(Table t, std::uint16_t addr, std::uint16_t nb,
                  const std::uint16_t* in) noexcept override;

  /// What the last write() did, for the log: "wrote p.g.k = 3", "write p.lp.tau = 0 refused:
  /// …", or both ("wrote a = 1; write b = 0 refused: …"); empty when it wrote nothing and no
  /// value was refused (an address error). Cleared by take_note().
  struct Note {
    std::string text;
    bool refused{false};
  };
  Note take_note() noexcept;
  [[nodiscard]] std::uint64_t writes() const noexcept { return writes_; }

 private:
  const ServerEntry* entry_at(Table t, std::uint32_t addr) const noexcept;
  Exception write_checked(Table t, std::uint16_t addr, std::uint16_t nb, const std::uint16_t* in);

  rt::VariableRegistry& vars_;
  const std::vector<ServerEntry>& map_;
  std::vector<std::vector<std::int16_t>> index_;  // per table: address → entry (-1: unmapped)
  Note note_;
  std::uint64_t writes_{0};
};

}  // namespace edm::modbus
