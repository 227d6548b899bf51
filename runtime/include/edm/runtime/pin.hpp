#pragma once
// Typed pins: the data inputs and outputs of blocks, drivers and programs.
//
// An Output owns its value; an Input holds a direct pointer to the Output it is wired to
// (resolved once at load), or to its own constant when unwired. Values live in relaxed atomics,
// so any thread (trace, bridge, stats) reads a pin without tearing and without a lock; on x86-64
// these are plain loads and stores.
//
// Forcing (as in CODESYS): a forced pin takes the forced value regardless of the program.
//  - forced Output: every set() by the owning block stores the forced value instead, so every
//    reader (wires, trace, bridge, I/O) sees the forced value from the next cycle on;
//  - forced Input: get() returns the forced value; the wire is not read.
// unforce() returns the pin to its computed value: at the next set() for outputs, at once for
// inputs. release() (outputs) also puts the block's last computed value back at once.
// The runtime releases every force when the machine enters FAULT or ESTOP (the safe state
// wins over forces; docs/runtime.md "Forcing").
//
// Supervision (inputs only): the safety supervisor (supervisor.hpp) may replace what an Input
// of the process image reads — a refused velocity, a generator pin held off in FAULT. It ranks
// above a force: get() returns the supervised value, then the forced one, then the wire.
// requested() is what the input would read without the supervisor.
//
// RT-safe: get(), set(), drive(). Non-RT: connect(), follow(), claim(), set_constant().
// force()/unforce() may be called from any thread. Pins are neither copyable nor movable (wires
// point at them).

#include <atomic>
#include <cstdint>
#include <string_view>
#include <vector>

namespace edm::rt {

/// IEC 61131-3 elementary types used on pins: BOOL, LINT (64-bit integer), LREAL (double).
enum class PinType : std::uint8_t { kBool, kInt, kReal };

std::string_view to_string(PinType t) noexcept;

template <class T>
struct PinTypeOf;
template <>
struct PinTypeOf<bool> {
  static constexpr PinType value = PinType::kBool;
};
template <>
struct PinTypeOf<std::int64_t> {
  static constexpr PinType value = PinType::kInt;
};
template <>
struct PinTypeOf<double> {
  static constexpr PinType value = PinType::kReal;
};

template <class T>
concept PinValue = requires {
  PinTypeOf<T>::value;
};

class PinTable;

template <PinValue T>
class Output {
 public:
  explicit Output(T initial = T{}) noexcept : value_(initial), computed_(initial) {}
  /// A named output, listed by `table` (its owner's pins) under `name` with `unit`. Both strings
  /// must outlive the owner (string literals). Non-RT (construction).
  Output(PinTable& table, std::string_view name, std::string_view unit = {}, T initial = T{});
  Output(const Output&) = delete;
  Output& operator=(const Output&) = delete;

  /// Writes the block's result (or the forced value while forced). RT-safe.
  void set(T v) noexcept {
    computed_.store(v, std::memory_order_relaxed);
    value_.store(
        forced_.load(std::memory_order_acquire) ? force_value_.load(std::memory_order_relaxed) : v,
        std::memory_order_relaxed);
  }
  /// Current value. RT-safe, any thread.
  [[nodiscard]] T get() const noexcept { return value_.load(std::memory_order_relaxed); }

  void force(T v) noexcept {
    force_value_.store(v, std::memory_order_relaxed);
    forced_.store(true, std::memory_order_release);
    value_.store(v, std::memory_order_relaxed);
  }
  /// Ends the force; readers see the computed value from the owner's next set() (a block whose
  /// output is its state, e.g. an integrator, continues from the forced value).
  void unforce() noexcept { forced_.store(false, std::memory_order_release); }
  /// Ends the force and puts the block's last computed value back at once: the safe state's
  /// release, which must not leave a forced value on a wire until a slower task's next cycle.
  void release() noexcept {
    forced_.store(false, std::memory_order_release);
    value_.store(computed_.load(std::memory_order_relaxed), std::memory_order_relaxed);
  }
  [[nodiscard]] bool forced() const noexcept { return forced_.load(std::memory_order_acquire); }

  [[nodiscard]] const std::atomic<T>& cell() const noexcept { return value_; }

 private:
  std::atomic<T> value_;
  std::atomic<T> computed_;  // the block's last set(), restored by unforce()
  std::atomic<T> force_value_{};
  std::atomic<bool> forced_{false};
};

template <PinValue T>
class Input {
 public:
  /// default_value is what an unwired input reads (YAML may replace it with a constant).
  explicit Input(T default_value = T{}) noexcept : constant_(default_value) {}
  /// A named input, listed by `table` (its owner's pins) under `name` with `unit`. Both strings
  /// must outlive the owner (string literals). Non-RT (construction).
  Input(PinTable& table, std::string_view name, std::string_view unit = {}, T default_value = T{});
  Input(const Input&) = delete;
  Input& operator=(const Input&) = delete;

  /// The supervised value while supervised, else requested(). RT-safe.
  [[nodiscard]] T get() const noexcept {
    const std::uint8_t m = mode_.load(std::memory_order_acquire);
    if (m == 0) {
      return wired();
    }
    if ((m & kSupervised) != 0) {
      return supervised_value_.load(std::memory_order_relaxed);
    }
    return force_value_.load(std::memory_order_relaxed);
  }
  /// The forced value, or the wired source's current value, or the constant if unwired: what
  /// the input reads when the supervisor does not intervene. RT-safe.
  [[nodiscard]] T requested() const noexcept {
    if ((mode_.load(std::memory_order_acquire) & kForced) != 0) {
      return force_value_.load(std::memory_order_relaxed);
    }
    return wired();
  }

  /// Wires this input to an output. Non-RT (load time only).
  void connect(const Output<T>& source) noexcept {
    src_ = &source.cell();
    via_ = nullptr;
    connected_ = true;
    driven_ = false;
  }
  /// Reads whatever `outer` reads: its wire, its constant, or its forced value. A composite
  /// hands one of its own inputs to a child this way. Non-RT (bind time).
  void follow(const Input& outer) noexcept {
    via_ = &outer;
    connected_ = true;
    driven_ = false;
  }
  /// Makes this input the owner's to drive (drive() below): it reads its own cell, which only
  /// the composite that owns the child writes, the way an IEC 61131-3 FB call passes a
  /// parameter. Replaces any wire or constant YAML gave it. Non-RT (bind time).
  void claim(T initial = T{}) noexcept {
    constant_.store(initial, std::memory_order_relaxed);
    src_ = &constant_;
    via_ = nullptr;
    connected_ = true;
    driven_ = true;
  }
  /// Writes the value a claimed input reads (forced and supervised values still rank above
  /// it). RT-safe; only the owning composite's task calls it.
  void drive(T v) noexcept { constant_.store(v, std::memory_order_relaxed); }
  /// The value last driven, whatever a force makes get() return. RT-safe.
  [[nodiscard]] T driven() const noexcept { return constant_.load(std::memory_order_relaxed); }
  [[nodiscard]] bool claimed() const noexcept { return driven_; }
  /// Makes this input read a constant. Non-RT (load time only).
  void set_constant(T v) noexcept {
    constant_.store(v, std::memory_order_relaxed);
    src_ = &constant_;
    via_ = nullptr;
    connected_ = false;
    driven_ = false;
  }
  [[nodiscard]] bool connected() const noexcept { return connected_; }

  void force(T v) noexcept {
    force_value_.store(v, std::memory_order_relaxed);
    mode_.fetch_or(kForced, std::memory_order_release);
  }
  void unforce() noexcept { mode_.fetch_and(kSupervised, std::memory_order_release); }
  [[nodiscard]] bool forced() const noexcept {
    return (mode_.load(std::memory_order_acquire) & kForced) != 0;
  }

  /// The safety supervisor's override: get() returns v until end_supervision(). RT-safe; only
  /// the supervisor (the I/O task's thread) calls it.
  void supervise(T v) noexcept {
    supervised_value_.store(v, std::memory_order_relaxed);
    mode_.fetch_or(kSupervised, std::memory_order_release);
  }
  void end_supervision() noexcept {
    if ((mode_.load(std::memory_order_relaxed) & kSupervised) != 0) {
      mode_.fetch_and(kForced, std::memory_order_release);
    }
  }
  [[nodiscard]] bool supervised() const noexcept {
    return (mode_.load(std::memory_order_acquire) & kSupervised) != 0;
  }

 private:
  static constexpr std::uint8_t kForced = 1;
  static constexpr std::uint8_t kSupervised = 2;

  [[nodiscard]] T wired() const noexcept {
    if (via_ != nullptr) {
      return via_->get();
    }
    return src_->load(std::memory_order_relaxed);
  }

  std::atomic<T> constant_;
  const std::atomic<T>* src_{&constant_};
  const Input* via_{nullptr};  // follow(): read through another input
  std::atomic<T> force_value_{};
  std::atomic<T> supervised_value_{};
  std::atomic<std::uint8_t> mode_{0};  // kForced | kSupervised; one load when neither is set
  bool connected_{false};
  bool driven_{false};  // claim(): the owning composite drives it
};

enum class PinDir : std::uint8_t { kInput, kOutput };

/// A type-erased reference to one pin, as handed to PinVisitor implementations.
struct PinRef {
  PinDir dir{PinDir::kInput};
  PinType type{PinType::kReal};
  void* pin{nullptr};

  template <PinValue T>
  static PinRef of(Input<T>& p) noexcept {
    return {PinDir::kInput, PinTypeOf<T>::value, &p};
  }
  template <PinValue T>
  static PinRef of(Output<T>& p) noexcept {
    return {PinDir::kOutput, PinTypeOf<T>::value, &p};
  }
  template <PinValue T>
  [[nodiscard]] Input<T>* as_input() const noexcept {
    return dir == PinDir::kInput && type == PinTypeOf<T>::value ? static_cast<Input<T>*>(pin)
                                                                : nullptr;
  }
  template <PinValue T>
  [[nodiscard]] Output<T>* as_output() const noexcept {
    return dir == PinDir::kOutput && type == PinTypeOf<T>::value ? static_cast<Output<T>*>(pin)
                                                                 : nullptr;
  }
};

/// Reads a pin of any type as a double (bool → 0/1). RT-safe, any thread.
double read_pin_as_double(const PinRef& ref) noexcept;

/// Visits the pins of a block in declaration order. Blocks call input()/output() for each pin.
class PinVisitor {
 public:
  virtual ~PinVisitor() = default;
  template <PinValue T>
  void input(std::string_view name, Input<T>& pin, std::string_view unit = {}) {
    on_pin(name, PinRef::of(pin), unit);
  }
  template <PinValue T>
  void output(std::string_view name, Output<T>& pin, std::string_view unit = {}) {
    on_pin(name, PinRef::of(pin), unit);
  }
  /// Passes on an already type-erased pin (composites re-expose their children's pins).
  void forward(std::string_view name, PinRef ref, std::string_view unit) {
    on_pin(name, ref, unit);
  }

 protected:
  virtual void on_pin(std::string_view name, PinRef ref, std::string_view unit) = 0;
};

/// The named pins of one owner (a block, or a group of pins inside one), in the order they were
/// declared: a pin constructed with a table adds itself, so its name and unit are written once,
/// beside its declaration. Non-RT (construction and listing).
class PinTable {
 public:
  PinTable() = default;
  PinTable(const PinTable&) = delete;
  PinTable& operator=(const PinTable&) = delete;

  void add(std::string_view name, PinRef ref, std::string_view unit) {
    entries_.push_back({name, ref, unit});
  }
  /// Hands every pin to `v`, in declaration order.
  void visit(PinVisitor& v) const {
    for (const Entry& e : entries_) {
      v.forward(e.name, e.ref, e.unit);
    }
  }

 private:
  struct Entry {
    std::string_view name;
    PinRef ref;
    std::string_view unit;
  };
  std::vector<Entry> entries_;
};

template <PinValue T>
Output<T>::Output(PinTable& table, std::string_view name, std::string_view unit, T initial)
    : Output(initial) {
  table.add(name, PinRef::of(*this), unit);
}

template <PinValue T>
Input<T>::Input(PinTable& table, std::string_view name, std::string_view unit, T default_value)
    : Input(default_value) {
  table.add(name, PinRef::of(*this), unit);
}

}  // namespace edm::rt
