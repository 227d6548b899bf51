#pragma once
// The motion block: one step of a part program after interpretation, the unit the HMI's G-code
// interpreter produces, the bridge carries (as JSON) and the runtime's job sequencer executes.
// Plain data, trivially copyable, so the real-time side can hold and copy it without allocating.
//
// Coordinates are absolute machine coordinates in mm (Z positive upward, the electrode drills
// toward −Z); speeds in mm/s; times in s. `line`/`col` name the G-code word the block came from,
// so an error found at commit (soft limit, unknown condition) can be reported as PART.nc:line:col.

#include <cstdint>
#include <string_view>
#include <type_traits>

namespace edm::machining {

struct Vec3 {
  double x{0.0};
  double y{0.0};
  double z{0.0};
  friend bool operator==(const Vec3&, const Vec3&) = default;
};

enum class MotionKind : std::uint8_t {
  kRapid = 0,        // G00 to `target`; the generator is off during rapids (never discharges)
  kLinear = 1,       // G01 to `target` at `feed_mm_s`, no gap control (X/Y moves, Z away from work)
  kArcCw = 2,        // G02 in the XY plane: centre `centre`, end `target`, `turns` extra turns
  kArcCcw = 3,       // G03, idem
  kDrill = 4,        // G01 Z toward the work while armed: gap-controlled feed to `target.z`
                     // (nominal hole bottom) with `feed_mm_s` as the speed cap; `z_travel_mm` is
                     // the Z travel after wear pre-compensation (eq. 9-11: lz' = lz + δ)
  kOrbitFinish = 5,  // orbit-finishing cycle about the current XY: radius offset grows by eq.
                     // (20)(21) up to `final_radius_mm`, then back to the centre
  kDwell = 6,        // G04: wait `dwell_s`
  kCondition = 7,  // E<n>: select condition `condition` (≥ 1, arms the generator) or E0 (disarm)
  kRotation = 8,   // M03 (`on` = true) / M05 (false): electrode rotation
  kFlushing = 9,   // M08 (`on` = true) / M09 (false)
  kEnd = 10,       // M02 / M30: end of program
  kProgramStop = 11,  // M00 (`on` = false): the job holds with the generator off until the
                      // operator resumes; M01 (`on` = true), the optional stop, is skipped (there
                      // is no optional-stop switch yet)
};

inline constexpr int kMotionKindCount = 12;

/// Stable lower-case names used by the protocol and in messages ("rapid", "drill", …).
std::string_view to_string(MotionKind k) noexcept;
/// Inverse of to_string(); false when the name is unknown.
bool motion_kind_from_string(std::string_view s, MotionKind& out) noexcept;

struct MotionBlock {
  MotionKind kind{MotionKind::kEnd};
  std::int32_t line{0};           // 1-based source line of the G-code block (0 = unknown)
  std::int32_t col{0};            // 1-based column of the word that made the block (0 = unknown)
  Vec3 target{};                  // end point (rapid, linear, arc, drill)
  Vec3 centre{};                  // arc centre (absolute); orbit: hole centre (= current XY)
  std::int32_t turns{0};          // arcs: extra full turns (G02/G03 P); 0 = the plain arc
  double feed_mm_s{0.0};          // linear / arc / drill speed cap; 0 = machine default
  std::int32_t condition{0};      // kCondition: E number (0 = disarm); other kinds: active E
  double z_travel_mm{0.0};        // kDrill: Z travel to send after wear pre-compensation (> 0)
  double depth_mm{0.0};           // kDrill: programmed depth below the work's Z0 (the active work
                                  // offset's surface); 0 = a machine-coordinate program whose Z0 is
                                  // machine Z 0 (depth = −target.z)
  double depth_done_mm{0.0};      // kDrill: depth the hole already has when the block starts (run
                                  // from a block after an interruption); 0 = a new hole
  double resume_touch_z_mm{0.0};  // kDrill with depth_done_mm > 0: the machine Z where the
                                  // interrupted drill first touched (its depth origin) ...
  double resume_wear_mm{0.0};     // ... and the wear it had compensated since: the depth goes on
                                  // counting from them (0, 0: from the resumed drill's first
                                  // sparks, plus depth_done_mm)
  double final_radius_mm{0.0};    // kOrbitFinish: final hole radius (mm, absolute, > 0)
  double dwell_s{0.0};            // kDwell
  bool on{false};                 // kRotation / kFlushing; kProgramStop: M01
  bool cut{false};                // kLinear / kArcCw / kArcCcw on a wire machine while armed: a
                                  // cut, its path speed set by the gap servo (feed_mm_s caps it)
  double electrode_ref_mm{0.0};   // the electrode length the block's Z assumes (its work frame's
                                  // Z was set with it): the job moves Z by the length lost since
                                  // (rt::Electrode); 0 = none (machine coordinates, or unknown)
  friend bool operator==(const MotionBlock&, const MotionBlock&) = default;
};

static_assert(std::is_trivially_copyable_v<MotionBlock>);

}  // namespace edm::machining
