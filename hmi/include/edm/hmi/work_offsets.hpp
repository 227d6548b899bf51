#pragma once
// Work offsets (DESIGN §12, docs/gcode.md "Work offsets"): the six work frames G54..G59 the
// runtime retains (`offset.get`), the names operators use for them, and the frame a motion block
// was interpreted in. A work frame's offset is where its origin is in machine coordinates:
//   machine = work + frame offset + G92 offset.
//
// Non-RT; plain data and pure functions (thread-compatible).

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

#include "edm/bridge/codec.hpp"
#include "edm/machining/motion_block.hpp"

namespace edm::hmi {

inline constexpr int kWorkFrames = 6;  // G54 .. G59

struct WorkOffsets {
  /// frame[0] is G54, frame[5] G59: each frame's origin in machine coordinates (mm).
  std::array<machining::Vec3, kWorkFrames> frame{};
  /// The electrode length each frame's Z was set with (0: unknown): a block interpreted in the
  /// frame carries it, and the job moves its Z by the length lost since.
  std::array<double, kWorkFrames> z_electrode_mm{};
  /// The electrode length when the offsets were read (`offset.get`'s electrode_mm; 0: unknown):
  /// what the program check compensates with.
  double electrode_mm{0.0};
  friend bool operator==(const WorkOffsets&, const WorkOffsets&) = default;
};

/// The frame a block was interpreted in: machine = work + offset_mm.
struct BlockFrame {
  std::uint8_t frame{0};        // 0 = G54 .. 5 = G59
  machining::Vec3 offset_mm{};  // the frame's offset plus the G92 offset then active
  bool g92{false};              // a G92 offset was active (non-zero)
  friend bool operator==(const BlockFrame&, const BlockFrame&) = default;
};

/// "G54" .. "G59" (an index outside 0..5 gives "G5?").
std::string frame_name(int index);
/// "G54" .. "G59" (case-insensitive, "g55" too) → 0..5; nullopt otherwise ("G59.1", "G53").
std::optional<int> frame_index(std::string_view name);

/// machine − offset, axis by axis.
machining::Vec3 to_work(const machining::Vec3& machine, const machining::Vec3& offset) noexcept;

/// The frames of an `offset.get` reply ({"frames": {"G54": {"x", "y", "z", "z_electrode_mm"},
/// ...}}) or of the same object saved to a file. Frames absent from `j` stay zero; an axis absent
/// from a frame is 0. False with `error` set when `j` is not that shape (a non-finite or non-number
/// coordinate, an unknown frame name).
bool offsets_from_json(const bridge::Json& j, WorkOffsets& out, std::string& error);
/// {"frames": {"G54": {"x", "y", "z"}, ...}} — what offsets_from_json reads back.
bridge::Json to_json(const WorkOffsets& offsets);

/// "G54  X   12.5000  Y   -3.0000  Z  -41.2500" (mm, 4 decimals).
std::string format_frame(int index, const machining::Vec3& offset);

}  // namespace edm::hmi
