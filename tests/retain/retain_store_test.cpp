#include <gtest/gtest.h>
#include <stdlib.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <memory>
#include <stdexcept>
#include <string>
#include <system_error>
#include <vector>

#include "edm/runtime/retain.hpp"
#include "support/temp_dir.hpp"

namespace edm::rt {
namespace {

namespace fs = std::filesystem;
using std::chrono::milliseconds;
using std::chrono::seconds;

using TempDir = edm::test::TempDir;

// Stands in for the RT side: atomics the store's read() functions load.
struct Plant {
  std::atomic<std::int64_t> holes{0};
  std::atomic<double> length_mm{250.0};
  std::atomic<bool> done{false};
  std::atomic<int> reads{0};

  std::vector<RetainStore::Variable> variables() {
    return {
        {"drill.counter.holes", RetainType::kInt,
         [this] {
           reads.fetch_add(1);
           return RetainValue::make_int(holes.load());
         }},
        {"drill.electrode.length_left", RetainType::kReal,
         [this] { return RetainValue::make_real(length_mm.load()); }},
        {"drill.seq.done", RetainType::kBool,
         [this] { return RetainValue::make_bool(done.load()); }},
    };
  }
};

std::int64_t holes_on_disk(const std::string& path) {
  const RetainLoadResult r = load_retain_file(path);
  EXPECT_EQ(r.warning, "");
  return r.values.contains("drill.counter.holes") ? r.values.at("drill.counter.holes").i : -1;
}

class RetainStoreTest : public ::testing::Test {
 protected:
  TempDir dir_;
  std::string path_ = dir_.file("retain.txt");
  Plant plant_;
};

TEST_F(RetainStoreTest, first_poll_writes_all_values) {
  RetainStore store(path_, seconds(1), plant_.variables());
  plant_.holes = 3;
  plant_.length_mm = 0.1;
  EXPECT_TRUE(store.poll(seconds(0)));
  EXPECT_EQ(store.writes(), 1U);
  const RetainLoadResult r = load_retain_file(path_);
  EXPECT_EQ(r.warning, "");
  const RetainMap expected = {
      {"drill.counter.holes", RetainValue::make_int(3)},
      {"drill.electrode.length_left", RetainValue::make_real(0.1)},
      {"drill.seq.done", RetainValue::make_bool(false)},
  };
  EXPECT_EQ(r.values, expected);
}

TEST_F(RetainStoreTest, changes_are_rate_limited_by_min_interval) {
  RetainStore store(path_, seconds(1), plant_.variables());
  plant_.holes = 1;
  EXPECT_TRUE(store.poll(seconds(0)));  // change at t=0 writes
  plant_.holes = 2;
  EXPECT_FALSE(store.poll(milliseconds(100)));  // change 100 ms later waits
  EXPECT_FALSE(store.poll(milliseconds(999)));
  EXPECT_EQ(holes_on_disk(path_), 1);
  EXPECT_TRUE(store.poll(milliseconds(1000)));  // t >= 1 s
  EXPECT_EQ(holes_on_disk(path_), 2);
  EXPECT_EQ(store.writes(), 2U);
  // A change after a long quiet period is written at once.
  plant_.holes = 3;
  EXPECT_TRUE(store.poll(seconds(60)));
  EXPECT_EQ(holes_on_disk(path_), 3);
  EXPECT_EQ(store.writes(), 3U);
  EXPECT_EQ(store.write_failures(), 0U);
}

TEST_F(RetainStoreTest, time_going_backwards_starts_a_new_time_line) {
  RetainStore store(path_, seconds(1), plant_.variables());
  EXPECT_TRUE(store.poll(std::chrono::hours(1000)));  // e.g. a long virtual run
  plant_.holes = 1;
  EXPECT_FALSE(store.poll(std::chrono::hours(1000) + milliseconds(10)));
  EXPECT_TRUE(store.poll(seconds(5)));  // steady clock after boot: must not wait 1000 h
  EXPECT_EQ(holes_on_disk(path_), 1);
}

TEST_F(RetainStoreTest, unchanged_values_are_never_rewritten) {
  RetainStore store(path_, milliseconds(10), plant_.variables());
  EXPECT_TRUE(store.poll(seconds(0)));
  fs::remove(path_);  // a rewrite would recreate it
  for (int k = 1; k <= 1000; ++k) {
    EXPECT_FALSE(store.poll(seconds(k)));
  }
  EXPECT_FALSE(store.flush());
  EXPECT_FALSE(fs::exists(path_));
  EXPECT_EQ(store.writes(), 1U);
}

TEST_F(RetainStoreTest, value_changed_and_changed_back_is_not_written) {
  RetainStore store(path_, seconds(1), plant_.variables());
  EXPECT_TRUE(store.poll(seconds(0)));
  plant_.holes = 9;
  EXPECT_FALSE(store.poll(milliseconds(500)));  // rate limited
  plant_.holes = 0;
  EXPECT_FALSE(store.poll(seconds(2)));  // equal to the file again: nothing to do
  EXPECT_EQ(store.writes(), 1U);
}

TEST_F(RetainStoreTest, sign_of_zero_counts_as_a_change) {
  plant_.length_mm = 0.0;
  RetainStore store(path_, seconds(0), plant_.variables());
  EXPECT_TRUE(store.poll(seconds(0)));
  plant_.length_mm = -0.0;
  EXPECT_TRUE(store.poll(seconds(1)));
  EXPECT_TRUE(std::signbit(load_retain_file(path_).values.at("drill.electrode.length_left").r));
}

TEST_F(RetainStoreTest, flush_writes_pending_change_regardless_of_interval) {
  RetainStore store(path_, seconds(10), plant_.variables());
  EXPECT_TRUE(store.poll(seconds(0)));
  plant_.holes = 42;
  EXPECT_FALSE(store.poll(milliseconds(100)));
  EXPECT_TRUE(store.flush());
  EXPECT_EQ(holes_on_disk(path_), 42);
  EXPECT_FALSE(store.flush());  // nothing pending any more
  EXPECT_EQ(store.writes(), 2U);
}

TEST_F(RetainStoreTest, stop_without_start_flushes_and_later_stops_do_not_read) {
  auto store = std::make_unique<RetainStore>(path_, seconds(10), plant_.variables());
  EXPECT_TRUE(store->poll(seconds(0)));
  plant_.holes = 7;
  EXPECT_FALSE(store->poll(seconds(1)));
  store->stop();
  EXPECT_EQ(holes_on_disk(path_), 7);
  const int reads = plant_.reads.load();
  store->stop();
  store.reset();  // destructor calls stop() again
  EXPECT_EQ(plant_.reads.load(), reads);
}

TEST_F(RetainStoreTest, destructor_flushes_pending_change) {
  {
    RetainStore store(path_, seconds(10), plant_.variables());
    EXPECT_TRUE(store.poll(seconds(0)));
    plant_.holes = 11;
    EXPECT_FALSE(store.poll(seconds(1)));
  }
  EXPECT_EQ(holes_on_disk(path_), 11);
}

TEST_F(RetainStoreTest, stop_of_running_thread_flushes_last_values) {
  RetainStore store(path_, seconds(3600), plant_.variables());
  store.start(std::chrono::hours(1));
  EXPECT_THROW(store.start(milliseconds(1)), std::logic_error);
  plant_.holes = 5;
  plant_.done = true;
  store.stop();  // must not wait an hour: the thread wakes up on stop
  EXPECT_GE(store.writes(), 1U);
  EXPECT_EQ(store.write_failures(), 0U);
  const RetainLoadResult r = load_retain_file(path_);
  EXPECT_EQ(r.warning, "");
  EXPECT_EQ(r.values.at("drill.counter.holes"), RetainValue::make_int(5));
  EXPECT_EQ(r.values.at("drill.seq.done"), RetainValue::make_bool(true));
  // Restartable.
  plant_.holes = 6;
  store.start(std::chrono::hours(1));
  store.stop();
  EXPECT_EQ(holes_on_disk(path_), 6);
}

TEST_F(RetainStoreTest, start_removes_stale_temp_files) {
  { std::ofstream(path_ + ".tmp.4194304") << "partial"; }
  RetainStore store(path_, seconds(1), plant_.variables());
  store.start(std::chrono::hours(1));
  store.stop();
  EXPECT_FALSE(fs::exists(path_ + ".tmp.4194304"));
  EXPECT_EQ(load_retain_file(path_).warning, "");
}

TEST_F(RetainStoreTest, unwritable_location_counts_failures_and_never_throws) {
  const std::string bad = dir_.file("no-such-dir/retain.txt");
  RetainStore store(bad, seconds(1), plant_.variables());
  bool wrote = true;
  EXPECT_NO_THROW(wrote = store.poll(seconds(0)));
  EXPECT_FALSE(wrote);
  EXPECT_EQ(store.writes(), 0U);
  EXPECT_EQ(store.write_failures(), 1U);
  EXPECT_FALSE(store.poll(milliseconds(500)));  // a failure also counts for min_interval
  EXPECT_EQ(store.write_failures(), 1U);
  EXPECT_FALSE(store.poll(seconds(1)));  // retried: nothing was written yet
  EXPECT_EQ(store.write_failures(), 2U);
  // The directory appears: the next allowed poll succeeds.
  fs::create_directory(dir_.file("no-such-dir"));
  EXPECT_TRUE(store.poll(seconds(2)));
  EXPECT_EQ(store.writes(), 1U);
  EXPECT_EQ(holes_on_disk(bad), 0);
}

TEST_F(RetainStoreTest, failing_background_thread_and_stop_do_not_throw) {
  const std::string plain = dir_.file("plain");
  std::ofstream(plain) << "x";
  RetainStore store(plain + "/retain.txt", seconds(1), plant_.variables());
  store.start(std::chrono::hours(1));
  EXPECT_NO_THROW(store.stop());
  EXPECT_GE(store.write_failures(), 1U);
  EXPECT_EQ(store.writes(), 0U);
}

TEST_F(RetainStoreTest, read_of_wrong_type_is_ignored) {
  std::vector<RetainStore::Variable> vars = {
      {"a.b.real", RetainType::kReal, [] { return RetainValue::make_int(5); }},
      {"a.b.int", RetainType::kInt, [] { return RetainValue::make_int(5); }},
  };
  RetainStore store(path_, seconds(1), std::move(vars));
  EXPECT_TRUE(store.poll(seconds(0)));
  const RetainLoadResult r = load_retain_file(path_);
  EXPECT_EQ(r.values.at("a.b.real"), RetainValue::make_real(0.0));
  EXPECT_EQ(r.values.at("a.b.int"), RetainValue::make_int(5));
}

TEST_F(RetainStoreTest, read_that_throws_is_counted_not_propagated) {
  std::vector<RetainStore::Variable> vars = {
      {"a.b.c", RetainType::kInt, []() -> RetainValue { throw std::runtime_error("boom"); }},
  };
  RetainStore store(path_, seconds(1), std::move(vars));
  EXPECT_FALSE(store.poll(seconds(0)));
  EXPECT_EQ(store.write_failures(), 1U);
  EXPECT_FALSE(store.flush());
  EXPECT_EQ(store.write_failures(), 2U);
  store.stop();
}

TEST_F(RetainStoreTest, bad_configuration_is_refused_at_construction) {
  auto read = [] { return RetainValue::make_int(0); };
  using V = std::vector<RetainStore::Variable>;
  EXPECT_THROW(RetainStore(path_, seconds(1), V{{"a b", RetainType::kInt, read}}),
               std::invalid_argument);
  EXPECT_THROW(RetainStore(path_, seconds(1), V{{"", RetainType::kInt, read}}),
               std::invalid_argument);
  EXPECT_THROW(RetainStore(path_, seconds(1),
                           V{{"a", RetainType::kInt, read}, {"a", RetainType::kInt, read}}),
               std::invalid_argument);
  EXPECT_THROW(RetainStore(path_, seconds(1), V{{"a", RetainType::kInt, nullptr}}),
               std::invalid_argument);
  EXPECT_THROW(RetainStore(path_, seconds(-1), V{}), std::invalid_argument);
  RetainStore ok(path_, seconds(1), V{{"a", RetainType::kInt, read}});
  EXPECT_THROW(ok.start(Duration::zero()), std::invalid_argument);
}

}  // namespace
}  // namespace edm::rt
