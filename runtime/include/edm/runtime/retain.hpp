#pragma once
// Retained variables (IEC 61131-3 VAR RETAIN): named values `program.block.pin` that survive a
// restart and `kill -9`. A text file written atomically (temp file, fsync, rename, fsync dir) by a
// non-RT thread, loaded once at start.
//
// File format (version 1), one value per line, names sorted, every line ends with '\n':
//   edmplc-retain 1
//   drill.counter.holes LINT 17
//   drill.electrode.length_left LREAL 123.456
//   drill.seq.done BOOL 1
//   end 5ad6925c
// LREAL values are the shortest decimal that reads back to the same double (exact round trip,
// also -0, inf, nan). The `end` line holds the CRC-32 (IEEE 802.3, lowercase hex, 8 digits) of
// every byte before it, so a truncated or garbled file is detected rather than half-applied.
//
// RT-safety: nothing here is RT-safe (everything allocates and does file I/O). The RT side only
// owns the atomics that RetainStore::Variable::read() loads.
// Thread-safety: the free functions are reentrant (concurrent writers of one path each use their
// own unpredictable temp name; the last rename wins). RetainStore: see the class comment.
//
// Only a running runtime writes the retain file: `edmplc --check` and `--list-vars` build the
// runtime with BuildOptions::load_retain = false, which constructs no RetainStore at all.

#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <functional>
#include <map>
#include <mutex>
#include <optional>
#include <string>
#include <string_view>
#include <thread>
#include <vector>

#include "edm/runtime/time.hpp"

namespace edm::rt {

/// IEC names in the file: BOOL, LINT (64-bit int), LREAL (64-bit float).
enum class RetainType : std::uint8_t { kBool, kInt, kReal };

/// The IEC name written in the file: BOOL, LINT, LREAL.
[[nodiscard]] std::string_view to_string(RetainType t) noexcept;

/// A retained value; only the field matching `type` is meaningful.
struct RetainValue {
  RetainType type{RetainType::kBool};
  bool b{false};
  std::int64_t i{0};
  double r{0.0};

  static constexpr RetainValue make_bool(bool v) noexcept { return {RetainType::kBool, v, 0, 0.0}; }
  static constexpr RetainValue make_int(std::int64_t v) noexcept {
    return {RetainType::kInt, false, v, 0.0};
  }
  static constexpr RetainValue make_real(double v) noexcept {
    return {RetainType::kReal, false, 0, v};
  }

  /// Same type and same active field; reals compare bit for bit, so -0.0 != 0.0 and a NaN equals
  /// itself (a changed sign of zero is persisted, and a NaN does not force a rewrite every poll).
  friend bool operator==(const RetainValue& a, const RetainValue& b) noexcept;
};

/// Name → value, sorted so the file is byte-for-byte deterministic.
using RetainMap = std::map<std::string, RetainValue>;

/// Largest retain file read or parsed (a real set is a few KB); anything bigger is refused
/// unread, so a wrong path (a disk image, /dev/zero) cannot exhaust memory.
inline constexpr std::size_t kMaxRetainFileBytes = std::size_t{4} << 20;

/// How a load ended. kMissing is a first start; kCorrupt and kUnreadable mean the file holds
/// something that must not be silently replaced by defaults (the runtime sets it aside).
enum class RetainLoadStatus : std::uint8_t {
  kLoaded,      // every value read, checksum good
  kMissing,     // no such file (first start)
  kCorrupt,     // read, but truncated, garbled, too large or of another version
  kUnreadable,  // exists but cannot be opened/read (permissions, I/O error)
  kNotRegular,  // a directory, FIFO, device, socket or symbolic link: never read nor replaced
};

struct RetainLoadResult {
  RetainMap values;
  std::string warning;  // empty when the file was read completely; else says path and problem
  RetainLoadStatus status{RetainLoadStatus::kLoaded};
};

/// A name is valid when non-empty and made only of printable ASCII other than space.
[[nodiscard]] bool is_valid_retain_name(std::string_view name) noexcept;

/// CRC-32 (IEEE 802.3, reflected 0xEDB88320, init and final xor 0xFFFFFFFF); "123456789" →
/// 0xCBF43926.
[[nodiscard]] std::uint32_t crc32_ieee(std::string_view data) noexcept;

/// The exact bytes of the file for `values`. Throws std::invalid_argument on an invalid name.
[[nodiscard]] std::string format_retain_file(const RetainMap& values);

/// Parses file bytes: the pure retain reader (no I/O; the fuzz target calls it with any bytes).
/// Never throws, never reads beyond `text`; text over kMaxRetainFileBytes is refused unparsed.
/// On any problem returns an empty map, status kCorrupt and a warning such as
/// "checksum mismatch (...)" or "line 3: bad LINT value 'x'" (no path; see load_retain_file).
[[nodiscard]] RetainLoadResult parse_retain_file(std::string_view text) noexcept;

/// Loads `path`. Never throws, never blocks on a FIFO, never follows a symbolic link and reads at
/// most kMaxRetainFileBytes + 1 bytes. A missing, unreadable, irregular or corrupt file gives an
/// empty map, its status and a warning "retain file '<path>': <problem>" — the caller decides
/// (the runtime: see docs/runtime.md, "Retained variables"). Nothing is half-applied.
[[nodiscard]] RetainLoadResult load_retain_file(const std::string& path) noexcept;

/// Why `path` must not be used as a retain file, or "" if it may: it is a regular file or does
/// not exist yet. Symbolic links, directories, FIFOs, devices and sockets are refused (lstat, so
/// the link itself is judged). Never throws.
[[nodiscard]] std::string retain_target_problem(const std::string& path) noexcept;

/// Writes `values` to `path` atomically: a temp file `path.tmp.<pid>.<16 random hex>` created in
/// the same directory with O_CREAT|O_EXCL|O_NOFOLLOW (never an existing file or link), mode
/// 0600; write, fsync, rename over `path`, fsync the directory. Refuses (before renaming) when
/// `path` exists and is not a regular file. After a crash at any point `path` holds either the
/// previous or the new complete file. Throws std::system_error (what() names the path and the
/// step) on failure, after removing the temp file; std::invalid_argument on an invalid name.
void write_retain_file_atomic(const std::string& path, const RetainMap& values);
/// The same atomic write for any text (the bridge's job log).
void write_file_atomic(const std::string& path, std::string_view text);

/// Moves a corrupt or unreadable retain file out of the way, to `path.corrupt` (or
/// `path.corrupt.1` … `.corrupt.99` when taken), so the runtime may write a new one without
/// destroying the evidence. Returns the new name. Throws std::system_error when it cannot.
std::string set_aside_retain_file(const std::string& path);

/// Removes `path.tmp.<pid>[.<hex>]` files left by a writer killed mid-write (any pid but ours).
/// Returns how many were removed. Never throws; errors are ignored (a leftover temp file is
/// harmless).
std::size_t remove_stale_retain_temps(const std::string& path) noexcept;

/// Owns the retain file of one runtime and the non-RT thread that keeps it up to date.
/// Writes when a value changed, at most once per `min_interval` (so a counter that changes every
/// cycle costs one fsync per interval, not one per cycle), and on stop().
/// A failed write is logged, counted, reported to the write listener (the runtime raises alarm
/// 183, retain_write_failed) and retried at the next poll while the values differ.
/// Thread-safety: poll(), flush() and sync() are serialised by an internal mutex and may be called
/// from any non-RT thread, also while the background thread runs; start()/stop() from one owner
/// thread; writes()/write_failures() from anywhere. Nothing is RT-safe.
class RetainStore {
 public:
  struct Variable {
    std::string name;  // `program.block.pin`
    RetainType type;
    /// Called on a non-RT thread (the store's or the caller of poll/flush); loads the RT side's
    /// atomics. Must return a value of `type` (a mismatch is logged and the value ignored).
    std::function<RetainValue()> read;
    /// A change of this variable is written at the next poll, without waiting for min_interval
    /// (the runtime's job-running flag: the record must reach the disk before a power loss).
    bool urgent{false};
  };

  /// Throws std::invalid_argument on an invalid or duplicate name, an empty read function or a
  /// negative min_interval (config time, never later).
  RetainStore(std::string path, Duration min_interval, std::vector<Variable> vars);
  /// Calls stop().
  ~RetainStore();
  RetainStore(const RetainStore&) = delete;
  RetainStore& operator=(const RetainStore&) = delete;
  RetainStore(RetainStore&&) = delete;
  RetainStore& operator=(RetainStore&&) = delete;

  /// Reads every variable; writes when a value differs from the last written set (or nothing was
  /// written yet) and at least min_interval passed since the last write attempt — or at once when
  /// an `urgent` variable differs. `now` is on any
  /// monotonic time line (virtual time in tests); a `now` earlier than the last attempt is taken
  /// as a new time line and does not wait. Returns true if it wrote. A failed write is logged and
  /// counted (retried at the next allowed poll), never thrown.
  bool poll(TimePoint now) noexcept;

  /// Writes now, ignoring min_interval, if anything changed since the last write (or nothing was
  /// written yet). Returns true if it wrote. Failures as in poll().
  bool flush() noexcept;

  /// What sync() did: kWritten (it wrote every value), kUnchanged (the file already held them),
  /// kFailed (the write failed or was refused: the file holds older values, or none).
  enum class SyncResult : std::uint8_t { kWritten, kUnchanged, kFailed };
  /// flush() that says whether the file now holds every current value: for an operation that
  /// must not report success for data it did not keep (offset.set).
  SyncResult sync() noexcept;

  /// Called after every write attempt with its outcome (true: written), on the writing thread
  /// and under the store's lock: keep it short (the runtime raises or clears an alarm) and never
  /// call the store from it. Set before start().
  void set_write_listener(std::function<void(bool ok)> listener) {
    write_listener_ = std::move(listener);
  }
  /// True from a failed write attempt until the next successful one. Any thread.
  [[nodiscard]] bool failing() const noexcept { return failing_.load(std::memory_order_acquire); }
  /// Whether `name` is one of the store's variables. Any thread (the list is fixed).
  [[nodiscard]] bool retains(std::string_view name) const noexcept;

  /// Removes stale temp files, forgets the time of the last attempt (poll() calls made before may
  /// have used another time line), then starts a thread calling poll(steady clock) right away and
  /// then every poll_period until stop(). Throws std::logic_error if already running,
  /// std::invalid_argument if poll_period <= 0.
  void start(Duration poll_period);

  /// Stops and joins the thread (if any), then flush(). Idempotent: later calls (also the
  /// destructor's) do nothing until the next start(), so read() is not called after the first
  /// stop() — the owner may tear down what read() looks at.
  void stop() noexcept;

  [[nodiscard]] std::uint64_t writes() const noexcept {
    return writes_.load(std::memory_order_relaxed);
  }
  [[nodiscard]] std::uint64_t write_failures() const noexcept {
    return write_failures_.load(std::memory_order_relaxed);
  }
  [[nodiscard]] const std::string& path() const noexcept { return path_; }

 private:
  void read_all_locked();
  bool write_locked() noexcept;
  void run(Duration poll_period) noexcept;

  const std::string path_;
  const Duration min_interval_;
  const std::vector<Variable> vars_;

  std::mutex mutex_;                        // guards everything below up to the thread members
  std::vector<RetainValue> current_;        // last good read, parallel to vars_
  std::vector<bool> type_mismatch_logged_;  // log a bad read() once per variable
  std::optional<std::vector<RetainValue>> written_;  // what the file holds (as we wrote it)
  std::optional<TimePoint> last_attempt_;            // for min_interval
  std::uint64_t failure_streak_{0};                  // to log a failing disk without spamming

  std::atomic<std::uint64_t> writes_{0};
  std::atomic<std::uint64_t> write_failures_{0};
  std::atomic<bool> failing_{false};
  std::function<void(bool ok)> write_listener_;

  std::mutex thread_mutex_;
  std::condition_variable wake_;
  bool stop_requested_{false};  // guarded by thread_mutex_
  bool stopped_{false};         // owner thread only: stop() already flushed
  std::thread thread_;
};

}  // namespace edm::rt
