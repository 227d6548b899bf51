#pragma once
// The controller benchmark (issue 7, PLANT-MODEL §5): scenarios, one simulated run, reports.
//
// A run builds a Runtime from a YAML config (config/bench/controllers/ or config/machines/),
// edited per scenario and seed, and steps it on the virtual clock in 1 ms slices, sampling the
// simulator's pins after every slice. Runs are independent (one Runtime each), so run() may be
// called from several threads at once. Not RT code: runs allocate freely.

#include <cstdint>
#include <functional>
#include <limits>
#include <string>
#include <utility>
#include <vector>

namespace edm::bench {

/// A text edit of the config: `from` must occur in it (replaced once), else run() throws.
struct Edit {
  std::string from;
  std::string to;
};

/// What to run and what to measure.
struct RunSpec {
  std::string config;           // path relative to the source root
  std::vector<Edit> edits;      // applied in order
  std::string io_extra;         // extra simulator params, appended after the seed
  std::uint64_t seed{1};        // replaces the config's `seed: 1` (common random numbers)
  double limit_s{60.0};         // simulated time limit [s]
  double target_depth_mm{0.0};  // > 0: time to depth = first io.depth_mm ≥ target − 0.05 mm
  bool stop_at_depth{false};    // end the run when the depth is reached
  std::string done_var;         // non-empty: end the run when this variable equals done_value
  double done_value{4.0};       // DeepHoleDrill's DONE
  double jump_period_s{0.0};    // > 0: forced jump (io.vz_cmd) every period (B5)
  double td_ref_us{0.0};        // > 0: RMS(Td − td_ref) over cycles with ignited pulses
  double rab_ref{0.0};          // > 0: Rab error against this set point (1 s means)
  double transient_s{0.0};      // Rab error only after this time [s] (whole seconds from it on)
  std::string jump_cycle_var;   // non-empty (B5 ILC): forced 1 for the first ms of each jump
  std::string jump_hold_var;    // non-empty: forced to jump_hold_value while the jump is forced
  double jump_hold_value{0.0};
  double jump_hold_extra_ms{0.0};  // the hold lasts this much past the forced jump (approach)
  std::string jump_track_var;      // non-empty: forced to io.z_mm at the jump's start while forced
  std::string loop_y_var;          // non-empty (B5 STR): a loop's output y, scored against ...
  std::string loop_ref_var;        // ... its reference, every ms outside the jumps and settling
  double wall_growth_mm{0.0};      // > 0 (B4): wall radius target = initial bin radius + this
  double flush_drop_mm{0.0};       // > 0 (B3): disturbance figures from this true depth on
  double window_end_state{0.0};    // > 0 (B3): ... until done_var reaches this (RETRACT)
};

/// Seed 000's acceptance band: Rab within ±0.1 of its set point after the transient.
inline constexpr double kRabBand = 0.1;

/// Outcomes of one run (PLANT-MODEL §5, as far as the simulator exposes them).
struct Outcome {
  double time_s{0.0};           // simulated time run [s]
  double reached{0.0};          // 1: target depth reached (or done_var reached)
  double time_to_depth_s{0.0};  // [s]; the time limit when not reached
  double depth_mm{0.0};         // io.depth_mm at the end
  double depth_error_um{0.0};   // depth − target [µm]
  double speed_mm_min{0.0};     // depth / time (to depth, break or end) [mm/min]
  double mrr_mm3_min{0.0};      // sink: depth × 100 mm² / time
  double short_pct{0.0};        // shorts / all pulses [%]
  double arc_pct{0.0};          // transient + stable arcs / all pulses [%]
  double open_pct{0.0};         // open pulses / all pulses [%]
  double retracts{0.0};         // rising edges of io.vz_cmd above +0.2 mm/s (jumps excluded)
  double electrode_used_mm{0.0};
  double td_rms_us{0.0};      // RMS(Td − Td_ref) per cycle
  double wire_broken{0.0};    // 1: the wire broke
  double break_time_s{0.0};   // [s]; the time limit when it did not break
  double rab_mean{0.0};       // mean io.rab after the transient
  double rab_err_rms{0.0};    // RMS of (1 s mean Rab − ref) after the transient
  double rab_above_max{0.0};  // max (1 s mean Rab − ref) after the transient (rupture side)
  double rab_below_max{0.0};  // max (ref − 1 s mean Rab) after the transient (speed lost)
  // The time from which every 1 s mean of Rab (seconds with sparks) stays within ±kRabBand of
  // the set point to the end of the run [s]: how long the transients lasted. The time limit
  // when the last second is out of the band or the wire broke.
  double rab_in_band_s{0.0};
  double overload_s{0.0};  // time with Ī > 0.9 I_BK [s] (simulator truth)
  // Five-state time ratios [%] (sink): normal (spark), transient arc, stable arc, short, open.
  double ratio_normal_pct{0.0};
  double ratio_tarc_pct{0.0};
  double ratio_sarc_pct{0.0};
  double ratio_short_pct{0.0};
  double ratio_open_pct{0.0};
  double jitter_um{0.0};        // z-jitter RMS per jump cycle [µm], mean over cycles
  double jitter_first_um{0.0};  // mean of the first 3 cycles
  double jitter_last_um{0.0};   // mean of the last 3 cycles
  // RunSpec::loop_y_var against loop_ref_var (NaN: the run has no such loop, printed "—").
  double loop_y_mean{std::numeric_limits<double>::quiet_NaN()};
  double loop_ref_mean{std::numeric_limits<double>::quiet_NaN()};
  double loop_err_rms{std::numeric_limits<double>::quiet_NaN()};
  // B4: the 64 wall bins of the simulator at the end.
  double wall_err_um{0.0};     // mean bin radius − target [µm]
  double circularity_um{0.0};  // max − min bin radius [µm]
  double wall_worst_um{0.0};   // the bin farthest from the target, signed [µm]
  // B3: from the first cycle at the drop depth to the target depth, in 100 ms windows.
  double recovery_s{0.0};      // drop → first 1 s of windows with ≤ 1 % shorts and progress
  double peak_short_pct{0.0};  // max short % of a window
  double peak_arc_pct{0.0};    // max arc % (transient + stable) of a window
  double stalls{0.0};          // whole seconds after the drop with < 5 µm of true depth gained
  std::vector<double> jitter_per_cycle_um;
  std::vector<double> rab_per_s;  // wire: 1 s means of io.rab from the start to the end or break

  /// Every scalar, named (CSV columns; B7 compares them bit for bit).
  [[nodiscard]] std::vector<std::pair<const char*, double>> fields() const;
};

/// Runs one simulated job. Throws on a config error or a missing variable.
Outcome run(const std::string& source_root, const RunSpec& spec);

/// One table column: a figure of the Outcome.
struct Column {
  std::string header;  // with its unit
  std::function<double(const Outcome&)> get;
  int precision{2};
};

/// One row of a scenario: a controller (or a variant of one) and its run.
struct Variant {
  std::string name;
  RunSpec spec;
};

struct Scenario {
  std::string id;     // B1, B2, B5, B6a …; file names out/bench/controllers/<id>.*
  std::string title;  // one line
  std::vector<Variant> variants;
  std::vector<Column> columns;
  std::size_t plot_column{0};  // the column of the bar plot
  bool plot_jitter{false};     // also plot jitter per cycle against the cycle number
  bool plot_rab{false};        // also plot the first seed's Rab (1 s means) against time
};

/// The scenarios; `quick` shortens runs (the seed count is the caller's).
std::vector<Scenario> make_scenarios(bool quick);

/// Mean and sample SD.
std::pair<double, double> mean_sd(const std::vector<double>& v);

}  // namespace edm::bench

namespace edm::bench {

/// The runs of one scenario: outcomes[variant][seed index].
struct ScenarioResult {
  const Scenario* scenario{nullptr};
  std::vector<std::vector<Outcome>> outcomes;
};

/// Markdown: a heading line, then one row per variant, each column as mean ± SD over seeds.
std::string markdown_table(const ScenarioResult& r);
/// `<dir>/<id>.csv`: one line per (variant, seed) with every Outcome field.
void write_csv(const std::string& dir, const ScenarioResult& r,
               const std::vector<std::uint64_t>& seeds);
/// `<dir>/<id>.gp` (+ `.dat`); runs gnuplot to `<id>.png` when `gnuplot` is found. Returns a
/// note for the log (the PNG path, or why there is none).
std::string write_plot(const std::string& dir, const ScenarioResult& r);

}  // namespace edm::bench
