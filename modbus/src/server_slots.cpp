#include "edm/modbus/server_slots.hpp"

namespace edm::modbus {

namespace {

// a is less useful than b.
bool less_useful(const SlotState& a, const SlotState& b) noexcept {
  if (a.use != b.use) {
    return a.use < b.use;
  }
  return a.since < b.since;
}

}  // namespace

Admission admit(std::span<const SlotState> slots, std::uint32_t peer, std::size_t max_total,
                std::size_t max_per_address) noexcept {
  constexpr std::size_t kNone = static_cast<std::size_t>(-1);
  std::size_t same = 0;
  std::size_t worst_same = kNone;   // the least useful of peer's
  std::size_t worst_other = kNone;  // the least useful kNew/kStuck of any address
  for (std::size_t i = 0; i < slots.size(); ++i) {
    const SlotState& s = slots[i];
    if (s.peer == peer) {
      ++same;
      if (worst_same == kNone || less_useful(s, slots[worst_same])) {
        worst_same = i;
      }
    }
    if (s.use != SlotState::Use::kServing &&
        (worst_other == kNone || less_useful(s, slots[worst_other]))) {
      worst_other = i;
    }
  }
  if (same >= max_per_address && worst_same != kNone) {
    return {Admission::Kind::kEvictAndAdmit, worst_same};
  }
  if (slots.size() >= max_total) {
    if (worst_other == kNone) {
      return {Admission::Kind::kRefuse, 0};
    }
    return {Admission::Kind::kEvictAndAdmit, worst_other};
  }
  return {Admission::Kind::kAdmit, 0};
}

}  // namespace edm::modbus
