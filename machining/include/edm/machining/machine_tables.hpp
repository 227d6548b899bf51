#pragma once
// What a part program is checked against: the machine's machining-condition table (E numbers)
// and its soft limits. Plain data shared by the runtime (which enforces them) and the HMI (which
// checks a program offline), so both sides use one definition. Non-RT; thread-compatible.

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "edm/machining/diagnostics.hpp"

namespace edm::machining {

enum class Polarity : std::uint8_t { kNegative, kPositive };

/// A machining condition, selected by its E number.
struct Condition {
  int e{0};  // >= 1, unique in a table
  std::string name;
  Polarity polarity{Polarity::kNegative};
  double open_voltage_v{120.0};
  double peak_current_a{10.0};
  double on_time_us{20.0};
  double off_time_us{40.0};
  double tdr_us{8.0};        // reference ignition delay for the gap controller
  double servo_ref_v{40.0};  // reference mean gap voltage for voltage-based servos
  double wear_ratio{0.0};    // θ: electrode volume / workpiece volume removed, 0..10
  // A_hole / A_e: the hole's cross-section over the electrode's (seed 004 eq. 8; a drilling
  // condition is set for one electrode), > 0 and <= 100; 1 = the paper's single A.
  double area_ratio{1.0};
  // Wire: the wire offset of this pass (wire radius + side gap + what later passes take off),
  // applied by G41/G42 without a D word; >= 0.
  double offset_mm{0.0};
};

/// The numeric fields of a condition an operator may be allowed to edit (`machine.condition_edit`),
/// by their config names: open_voltage_v peak_current_a on_time_us off_time_us tdr_us servo_ref_v
/// wear_ratio area_ratio offset_mm. nullptr for another name.
[[nodiscard]] double* condition_field(Condition& c, std::string_view field) noexcept;
/// Why `value` is not a valid `field` of a condition (the config's own ranges: > 0, wear_ratio
/// 0..10, area_ratio (0, 100]), or nullopt when it is.
[[nodiscard]] std::optional<std::string> condition_value_error(std::string_view field,
                                                               double value);

/// Soft limits and dynamics of one axis (machine coordinates, mm).
struct AxisLimits {
  char name{'X'};  // 'X', 'Y' or 'Z'
  double min_mm{0.0};
  double max_mm{0.0};
  double v_max_mm_s{10.0};
  double a_max_mm_s2{1000.0};
};

/// What the machine machines (`machine.kind`): the G-code interpreter makes a wire machine's
/// armed G01/G02/G03 cuts (gap-controlled feed along the path) and allows G41/G42 there.
enum class MachineKind : std::uint8_t { kDrill, kWire, kSink };
/// "drill", "wire", "sink".
std::string_view to_string(MachineKind k) noexcept;
/// Inverse of to_string(); false for another name.
bool machine_kind_from_string(std::string_view s, MachineKind& out) noexcept;

struct MachineTables {
  MachineKind kind{MachineKind::kDrill};
  std::vector<Condition> conditions;
  std::vector<AxisLimits> axes;  // axes not listed are unlimited

  /// The condition with E number e, or nullptr.
  [[nodiscard]] const Condition* condition(int e) const noexcept;
  /// The limits of axis 'X' / 'Y' / 'Z', or nullptr.
  [[nodiscard]] const AxisLimits* axis(char name) const noexcept;
};

/// An axis as read from a config, with where its entry was written.
struct LocatedAxis : AxisLimits {
  SourceLoc loc;
};

/// A condition as read from a config, with where its entry was written.
struct LocatedCondition : Condition {
  SourceLoc loc;
};

/// The tables of what a config's `machine.axes` and `conditions` sections held.
MachineTables make_tables(const std::vector<LocatedAxis>& axes,
                          const std::vector<LocatedCondition>& conditions,
                          MachineKind kind = MachineKind::kDrill);

}  // namespace edm::machining
