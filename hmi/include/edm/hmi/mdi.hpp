#pragma once
// MDI (docs/hmi.md "mdi"): one G-code line typed by the operator, interpreted with the same words
// and checks as a part program (conditions, soft limits, wear pre-compensation, work frames),
// starting where the electrode is. It runs in the runtime's MDI slot; the loaded program is
// untouched.
//
// Each line starts afresh: G54, G90, no G92, no condition armed, no feed (give F in the line), the
// motion mode unset. The line need not end with M02/M30 (an end block is appended).
//
// Non-RT; a pure function (thread-safe to call concurrently).

#include <string_view>

#include "edm/hmi/gcode.hpp"
#include "edm/hmi/work_offsets.hpp"
#include "edm/machining/machine_tables.hpp"

namespace edm::hmi {

inline constexpr std::string_view kMdiName = "MDI";  // the file name in messages: MDI:1:col

/// `line` is one line (no line break); `position_mm` the machine's position (machine
/// coordinates, io.x_mm/io.y_mm/io.z_mm). Errors are "MDI:1:col: message"; an empty line (no
/// words) is an error too.
GcodeResult interpret_mdi(std::string_view line, const machining::MachineTables& tables,
                          const WorkOffsets& offsets, const machining::Vec3& position_mm);

}  // namespace edm::hmi
