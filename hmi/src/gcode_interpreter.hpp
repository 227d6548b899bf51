#pragma once
// Private to the interpreter: its state and the steps of one block. gcode_interpreter.cpp holds
// the line loop, the word checks and the modal state (F, E, M, G90/G91, work frames and G92);
// gcode_motion.cpp turns a block's axis words into motion blocks (rapid, feed, drilling with
// eq. 9-11, arcs, the G160 orbit). Non-RT; one instance per interpret_gcode() call.

#include <array>
#include <cstdint>
#include <map>
#include <string>
#include <string_view>
#include <vector>

#include "edm/hmi/gcode.hpp"
#include "gcode_block.hpp"
#include "gcode_comp.hpp"

namespace edm::hmi::detail {

enum class Motion : std::uint8_t { kNone, kRapid, kLinear, kArcCw, kArcCcw };

/// "1.500" (mm in messages).
std::string mm(double v);

class Interpreter {
 public:
  Interpreter(std::string_view text, std::string_view file, const machining::MachineTables& tables,
              const GcodeOptions& options);
  GcodeResult run();

 private:
  // gcode_interpreter.cpp
  void error(int line, int col, std::string message);
  void error(const Block& b, const Word* at, std::string message);
  void process_line(std::string_view line, int line_no);
  /// G20/G21 of this line set the units (before anything else of the block, as RS274/NGC
  /// orders it); in inches, the length words (X Y Z I J R) and F become mm and mm/min.
  void apply_units(std::vector<Word>& words);
  void execute(const Block& b);
  void check_blocks();
  bool need_feed(const Block& b, const Word* at, const char* what);
  bool check_orbit_words(const Block& b, int armed_after);
  [[nodiscard]] std::string known_conditions() const;
  [[nodiscard]] bool is_code(const Word* w, int c10) const noexcept {
    return w != nullptr && code10(*w) == c10;
  }
  static std::size_t axis_index(char axis) noexcept {
    return static_cast<std::size_t>(axis == 'X' ? 0 : axis == 'Y' ? 1 : 2);
  }

  // gcode_motion.cpp
  [[nodiscard]] machining::MotionBlock make(machining::MotionKind kind, const Block& b,
                                            const Word* at) const;
  void push(const machining::MotionBlock& mb);
  /// The offset of the active frame plus G92: machine = work + offset().
  [[nodiscard]] machining::Vec3 offset() const noexcept;
  void set_g92(const Block& b);
  void do_orbit(const Block& b);
  void do_motion(const Block& b);
  void do_linear(const Block& b, const Word* at, const machining::Vec3& start,
                 const machining::Vec3& target);
  void do_arc(const Block& b, const Word* at, const machining::Vec3& start, machining::Vec3 target);
  void remember_axis_words(const Block& b);
  /// A move of a wire machine: through the wire offset when it is engaged, else pushed.
  void push_move(const machining::MotionBlock& mb, const machining::Vec3& start);
  void push_now(const machining::MotionBlock& mb);
  /// G40/G41/G42 of block b (phase 2); false with an error when the offset cannot be set.
  bool set_wire_offset(const Block& b);

  // gcode_subprograms.cpp: O<n> … M99 definitions (found before the program runs) and M98 calls.
  struct SubprogramDef {
    int o_line{0};
    int first{0}, last{0};  // body lines (1-based); the M99 line is last + 1
  };
  /// Splits the text into lines and finds the definitions; their lines are skipped in the
  /// program's own flow.
  void scan_subprograms();
  /// M98 P<n> [L<k>]: runs the body k times.
  void call_subprogram(const Block& b);
  [[nodiscard]] std::string_view line_text(int line_no) const;

  std::string_view text_;
  const machining::MachineTables& tables_;
  const GcodeOptions& opt_;
  GcodeResult result_;
  std::vector<std::array<int, 3>> axis_cols_;  // by line: columns of X, Y, Z words

  machining::Vec3 pos_{};  // the current point, machine coordinates
  Motion mode_{Motion::kNone};
  bool incremental_{false};
  double feed_mm_min_{0.0};
  int armed_{0};
  int frame_{0};           // 0 = G54 .. 5 = G59
  machining::Vec3 g92_{};  // the program's G92 offset (mm), added to the frame's
  bool g92_active_{false};
  bool inch_{false};  // G20: lengths and feeds in the program are inches (inch/min)

  bool opened_{false};
  bool closed_{false};
  bool seen_block_{false};
  bool ended_{false};
  int end_line_{0};
  int last_line_{0};  // the last line with words (an implicit end goes there)
  std::string end_word_;
  bool reported_after_end_{false};
  bool reported_no_feed_{false};
  bool stop_{false};
  bool too_many_{false};

  WireOffset comp_;
  std::vector<std::string_view> lines_;  // by line - 1
  std::vector<char> in_definition_;      // by line - 1: part of an O … M99 definition
  std::map<long, SubprogramDef> subprograms_;
  int call_depth_{0};
  std::size_t lines_called_{0};  // lines run through calls (bounded)
};

}  // namespace edm::hmi::detail
