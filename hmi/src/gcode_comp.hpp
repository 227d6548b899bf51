#pragma once
// Private to the interpreter: wire-offset compensation G41/G42/G40 on lines and arcs in XY
// (docs/gcode.md "Wire offset"), with LinuxCNC's lead-in and lead-out rules: the offset is
// switched on on a straight lead-in move (from the uncompensated point to the compensated start
// of the next move) and off on a straight lead-out; an outside corner gets an arc of the offset's
// radius about the programmed corner, an inside corner is cut at the offset paths' intersection.
// The compensated path is emitted one move late (a move's end depends on the next one); the
// blocks programmed between two moves (a condition, a stop) are held and emitted after the
// corner. Non-RT; one instance per interpretation.

#include <optional>
#include <string>
#include <vector>

#include "edm/machining/motion_block.hpp"

namespace edm::hmi::detail {

/// A move of the programmed path: a line, or an arc about `centre`, from `from` to b.target.
struct CompMove {
  machining::MotionBlock b;  // the block as the interpreter made it (kind, target, centre, …)
  machining::Vec3 from;
};

/// Why an offset could not be applied, at the move's word.
struct CompError {
  int line{0};
  int col{0};
  std::string message;
};

class WireOffset {
 public:
  /// G41 (side +1, the wire left of the path) or G42 (−1) with offset `d_mm` > 0: the next move
  /// is the lead-in.
  void start(int side, double d_mm) noexcept;
  /// G40: the next move is the lead-out.
  void stop() noexcept { stopping_ = true; }
  /// On, or a lead-in, lead-out or pending move still to come: moves and blocks go through here.
  [[nodiscard]] bool engaged() const noexcept { return side_ != 0; }
  [[nodiscard]] bool pending() const noexcept { return pending_.has_value(); }

  /// A programmed XY move (line or arc); compensated blocks are appended to `out`.
  std::optional<CompError> move(const CompMove& m, std::vector<machining::MotionBlock>& out);
  /// A block that is not a move while a move is pending: emitted after that move and its corner.
  void hold(const machining::MotionBlock& b) { held_.push_back(b); }
  /// The program ends with the offset on: the error to report (at `line`, `col`), or none.
  [[nodiscard]] std::optional<CompError> at_end(int line, int col) const;

  struct Element;  // an offset line or arc (gcode_comp.cpp)

 private:
  std::optional<CompError> join(const CompMove& a, const CompMove& b,
                                std::vector<machining::MotionBlock>& out);
  void emit(const CompMove& m, machining::Vec3 to, std::vector<machining::MotionBlock>& out) const;

  int side_{0};
  double d_{0.0};
  bool lead_in_{false};
  bool stopping_{false};
  std::optional<CompMove> pending_;  // the last move, its end not yet known
  machining::Vec3 pending_from_{};   // where its compensated version starts
  std::vector<machining::MotionBlock> held_;
};

}  // namespace edm::hmi::detail
