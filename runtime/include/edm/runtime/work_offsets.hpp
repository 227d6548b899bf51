#pragma once
// WorkOffsets: the work coordinate systems G54…G59 (DESIGN §11–12, issue 21) — for each frame the
// machine coordinates of the work's zero. The runtime keeps them (set by the bridge's offset.set,
// typically from a touch-off) and retains them beside the job record, so they survive a restart
// and kill -9; the HMI reads them (offset.get) to interpret a part program into machine
// coordinates. The real-time side never reads them: programs arrive in machine coordinates, each
// block with the electrode length its frame's Z was set with (electrode.hpp).
//
// Thread-safety: every member may be called from any non-RT thread (an internal mutex); nothing
// is RT-safe.

#include <array>
#include <cstdint>
#include <mutex>
#include <optional>
#include <string>
#include <string_view>

namespace edm::rt {

struct WorkFrame {
  double x{0.0}, y{0.0}, z{0.0};
  double z_electrode_mm{0.0};  // the electrode's length when z was set (Electrode; 0: unknown)
  friend bool operator==(const WorkFrame&, const WorkFrame&) = default;
};

class WorkOffsets {
 public:
  static constexpr int kFrames = 6;  // G54 … G59

  /// "G54" … "G59" (also lower case) → 0 … 5; nullopt otherwise.
  static std::optional<int> frame_index(std::string_view name) noexcept;
  static std::string frame_name(int index);

  [[nodiscard]] WorkFrame get(int index) const;
  [[nodiscard]] std::array<WorkFrame, kFrames> all() const;
  /// Sets the given axes of one frame (nullopt keeps the axis); returns the new frame. The
  /// values must be finite (the caller checks; a non-finite one is ignored here). A new z
  /// records `z_electrode_mm`, the electrode length it was set with (0: unknown).
  WorkFrame set(int index, std::optional<double> x, std::optional<double> y,
                std::optional<double> z, double z_electrode_mm = 0.0);
  /// Sets a whole frame as it was (undo, the retain store's restore). Non-finite fields are 0.
  void restore(int index, const WorkFrame& frame);
  /// Increments on every set(): the HMI's programs name the generation they were built with.
  [[nodiscard]] std::uint64_t generation() const;

 private:
  mutable std::mutex mutex_;
  std::array<WorkFrame, kFrames> frames_{};
  std::uint64_t generation_{0};
};

}  // namespace edm::rt
