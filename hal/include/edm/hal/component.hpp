#pragma once
// A LinuxCNC HAL userspace component (Debian's liblinuxcnchal, built with -DULAPI): its pins live
// in HAL's shared memory, so the real-time side reads and writes them with plain loads and stores,
// no lock, no system call (DESIGN §3). Only component.cpp includes <hal.h>.
//
// A pin's storage is two levels deep: HAL keeps, in its shared memory, the address of the value
// (`*slot`), and `net` rewrites that address to the signal's value while the component runs. So
// every access reads the slot first (pin_read/pin_write): a stale cached address would keep
// reading the pin's own dummy after it is netted.
//
// Thread-safety: Component's methods are non-RT, from one thread. pin_read/pin_write are RT-safe
// (volatile loads and stores of naturally aligned words, as HAL's own RT components do).

#include <cstdint>
#include <string>
#include <string_view>

namespace edm::hal {

enum class HalType : std::uint8_t { kBit, kFloat, kS32, kU32 };
/// HAL's direction, seen from the component: kIn = the component reads it.
enum class HalDir : std::uint8_t { kIn, kOut };

std::string_view to_string(HalType t) noexcept;

/// Where a pin's value is: the slot HAL rewrites on `net`, and the value's type.
struct PinSlot {
  void* volatile* slot{nullptr};
  HalType type{HalType::kFloat};
};

/// The value as a double (bit: 0/1; s32/u32 exact). RT-safe.
[[nodiscard]] inline double pin_read(const PinSlot& p) noexcept {
  void* const v = *p.slot;
  switch (p.type) {
    case HalType::kBit: return *static_cast<volatile bool*>(v) ? 1.0 : 0.0;
    case HalType::kFloat: return *static_cast<volatile double*>(v);
    case HalType::kS32: return static_cast<double>(*static_cast<volatile std::int32_t*>(v));
    case HalType::kU32: return static_cast<double>(*static_cast<volatile std::uint32_t*>(v));
  }
  return 0.0;
}
/// The raw 32 bits of an s32/u32 pin (a bit: 0/1). RT-safe.
[[nodiscard]] inline std::uint32_t pin_read_u32(const PinSlot& p) noexcept {
  void* const v = *p.slot;
  switch (p.type) {
    case HalType::kBit: return *static_cast<volatile bool*>(v) ? 1U : 0U;
    case HalType::kS32: return static_cast<std::uint32_t>(*static_cast<volatile std::int32_t*>(v));
    case HalType::kU32: return *static_cast<volatile std::uint32_t*>(v);
    case HalType::kFloat: break;
  }
  return 0U;
}
/// Writes `value` (bit: != 0; s32/u32: already rounded and clamped by the caller). RT-safe.
inline void pin_write(const PinSlot& p, double value) noexcept {
  void* const v = *p.slot;
  switch (p.type) {
    case HalType::kBit: *static_cast<volatile bool*>(v) = value != 0.0; break;
    case HalType::kFloat: *static_cast<volatile double*>(v) = value; break;
    case HalType::kS32:
      *static_cast<volatile std::int32_t*>(v) = static_cast<std::int32_t>(value);
      break;
    case HalType::kU32:
      *static_cast<volatile std::uint32_t*>(v) = static_cast<std::uint32_t>(value);
      break;
  }
}
inline void pin_write_u32(const PinSlot& p, std::uint32_t value) noexcept {
  *static_cast<volatile std::uint32_t*>(*p.slot) = value;
}

/// True when HAL's shared memory exists (a `halrun` or LinuxCNC session is up). Non-RT.
[[nodiscard]] bool hal_running() noexcept;

/// One userspace component: hal_init() in open(), hal_exit() in close() and the destructor.
/// Errors come back as text (never thrown, never a crash).
class Component {
 public:
  Component() = default;
  ~Component() { close(); }
  Component(const Component&) = delete;
  Component& operator=(const Component&) = delete;

  /// Joins HAL as `name`; "" on success, else why not (HAL not running, the name in use, ...).
  [[nodiscard]] std::string open(const std::string& name);
  /// Creates `<name>.<pin>`; "" on success. The slot stays valid until close().
  [[nodiscard]] std::string add_pin(std::string_view pin, HalType type, HalDir dir, PinSlot& out);
  /// Links the pin `<name>.<pin>` to signal `signal`, created with `type` when absent; "" on
  /// success, else why not (a signal of another type, a second writer).
  [[nodiscard]] std::string link(std::string_view pin, std::string_view signal, HalType type);
  /// hal_ready(): `loadusr -W` and `waitusr` see the component. "" on success.
  [[nodiscard]] std::string ready();
  void close() noexcept;
  [[nodiscard]] bool is_open() const noexcept { return id_ > 0; }
  [[nodiscard]] const std::string& name() const noexcept { return name_; }

 private:
  int id_{0};
  std::string name_;
};

}  // namespace edm::hal
