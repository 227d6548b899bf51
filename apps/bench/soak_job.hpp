#pragma once
// The job loop's pieces for edm-bench-soak: the config and the program of job k, and the figures
// of an `edmhmi run` report. Pure functions; thread-safe.

#include <optional>
#include <string>

namespace edm::bench::soak {

/// A job reached its depth: the controller's "depth reached" within 0.02 mm of the program (the
/// edmhmi process test's tolerance, tests/hmi) and the simulator's measured hole no more than
/// 0.05 mm short of it (the "reached" oracle of the controllers bench B1: on the real clock the
/// true hole ends 10-25 µm short of the estimate).
inline constexpr double kDepthToleranceMm = 0.02;
inline constexpr double kMeasuredShortMm = 0.05;
/// The soak config's electrode length (config/machines/drill-sim.yaml has the simulator's 300).
inline constexpr double kSoakElectrodeMm = 1200.0;

/// config/machines/drill-sim.yaml with the machine's envelope widened so that one edmplc can
/// drill hole after hole: Z travel down to -1000 mm (not -60) and a 1200 mm electrode (not 300).
/// Everything else — tasks, watchdogs, bridge, conditions — is the shipped file. Empty `error`
/// on success.
std::string soak_config(const std::string& shipped_yaml, std::string& error);

/// demo.nc for the k-th job (0-based): a new hole at X = 5 + 3 (k mod 30) mm, Y = 5 + 3 (k / 30)
/// mm, inside the ±100 mm soft limits and starting where demo.nc drills (a first rapid of 134 mm
/// to −95, −95 tripped the supervisor's following-error alarm 140), 3 mm apart (the simulator
/// starts a new hole when the electrode moves away), and the rapid back into the hole for the wall
/// finish lowered by `worn_mm`, the electrode worn by the previous jobs (the touch-off an operator
/// does; the dialect has no tool-length offset).
std::string job_program(const std::string& demo_nc, int k, double worn_mm, std::string& error);

struct JobFigures {
  std::string outcome;                // "finished", "aborted (...)", or empty: no report
  std::optional<double> reached_mm;   // "depth reached" (the controller's estimate)
  std::optional<double> program_mm;   // "(program N mm"
  std::optional<double> measured_mm;  // "hole depth (measured)"
  std::optional<double> machining_s;  // "machining time m:ss (N s)"
  std::optional<double> electrode_left_mm;
  std::string alarms;  // the "alarms" row
  [[nodiscard]] bool at_depth() const;
};

/// The figures of an `edmhmi run` job report (apps/edmhmi/cmd_run.cpp, hmi/src/job_report.cpp).
JobFigures parse_report(const std::string& report);

}  // namespace edm::bench::soak
