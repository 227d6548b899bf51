#pragma once
// Electrode: the control's estimate of the electrode's length, what keeps the tip where a part
// program says after the electrode has worn (issue 33; docs/gcode.md "Electrode length
// compensation"). EDM electrodes wear by millimetres a hole, so a Z offset set by touching the
// work with one length is wrong by the length lost since:
//   - each work frame's Z remembers the length it was set with (WorkFrame::z_electrode_mm);
//   - the job sequencer moves a block interpreted in that frame by length now − that length
//     (a shorter electrode: the axis goes lower by what it lost), and lowers this estimate by the
//     wear it estimates while it drills (RT);
//   - the operator sets it after an electrode change or a measurement (non-RT, the bridge's
//     electrode.set); the retain store keeps it across restarts.
// 0 is "unknown": no compensation, and a frame set meanwhile records 0.
//
// Thread-safety: every member may be called from any thread; RT-safe (one atomic double).

#include <atomic>
#include <cmath>

namespace edm::rt {

class Electrode {
 public:
  /// The estimated length now [mm]; 0 = unknown.
  [[nodiscard]] double length_mm() const noexcept {
    return length_.load(std::memory_order_acquire);
  }
  [[nodiscard]] bool known() const noexcept { return length_mm() > 0.0; }
  /// A length that is not finite or negative is ignored; 0 makes it unknown.
  void set_length_mm(double mm) noexcept {
    if (std::isfinite(mm) && mm >= 0.0) length_.store(mm, std::memory_order_release);
  }

 private:
  std::atomic<double> length_{0.0};
};

}  // namespace edm::rt
