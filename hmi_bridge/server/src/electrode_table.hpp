#pragma once
// The electrode table (issue 33, "Electrodes"): each electrode the machine has used — its id,
// kind and size, material, new length, length now, and the wear ratio measured over its holes —
// and which one is in the spindle. Kept beside the retain file as JSON (`<retain
// file>.electrodes.json`), rewritten whole (temp file, fsync, rename) at each change; without a
// retain file it is kept in memory only. The length the job compensates with is the runtime's
// (rt::Electrode, retained in the retain file, lowered by the wear while a job drills): the
// table takes it at each job's end and each measurement. Server thread only; never RT.

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "edm/bridge/codec.hpp"

namespace edm::bridge {

struct ElectrodeEntry {
  std::string id;        // [A-Za-z0-9._-], 1..32 characters
  std::string kind;      // round, tube, rect
  double size_mm{0.0};   // diameter (round, tube) or width (rect)
  std::string material;  // copper, graphite, CuW, brass, … (printable, ≤ 32 characters)
  double new_length_mm{0.0};
  double length_mm{0.0};  // now (the current one's: the runtime's estimate when last taken)
  std::int64_t holes{0};
  double drilled_mm{0.0};             // Σ depth reached over its holes
  double measured_length_mm{0.0};     // the last measurement (0: never measured)
  double drilled_at_measure_mm{0.0};  // drilled_mm when it was measured
  std::string changed;                // UTC when it was last put in the spindle
  bool unmeasured{false};  // put in the spindle and not measured since (jobs are refused)

  /// Length lost per depth drilled, from its last measurement; nullopt before it drilled and was
  /// measured since.
  [[nodiscard]] std::optional<double> measured_wear_ratio() const noexcept;
  /// The same from the length now (the runtime's estimate between measurements).
  [[nodiscard]] std::optional<double> estimated_wear_ratio() const noexcept;
};

/// Every stored field of `e`, as the file keeps it (electrode.get adds the derived ones).
bridge::Json to_json(const ElectrodeEntry& e);

class ElectrodeTable {
 public:
  static constexpr std::size_t kCap = 200;

  /// `path` empty: in memory only. Loads the file when there is one; a file that cannot be read
  /// is set aside as `<path>.bad` and the table starts empty (load_error() says why).
  explicit ElectrodeTable(std::string path);

  [[nodiscard]] const std::vector<ElectrodeEntry>& entries() const noexcept { return entries_; }
  /// The electrode in the spindle, or nullptr (none named yet).
  [[nodiscard]] const ElectrodeEntry* current() const noexcept;
  [[nodiscard]] const ElectrodeEntry* find(const std::string& id) const noexcept;

  /// Puts `e` in the spindle: a new id is added (false when the table is full), a known one
  /// keeps its history and takes the fields given. The previous one keeps `previous_length_mm`.
  bool change(const ElectrodeEntry& e, double previous_length_mm, const std::string& when);
  /// A job ended: electrode `id` drilled `holes` holes, `drilled_mm` deep in all, and is now
  /// `length_mm` long (the runtime's estimate; taken only when it is still the current one).
  void add_job(const std::string& id, std::int64_t holes, double drilled_mm, double length_mm);
  /// The current one was measured `length_mm` long.
  void measured(double length_mm);
  /// The current one's length now (electrode.set, a measurement).
  void set_length(double length_mm);

  /// Writes the file; false (with the reason logged) when it cannot.
  bool save() const;
  [[nodiscard]] bool retained() const noexcept { return !path_.empty(); }
  [[nodiscard]] const std::string& load_error() const noexcept { return load_error_; }

  /// The check of an id, kind and material: an empty string when valid, else why not.
  static std::string invalid_id(const std::string& id);
  static std::string invalid_kind(const std::string& kind);
  static std::string invalid_material(const std::string& material);

 private:
  void load();
  ElectrodeEntry* mutable_current() noexcept;

  std::string path_;
  std::vector<ElectrodeEntry> entries_;
  std::string current_;
  std::string load_error_;
};

}  // namespace edm::bridge
