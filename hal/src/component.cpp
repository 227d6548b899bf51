#include "edm/hal/component.hpp"

#include <hal.h>  // a system header (CMake): it trips -Wvolatile and -Wpedantic otherwise
#include <rtapi.h>
#include <sys/ipc.h>
#include <sys/shm.h>

#include <cerrno>
#include <cstring>

namespace edm::hal {

namespace {

// HAL's shared-memory key (hal_priv.h, not installed): "HAL2".
constexpr key_t kHalKey = 0x48414C32;

hal_type_t hal_type_of(HalType t) noexcept {
  switch (t) {
    case HalType::kBit: return HAL_BIT;
    case HalType::kFloat: return HAL_FLOAT;
    case HalType::kS32: return HAL_S32;
    case HalType::kU32: return HAL_U32;
  }
  return HAL_FLOAT;
}

std::string why(int rc) {
  switch (-rc) {
    case EINVAL: return "refused by HAL (EINVAL: a name in use, too long, or HAL locked)";
    case ENOMEM: return "HAL's shared memory is full (ENOMEM)";
    case EPERM: return "HAL is locked (EPERM: halcmd lock)";
    default: return std::string("error ") + std::to_string(rc) + " (" + std::strerror(-rc) + ")";
  }
}

}  // namespace

std::string_view to_string(HalType t) noexcept {
  switch (t) {
    case HalType::kBit: return "bit";
    case HalType::kFloat: return "float";
    case HalType::kS32: return "s32";
    case HalType::kU32: return "u32";
  }
  return "?";
}

bool hal_running() noexcept { return shmget(kHalKey, 0, 0) >= 0 || errno == EACCES; }

std::string Component::open(const std::string& name) {
  close();
  if (!hal_running()) {
    return "HAL is not running (no HAL shared memory): start it first (halrun, or LinuxCNC)";
  }
  if (name.empty() || name.size() > HAL_NAME_LEN) {
    return "component name must be 1 to " + std::to_string(HAL_NAME_LEN) + " characters";
  }
  const int id = hal_init(name.c_str());
  if (id <= 0) {
    return "HAL refused component '" + name + "': " +
           (id == -EINVAL ? std::string("the name is in use (another component, or one that "
                                        "died: halcmd unloadusr)")
                          : why(id));
  }
  id_ = id;
  name_ = name;
  return {};
}

std::string Component::add_pin(std::string_view pin, HalType type, HalDir dir, PinSlot& out) {
  if (id_ <= 0) {
    return "no HAL component";
  }
  const std::string full = name_ + "." + std::string(pin);
  if (full.size() > HAL_NAME_LEN) {
    return "HAL pin name '" + full + "' is longer than " + std::to_string(HAL_NAME_LEN);
  }
  auto* slot = static_cast<void**>(hal_malloc(sizeof(void*)));
  if (slot == nullptr) {
    return "HAL's shared memory is full (hal_malloc)";
  }
  const int rc = hal_pin_new(full.c_str(), hal_type_of(type), dir == HalDir::kIn ? HAL_IN : HAL_OUT,
                             slot, id_);
  if (rc != 0) {
    return "HAL pin '" + full + "' cannot be created: " + why(rc);
  }
  out.slot = slot;
  out.type = type;
  return {};
}

std::string Component::link(std::string_view pin, std::string_view signal, HalType type) {
  const std::string full = name_ + "." + std::string(pin);
  const std::string sig(signal);
  // An existing signal (a .hal file netted the hardware first) is the usual case: quiet HAL's
  // "duplicate signal" message for this one call.
  const int level = rtapi_get_msg_level();
  rtapi_set_msg_level(RTAPI_MSG_NONE);
  int rc = hal_signal_new(sig.c_str(), hal_type_of(type));
  rtapi_set_msg_level(level);
  // -EINVAL: it exists already (of any type: hal_link says whether the types agree).
  if (rc != 0 && rc != -EINVAL) {
    return "HAL signal '" + sig + "' cannot be created: " + why(rc);
  }
  rc = hal_link(full.c_str(), sig.c_str());
  if (rc != 0) {
    return "HAL pin '" + full + "' cannot be linked to signal '" + sig + "': " +
           (rc == -EINVAL ? "the signal has another type or already has a writer" : why(rc));
  }
  return {};
}

std::string Component::ready() {
  const int rc = hal_ready(id_);
  return rc == 0 ? std::string{} : "hal_ready: " + why(rc);
}

void Component::close() noexcept {
  if (id_ > 0) {
    hal_exit(id_);
    id_ = 0;
  }
}

}  // namespace edm::hal
