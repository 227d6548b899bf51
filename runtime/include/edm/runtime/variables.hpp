#pragma once
// The variable registry: every pin and parameter of every block (and of the I/O driver) as a
// variable named `program.block.pin` (driver: `io.pin`), listable, readable, writable
// (parameters) and forceable (pins).
//
// Reads of pins are lock-free atomic loads. Parameter reads and writes go through the block's
// shadow parameter copy under a mutex (non-RT threads only); an accepted write is queued to the
// owning task and applied at the start of its next cycle. The RT threads touch this registry
// only through release_forces() (lock-free, no allocation). Forcing semantics: see pin.hpp.
//
// The safe state wins over forces: in FAULT and ESTOP force() is refused, and the tasks
// call release_forces() at the start of every cycle in those states, so a force that raced in
// is gone before the outputs are latched. Forces are released, not masked: reset never brings a
// forced motion back; the operator must force again, deliberately (docs/runtime.md "Forcing").
//
// Thread-safety: all members are thread-safe for non-RT callers once the runtime is built;
// release_forces() also from the RT threads.

#include <atomic>
#include <mutex>
#include <optional>
#include <string>
#include <string_view>
#include <unordered_map>
#include <vector>

#include "edm/runtime/block.hpp"
#include "edm/runtime/param.hpp"
#include "edm/runtime/pin.hpp"

namespace edm::rt {

class Task;
class Machine;

enum class VarKind : std::uint8_t { kInput, kOutput, kParam };
std::string_view to_string(VarKind k) noexcept;

struct Variable {
  std::string name;  // program.block.pin | io.pin
  VarKind kind{VarKind::kOutput};
  PinRef pin{};  // pins
  Block* block{nullptr};
  std::uint32_t param_index{0};
  ParamType param_type{ParamType::kReal};
  std::string unit;
  Task* owner{nullptr};  // the task whose thread updates it
  // Parameters: from the block's ParamSpec.
  std::string description;
  std::string range;  // "> 0", "[1, 65536]", "" (any)
  // What write() accepts (with param_finite), checked before the block sees the value.
  Range param_range{};
  bool param_finite{true};
  bool load_time_only{false};

  [[nodiscard]] bool is_pin() const noexcept { return kind != VarKind::kParam; }
  /// The IEC type name: BOOL, LINT, LREAL, TIME, STRING.
  [[nodiscard]] std::string_view type_name() const noexcept;
};

/// One line of `edmplc --list-vars`: name, kind, type, unit, task, then for parameters the
/// range, "load-time" or "runtime", and the description; tab-separated, "-" for empty.
std::string list_row(const Variable& v);

enum class VarResult : std::uint8_t {
  kOk,
  kNotFound,      // no such variable
  kWrongKind,     // e.g. writing a pin or forcing a parameter
  kTypeMismatch,  // value does not fit the variable's type
  kInvalid,       // outside the parameter's range, or its block's validate() refused it
  kBusy,          // the task's write queue is full
  kInvalidState,  // refused in this machine state (forcing in FAULT or ESTOP)
};

struct VarStatus {
  VarResult result{VarResult::kOk};
  std::string message;
  explicit operator bool() const noexcept { return result == VarResult::kOk; }
};

class VariableRegistry {
 public:
  /// Adds a variable; false if the name exists. Non-RT, build time.
  bool add(Variable v);

  [[nodiscard]] const Variable* find(std::string_view name) const;
  /// Every variable: pins sorted by name, then parameters in program and block order.
  [[nodiscard]] const std::vector<Variable>& all() const noexcept { return vars_; }

  /// Current value (pins: live value; params: the accepted value). Bools as 0/1, TIME in
  /// seconds. nullopt for unknown names and string parameters.
  [[nodiscard]] std::optional<double> read(std::string_view name) const;
  [[nodiscard]] std::optional<ParamValue> read_param(std::string_view name) const;

  /// Writes a parameter: the one entry point of every runtime writer (bridge var.write, Modbus,
  /// MQTT). Checks the type, then the value against the parameter's ParamSpec range (and
  /// finiteness: NaN and ±inf are refused) — kInvalid "out of range", nothing changed — then
  /// validates on the block's shadow copy and queues it to the owning task (or applies it at
  /// once when `apply_now`, only before tasks run).
  VarStatus write(std::string_view name, double value, bool apply_now = false);
  VarStatus write(std::string_view name, const ParamValue& value, bool apply_now = false);
  /// Forces a pin to a value (converted to the pin's type: bool ≠ 0, integers must be whole).
  VarStatus force(std::string_view name, double value);
  VarStatus unforce(std::string_view name);
  [[nodiscard]] std::vector<std::string> forced() const;

  /// The machine whose state gates force(). Non-RT, build time; nullptr: never refused.
  void set_machine(const Machine* m) noexcept { machine_ = m; }
  /// Unforces every forced pin; returns how many were forced. Cheap when none is (one atomic
  /// exchange). RT-safe: no allocation, no lock; any thread.
  std::size_t release_forces() noexcept;

 private:
  /// The parameter called name, or nullptr with status saying why not.
  const Variable* find_param(std::string_view name, VarStatus& status) const;

  std::vector<Variable> vars_;
  std::unordered_map<std::string, std::size_t> index_;
  mutable std::mutex param_mutex_;  // non-RT only: guards the blocks' shadow parameters
  const Machine* machine_{nullptr};
  std::atomic<bool> maybe_forced_{false};  // set after every force(); cleared by a full sweep
};

}  // namespace edm::rt
