#include "edm/runtime/pin.hpp"

namespace edm::rt {

std::string_view to_string(PinType t) noexcept {
  switch (t) {
    case PinType::kBool: return "BOOL";
    case PinType::kInt: return "LINT";
    case PinType::kReal: return "LREAL";
  }
  return "?";
}

double read_pin_as_double(const PinRef& ref) noexcept {
  if (ref.pin == nullptr) {
    return 0.0;
  }
  switch (ref.type) {
    case PinType::kBool:
      return ref.dir == PinDir::kInput ? (static_cast<Input<bool>*>(ref.pin)->get() ? 1.0 : 0.0)
                                       : (static_cast<Output<bool>*>(ref.pin)->get() ? 1.0 : 0.0);
    case PinType::kInt:
      return static_cast<double>(ref.dir == PinDir::kInput
                                     ? static_cast<Input<std::int64_t>*>(ref.pin)->get()
                                     : static_cast<Output<std::int64_t>*>(ref.pin)->get());
    case PinType::kReal:
      return ref.dir == PinDir::kInput ? static_cast<Input<double>*>(ref.pin)->get()
                                       : static_cast<Output<double>*>(ref.pin)->get();
  }
  return 0.0;
}

}  // namespace edm::rt
