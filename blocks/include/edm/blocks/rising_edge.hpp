#pragma once
// RisingEdge: IEC 61131-3 R_TRIG, true for the one cycle in which a bool input goes from false to
// true. An input that is already true at the first call counts as a rising edge.
// RT-safe (noexcept, no allocation). Not thread-safe: the owning block's task calls it.

namespace edm::blocks {

class RisingEdge {
 public:
  /// Feeds this cycle's value; true on a rising edge.
  [[nodiscard]] bool operator()(bool now) noexcept {
    const bool edge = now && !prev_;
    prev_ = now;
    return edge;
  }
  /// Forgets the previous value (as after activation).
  void reset() noexcept { prev_ = false; }

 private:
  bool prev_{false};
};

}  // namespace edm::blocks
