#pragma once
// FuzzyServoLUT: the servo-feed fuzzy controller of seed 003 (Liu 2011, §2.2 (2)), made real-time
// the way the paper does it: the fuzzy surface is precomputed at load time into an integer table
// addressed by the two counts, and each cycle is one memory read.
//
//   configure():  v(o, s)   = quant_v_full · clamp(centroid(o, s), −1, +1)      [paper units, ±5]
//                 y(o, s)   = round(quant_num · v(o, s) / quant_den)           (paper: 30000, 366)
//                 T[o·64 + s] = y(o, s)                     o, s = 0 … 32; other words 0
//   update():     v_mm_s    = v_max_mm_s · T[open_count·64 + short_count] · lsb,
//                 lsb       = quant_den / (quant_num · quant_v_full)       (normalised per code)
//
// The table is the paper's: the M-file line `y(i) = round(30000*velocity(m_open,m_short)/366)`
// gives integers in [−410, +410] for velocities in [−5, +5], stored as int16. The open count is
// the high address and the short count the low address; a count 0 … 32 needs 6 bits, so the
// address is open·64 + short (12 bits, 4096 words). 4096 words × 10 bits (±410 needs a 10-bit
// two's-complement word) is 40 960 bits, the paper's reported memory use; that the paper's LUT
// is laid out so is our inference, the paper does not say it. Reading a code back gives the
// velocity to within half a code, lsb/2 = 0.00122 of full scale.
//
// centroid() is a Mamdani inference (fuzzy_mamdani.hpp: min for AND, min implication, max
// aggregation, centroid on a sampled output universe) over the input variables
//   open   = open count   [pulses of the last 32]      (terms: open_terms)
//   short  = short count  [pulses of the last 32]      (terms: short_terms)
//   normal = 32 − open − short, floored at 0           (terms: normal_terms, optional)
// and the output variable `v` in normalised units (terms: velocity_terms; ±1 = ±v_max_mm_s,
// the paper's ±5 = ±quant_v_full).
//
// Sign (the paper's): v > 0 advances the electrode into the work (all-open → +v_max), v < 0
// retracts (all-short → −v_max), all-normal → 0 (hold). On this project's Z axis (+z away from the
// work) wire io.vz_cmd through a Gain with k = −1.
//
// Defaults: three Ruspini-partition terms per input, Z=tri(-14,0,14) M=tri(0,14,32)
// L=tri(14,32,50) (the paper's example: an open count of 23 is 50 % "open", 32 is 100 %), five
// symmetric output terms NB…PB at −1, −0.5, 0, +0.5, +1 and the 3 × 3 rule table
// v = (index(open) − index(short))/2. They give the three corners (codes +410, −410, 0) and a
// surface that is non-decreasing in the open count and non-increasing in the short count
// (tests/controllers).
//
// Only cells with open + short ≤ 32 are reachable from a DischargeStateCounter; the others with
// counts ≤ 32 are filled too (normal floored at 0) so every in-range read is defined. configure()
// refuses terms or rules that do not parse (the error names the parameter and "line L, column
// C"), a rule base under which no rule fires for some reachable cell (unreachable cells where
// nothing fires hold 0), and a coding whose full-scale code does not fit an int16.
//
// Inputs outside 0…32 are a broken signal: v_mm_s is held and update() returns kFault.
// The term, rule and coding parameters are load-time only (they fill the table); v_max_mm_s can
// be written at run time (the table is normalised).
// RT-safe: update(). Not thread-safe: the owning task calls every member except the pins.

#include <array>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "edm/blocks/fuzzy_mamdani.hpp"
#include "edm/blocks/param_ranges.hpp"
#include "edm/runtime/block.hpp"

namespace edm::blocks {

struct FuzzyServoLUTParams {
  static constexpr const char* kDefaultInputTerms =
      "Z=tri(-14,0,14) M=tri(0,14,32) L=tri(14,32,50)";
  static constexpr const char* kDefaultVelocityTerms =
      "NB=tri(-1.5,-1,-0.5) NS=tri(-1,-0.5,0) ZE=tri(-0.5,0,0.5) PS=tri(0,0.5,1) "
      "PB=tri(0.5,1,1.5)";
  static constexpr const char* kDefaultRules =
      "if open is Z and short is Z then v is ZE; "
      "if open is Z and short is M then v is NS; "
      "if open is Z and short is L then v is NB; "
      "if open is M and short is Z then v is PS; "
      "if open is M and short is M then v is ZE; "
      "if open is M and short is L then v is NS; "
      "if open is L and short is Z then v is PB; "
      "if open is L and short is M then v is PS; "
      "if open is L and short is L then v is ZE";

  std::string open_terms{kDefaultInputTerms};
  std::string short_terms{kDefaultInputTerms};
  std::string normal_terms{};  // optional; rules may then use `normal is ...`
  std::string velocity_terms{kDefaultVelocityTerms};
  std::string rules{kDefaultRules};
  std::int64_t samples{301};      // points of the sampled output universe, 3..100000
  std::int64_t quant_num{30000};  // the paper's coding y = round(quant_num · v / quant_den)
  std::int64_t quant_den{366};
  double quant_v_full{5.0};  // paper velocity at a normalised output of 1 (Fig. 4: ±5)
  double v_max_mm_s{5.0};    // [mm/s] > 0: |v| at a normalised output of 1

  void visit(rt::ParamVisitor& v) {
    v.param("open_terms", open_terms,
            {"pulses", "terms of the open count, e.g. 'Z=tri(-14,0,14) ...'"});
    v.param("short_terms", short_terms, {"pulses", "terms of the short count"});
    v.param("normal_terms", normal_terms,
            {"pulses", "terms of the normal count 32 - open - short (optional)"});
    v.param("velocity_terms", velocity_terms, {"1", "output terms in units of v_max_mm_s"});
    v.param("rules", rules, {"", "'if open is L and short is Z then v is PB; ...'"});
    v.param("samples", samples,
            rt::load_time({"", "points of the sampled output universe", rt::closed(3, 100000)}));
    v.param("quant_num", quant_num,
            rt::load_time({"", "table code y = round(quant_num * v / quant_den), v in paper units",
                           rt::closed(1, 1e9)}));
    v.param(
        "quant_den", quant_den,
        rt::load_time({"", "denominator of the table coding (paper: 366)", rt::closed(1, 1e9)}));
    v.param("quant_v_full", quant_v_full,
            rt::load_time(
                {"", "paper velocity at a normalised output of +-1 (paper: 5)", rt::kPositive}));
    v.param("v_max_mm_s", v_max_mm_s,
            {"mm/s", "speed at a normalised output of +-1", ranges::kSpeedMmS});
  }
};

class FuzzyServoLUT final : public rt::BlockWithParams<FuzzyServoLUTParams> {
 public:
  static constexpr int kCounts = 33;                   // counts 0…32
  static constexpr int kAddrBits = 6;                  // bits per count in the address
  static constexpr int kWords = 1 << (2 * kAddrBits);  // 4096
  /// The table address of (open, short): open is the high address, short the low one.
  static constexpr int address(int open, int shorts) noexcept {
    return (open << kAddrBits) | shorts;
  }
  /// Non-RT. Parses terms and rules, builds the engine and fills the table.
  std::vector<rt::ParamError> configure(const rt::BlockSetup& setup) override;
  /// Non-RT. v_mm_s = the (0, 0) cell.
  void activate() noexcept override;
  /// RT-safe. One table read. kOk, or kFault (output held) for counts outside 0…32.
  rt::BlockStatus update(const rt::CycleContext& ctx) noexcept override;

  /// The stored integer code of (open, shorts), counts 0…63. Owning thread only (tests).
  [[nodiscard]] std::int16_t code(int open, int shorts) const noexcept {
    return table_[static_cast<std::size_t>(address(open, shorts))];
  }
  /// The lookup update() makes: the code read back in normalised units (±1 = ±v_max_mm_s),
  /// code · lsb(). Counts 0…63. RT-safe; owning thread only.
  [[nodiscard]] double table(int open, int shorts) const noexcept {
    return static_cast<double>(code(open, shorts)) * lsb_;
  }
  /// Normalised output per code, quant_den / (quant_num · quant_v_full).
  [[nodiscard]] double lsb() const noexcept { return lsb_; }
  /// The engine built by configure() (null before). Inputs are {open, short, normal}.
  [[nodiscard]] const fuzzy::MamdaniEngine* engine() const noexcept { return engine_.get(); }

 private:
  rt::Input<std::int64_t> open_count_{pins_, "open_count", "pulses"};
  rt::Input<std::int64_t> short_count_{pins_, "short_count", "pulses"};
  rt::Output<double> v_mm_s_{pins_, "v_mm_s", "mm/s"};
  std::array<std::int16_t, static_cast<std::size_t>(kWords)> table_{};
  double lsb_{0.0};
  std::unique_ptr<fuzzy::MamdaniEngine> engine_;
};

}  // namespace edm::blocks
