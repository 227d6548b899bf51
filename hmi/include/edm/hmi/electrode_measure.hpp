#pragma once
// Measuring the electrode in the spindle (docs/hmi.md "Electrodes"), as `edmhmi electrode
// measure` and the page's Electrode panel do it:
//   reference "setter": first up to the approach height over the tool setter (never down), then
//     across, as an MDI program in machine coordinates (job_runner.hpp), then electrode.measure;
//   reference "work": electrode.measure where the electrode is (the frame's Z is the surface).
// Then electrode.get is polled until the measurement's seq reports its result.
//
// Non-RT. Blocking; not thread-safe (one Client per call: run_job() sets its event handlers);
// `interrupt` is only read.

#include <atomic>
#include <chrono>
#include <functional>
#include <string>

#include "edm/bridge/client.hpp"

namespace edm::hmi {

/// The tip approaches the tool setter this high if its length is as the table says: the touch
/// searches 20 mm, so a length wrong by up to ±10 mm is still found.
inline constexpr double kSetterApproachMm = 10.0;

struct MeasureRequest {
  std::string reference{"setter"};  // "setter" | "work"
  std::string frame;                // "work": the frame whose Z is the surface ("": the active)
  std::chrono::milliseconds poll{50};
  std::chrono::seconds limit{120};  // no result within this (wall time): failed
};

struct MeasureOutcome {
  enum class Kind { kMeasured, kFailed, kInterrupted } kind{Kind::kFailed};
  std::string error;       // why not (kFailed)
  double length_mm{0.0};   // the length measured
  double was_mm{0.0};      // the estimate before
  bridge::Json electrode;  // electrode.get after the measurement
  [[nodiscard]] bool ok() const { return kind == Kind::kMeasured; }
};

/// `note` (may be empty) is told each step ("to the tool setter X… Y… at Z…").
MeasureOutcome measure_electrode(bridge::Client& client, const MeasureRequest& request,
                                 const std::atomic<bool>& interrupt,
                                 const std::function<void(const std::string&)>& note = {});

}  // namespace edm::hmi
