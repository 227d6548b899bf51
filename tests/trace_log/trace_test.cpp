#include "edm/runtime/trace.hpp"

#include <gtest/gtest.h>

#include <chrono>
#include <cstdint>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "edm/runtime/pin.hpp"
#include "edm/runtime/pin_sampler.hpp"
#include "support/files.hpp"

namespace edm::rt {
namespace {

using namespace std::chrono_literals;

using Row = std::vector<std::string>;
using edm::test::read_file;

// Field split without quoting: the names used in these tests contain no commas or quotes.
Row split_fields(const std::string& line) {
  Row fields;
  std::string field;
  std::istringstream in(line);
  while (std::getline(in, field, ',')) {
    fields.push_back(field);
  }
  if (!line.empty() && line.back() == ',') {
    fields.emplace_back();  // getline drops a trailing empty field
  }
  return fields;
}

struct Csv {
  Row header;
  std::vector<Row> rows;
};

Csv parse_csv(const std::string& text) {
  Csv csv;
  EXPECT_TRUE(text.empty() || text.back() == '\n') << "CSV must end with a newline";
  std::istringstream in(text);
  std::string line;
  bool first = true;
  while (std::getline(in, line)) {
    if (first) {
      csv.header = split_fields(line);
      first = false;
    } else {
      csv.rows.push_back(split_fields(line));
    }
  }
  return csv;
}

std::string temp_path(const std::string& name) {
  return ::testing::TempDir() + "edm_trace_" + name + "_" +
         std::to_string(std::chrono::steady_clock::now().time_since_epoch().count()) + ".csv";
}

// The one sampler of the trace recorder and the bridge's trace tap.
TEST(PinSampler, reads_every_pin_as_a_double_and_stamps_the_cycle) {
  Output<double> td{-2.5};
  Output<std::int64_t> count{9007199254740992};
  Output<bool> on{true};
  PinSampler sampler;
  const std::vector<PinRef> pins{PinRef::of(td), PinRef::of(count), PinRef::of(on)};
  sampler.assign(pins);
  EXPECT_EQ(sampler.size(), 3u);
  static_assert(noexcept(sampler.sample(TimePoint{}, 0, 0)), "sampling runs in the cycle");

  const TraceSample s = sampler.sample(TimePoint{1234567890123}, 77, 2);
  EXPECT_EQ(s.release, TimePoint{1234567890123});
  EXPECT_EQ(s.cycle, 77u);
  EXPECT_EQ(s.channel, 2u);
  ASSERT_EQ(s.n, 3u);
  EXPECT_EQ(s.v[0], -2.5);
  EXPECT_EQ(s.v[1], 9007199254740992.0);
  EXPECT_EQ(s.v[2], 1.0);

  on.set(false);
  EXPECT_EQ(sampler.sample(TimePoint{}, 78).v[2], 0.0);  // read now, not at assign()
}

TEST(PinSampler, refuses_too_many_or_null_pins_and_keeps_the_previous_ones) {
  Output<double> x{4.0};
  PinSampler sampler;
  sampler.assign(std::vector<PinRef>{PinRef::of(x)});
  EXPECT_THROW(sampler.assign(std::vector<PinRef>(kMaxTraceVarsPerTask + 1, PinRef::of(x))),
               std::invalid_argument);
  EXPECT_THROW(sampler.assign(std::vector<PinRef>{PinRef::of(x), PinRef{}}), std::invalid_argument);
  ASSERT_EQ(sampler.size(), 1u);
  EXPECT_EQ(sampler.sample(TimePoint{}, 0).v[0], 4.0);

  sampler.assign(std::vector<PinRef>(kMaxTraceVarsPerTask, PinRef::of(x)));  // the limit is fine
  EXPECT_EQ(sampler.size(), kMaxTraceVarsPerTask);
  sampler.assign({});
  EXPECT_EQ(sampler.sample(TimePoint{}, 0).n, 0u);
}

TEST(TraceRecorder, records_exact_values_and_times_of_real_int_and_bool_pins) {
  Output<double> td{0.0};
  Output<std::int64_t> count{0};
  Output<bool> on{false};
  TraceRecorder rec;
  const auto ch = rec.add_channel("gap",
                                  {{"gap.ctl.td_us", PinRef::of(td)},
                                   {"gap.ctl.count", PinRef::of(count)},
                                   {"gap.ctl.on", PinRef::of(on)}},
                                  16);
  ASSERT_EQ(ch, 0u);

  const std::vector<double> tds{0.1, -2.5, 1e-300, 12345.678901234567};
  const std::vector<std::int64_t> counts{0, -42, 9007199254740992, 7};
  const std::vector<bool> ons{false, true, false, true};
  const std::vector<TimePoint> times{0ns, 1ms, 1234567890123ns, 2s};
  for (std::size_t i = 0; i < tds.size(); ++i) {
    td.set(tds[i]);
    count.set(counts[i]);
    on.set(ons[i]);
    rec.sample(ch, times[i], 10 + i);
  }

  std::ostringstream out;
  EXPECT_EQ(rec.drain(out), 4u);
  const Csv csv = parse_csv(out.str());
  EXPECT_EQ(csv.header,
            (Row{"t_s", "task", "cycle", "gap.ctl.td_us", "gap.ctl.count", "gap.ctl.on"}));
  ASSERT_EQ(csv.rows.size(), 4u);

  const std::vector<std::string> t_s{"0.000000000", "0.001000000", "1234.567890123", "2.000000000"};
  const std::vector<std::string> td_text{"0.1", "-2.5", "1e-300", ""};
  const std::vector<std::string> count_text{"0", "-42", "9007199254740992", "7"};
  for (std::size_t i = 0; i < csv.rows.size(); ++i) {
    const Row& r = csv.rows[i];
    ASSERT_EQ(r.size(), 6u) << "row " << i;
    EXPECT_EQ(r[0], t_s[i]);
    EXPECT_EQ(r[1], "gap");
    EXPECT_EQ(r[2], std::to_string(10 + i));
    EXPECT_EQ(std::stod(r[3]), tds[i]) << "round trip of " << r[3];
    if (!td_text[i].empty()) {
      EXPECT_EQ(r[3], td_text[i]);
    }
    EXPECT_EQ(r[4], count_text[i]);
    EXPECT_EQ(r[5], ons[i] ? "1" : "0");
  }
  EXPECT_EQ(rec.dropped(), 0u);
}

TEST(TraceRecorder, full_ring_counts_every_drop_and_keeps_the_oldest_samples) {
  Output<double> x{1.5};
  TraceRecorder rec;
  const auto ch = rec.add_channel("io", {{"io.x", PinRef::of(x)}}, 8);
  for (std::uint64_t i = 0; i < 20; ++i) {
    rec.sample(ch, TimePoint{static_cast<std::int64_t>(i) * 1'000'000}, i);  // returns: no block
  }
  EXPECT_EQ(rec.dropped(), 12u);
  EXPECT_EQ(rec.dropped(ch), 12u);
  EXPECT_EQ(rec.dropped(ch + 7), 0u);

  std::ostringstream out;
  ASSERT_EQ(rec.drain(out), 8u);
  const Csv csv = parse_csv(out.str());
  ASSERT_EQ(csv.rows.size(), 8u);
  for (std::size_t i = 0; i < 8; ++i) {
    EXPECT_EQ(csv.rows[i][2], std::to_string(i));
  }
  // Room again after draining.
  rec.sample(ch, 20ms, 20);
  EXPECT_EQ(rec.drain(out), 1u);
  EXPECT_EQ(rec.dropped(), 12u);
}

TEST(TraceRecorder, merges_two_channels_in_time_order_with_empty_foreign_columns) {
  Output<double> fast_x{1.0};
  Output<double> fast_y{2.0};
  Output<std::int64_t> slow_z{3};
  TraceRecorder rec;
  const auto fast = rec.add_channel(
      "fast", {{"fast.a.x", PinRef::of(fast_x)}, {"fast.a.y", PinRef::of(fast_y)}}, 16);
  const auto slow = rec.add_channel("slow", {{"slow.b.z", PinRef::of(slow_z)}}, 16);
  ASSERT_EQ(fast, 0u);
  ASSERT_EQ(slow, 1u);

  // All fast samples are pushed before the slow ones: the drain, not push order, sorts them.
  for (std::uint64_t i = 0; i <= 6; ++i) {
    rec.sample(fast, TimePoint{std::chrono::milliseconds(i)}, i);
  }
  for (std::uint64_t i = 0; i <= 2; ++i) {
    rec.sample(slow, TimePoint{std::chrono::milliseconds(3 * i)}, i);
  }

  std::ostringstream out;
  ASSERT_EQ(rec.drain(out), 10u);
  const Csv csv = parse_csv(out.str());
  EXPECT_EQ(csv.header, (Row{"t_s", "task", "cycle", "fast.a.x", "fast.a.y", "slow.b.z"}));
  const std::vector<std::pair<std::string, std::string>> expected{
      {"0.000000000", "fast"}, {"0.000000000", "slow"}, {"0.001000000", "fast"},
      {"0.002000000", "fast"}, {"0.003000000", "fast"}, {"0.003000000", "slow"},
      {"0.004000000", "fast"}, {"0.005000000", "fast"}, {"0.006000000", "fast"},
      {"0.006000000", "slow"}};
  ASSERT_EQ(csv.rows.size(), expected.size());
  for (std::size_t i = 0; i < expected.size(); ++i) {
    const Row& r = csv.rows[i];
    ASSERT_EQ(r.size(), 6u) << "row " << i;
    EXPECT_EQ(r[0], expected[i].first) << "row " << i;
    EXPECT_EQ(r[1], expected[i].second) << "row " << i;
    if (r[1] == "fast") {
      EXPECT_EQ(r[3], "1");
      EXPECT_EQ(r[4], "2");
      EXPECT_EQ(r[5], "");
    } else {
      EXPECT_EQ(r[3], "");
      EXPECT_EQ(r[4], "");
      EXPECT_EQ(r[5], "3");
    }
  }
}

TEST(TraceRecorder, writes_the_header_once_even_without_samples) {
  Output<bool> b{true};
  TraceRecorder rec;
  rec.add_channel("t", {{"t.p.b", PinRef::of(b)}}, 2);
  std::ostringstream out;
  EXPECT_EQ(rec.drain(out), 0u);
  EXPECT_EQ(out.str(), "t_s,task,cycle,t.p.b\n");
  EXPECT_EQ(rec.drain(out), 0u);
  EXPECT_EQ(out.str(), "t_s,task,cycle,t.p.b\n");
  rec.sample(0, 250us, 3);
  EXPECT_EQ(rec.drain(out), 1u);
  EXPECT_EQ(out.str(), "t_s,task,cycle,t.p.b\n0.000250000,t,3,1\n");
  // The columns are fixed once the header is out.
  EXPECT_THROW(rec.add_channel("late", {{"late.p.b", PinRef::of(b)}}, 2), std::logic_error);
}

TEST(TraceRecorder, rejects_too_many_variables_bad_capacity_and_null_pins) {
  std::vector<Output<double>> pins(kMaxTraceVarsPerTask + 1);
  std::vector<std::pair<std::string, PinRef>> vars;
  for (std::size_t i = 0; i < pins.size(); ++i) {
    vars.emplace_back("p.b.v" + std::to_string(i), PinRef::of(pins[i]));
  }
  TraceRecorder rec;
  EXPECT_THROW(rec.add_channel("t", vars, 8), std::invalid_argument);
  vars.pop_back();
  EXPECT_EQ(rec.add_channel("t", vars, 8), 0u);  // exactly the limit is fine

  Output<double> x;
  EXPECT_THROW(rec.add_channel("u", {{"u.x", PinRef::of(x)}}, 6), std::invalid_argument);
  EXPECT_THROW(rec.add_channel("u", {{"u.x", PinRef::of(x)}}, 0), std::invalid_argument);
  EXPECT_THROW(rec.add_channel("u", {{"u.x", PinRef{}}}, 8), std::invalid_argument);
  EXPECT_EQ(rec.channel_count(), 1u);
}

TEST(TraceRecorder, file_writer_has_written_every_sample_when_stop_returns) {
  Output<std::int64_t> n{0};
  TraceRecorder rec;
  const auto ch = rec.add_channel("task", {{"task.p.n", PinRef::of(n)}}, 4096);
  const std::string path = temp_path("writer");
  rec.start_file_writer(path);
  EXPECT_THROW(rec.start_file_writer(path), std::logic_error);
  constexpr std::int64_t kSamples = 3000;  // fewer than the capacity: nothing can be dropped
  for (std::int64_t i = 0; i < kSamples; ++i) {
    n.set(i * 3);
    rec.sample(ch, TimePoint{i * 1000}, static_cast<std::uint64_t>(i));
  }
  rec.stop();
  rec.stop();  // idempotent

  const Csv csv = parse_csv(read_file(path));
  EXPECT_EQ(csv.header, (Row{"t_s", "task", "cycle", "task.p.n"}));
  ASSERT_EQ(csv.rows.size(), static_cast<std::size_t>(kSamples));
  EXPECT_EQ(rec.dropped(), 0u);
  EXPECT_FALSE(rec.write_failed());
  for (std::int64_t i = 0; i < kSamples; ++i) {
    const Row& r = csv.rows[static_cast<std::size_t>(i)];
    ASSERT_EQ(r.size(), 4u);
    ASSERT_EQ(r[2], std::to_string(i));
    ASSERT_EQ(r[3], std::to_string(i * 3));
  }
  std::remove(path.c_str());
}

TEST(TraceRecorder, file_writer_reports_an_unopenable_path) {
  TraceRecorder rec;
  const std::string path = "/nonexistent-edm-dir/trace.csv";
  try {
    rec.start_file_writer(path);
    FAIL() << "expected std::runtime_error";
  } catch (const std::runtime_error& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find(path), std::string::npos) << what;
    EXPECT_NE(what.find("No such file or directory"), std::string::npos) << what;
  }
  rec.stop();  // no writer: no-op
}

TEST(TraceRecorder, file_writer_flags_a_failed_write_without_throwing) {
  Output<double> x{0.25};
  TraceRecorder rec;
  const auto ch = rec.add_channel("t", {{"t.x", PinRef::of(x)}}, 64);
  rec.start_file_writer("/dev/full");  // opens fine, every write fails with ENOSPC
  for (std::uint64_t i = 0; i < 50; ++i) {
    rec.sample(ch, TimePoint{static_cast<std::int64_t>(i)}, i);
  }
  EXPECT_NO_THROW(rec.stop());
  EXPECT_TRUE(rec.write_failed());
}

TEST(TraceRecorder, concurrent_producer_and_drain_lose_nothing_but_counted_drops) {
  Output<double> v{0.0};
  TraceRecorder rec;
  const auto ch = rec.add_channel("rt", {{"rt.p.v", PinRef::of(v)}}, 8);
  constexpr std::uint64_t kSamples = 20000;
  std::thread producer([&] {
    for (std::uint64_t i = 0; i < kSamples; ++i) {
      v.set(static_cast<double>(i));
      rec.sample(ch, TimePoint{static_cast<std::int64_t>(i)}, i);
    }
  });
  std::ostringstream out;
  std::size_t rows = 0;
  for (int i = 0; i < 200; ++i) {
    rows += rec.drain(out);
  }
  producer.join();
  rows += rec.drain(out);

  EXPECT_EQ(rows + rec.dropped(), kSamples);
  const Csv csv = parse_csv(out.str());
  ASSERT_EQ(csv.rows.size(), rows);
  long long previous = -1;
  for (const Row& r : csv.rows) {
    const long long cycle = std::stoll(r[2]);
    // Push order survives, and each value was read in the cycle of its row.
    EXPECT_GT(cycle, previous);
    EXPECT_EQ(std::stod(r[3]), static_cast<double>(cycle));
    previous = cycle;
  }
}

TEST(TraceRecorder, identical_runs_give_identical_bytes) {
  auto run = [] {
    Output<double> a{0.0};
    Output<bool> b{false};
    TraceRecorder rec;
    const auto c0 = rec.add_channel("t0", {{"t0.a", PinRef::of(a)}}, 64);
    const auto c1 = rec.add_channel("t1", {{"t1.b", PinRef::of(b)}}, 64);
    std::ostringstream out;
    for (std::uint64_t i = 0; i < 40; ++i) {
      a.set(static_cast<double>(i) / 3.0);
      rec.sample(c0, TimePoint{static_cast<std::int64_t>(i) * 250'000}, i);
      if (i % 4 == 0) {
        b.set(i % 8 == 0);
        rec.sample(c1, TimePoint{static_cast<std::int64_t>(i) * 250'000}, i / 4);
      }
      if (i % 7 == 0) {
        rec.drain(out);
      }
    }
    rec.drain(out);
    return out.str();
  };
  const std::string first = run();
  EXPECT_EQ(first, run());
  EXPECT_EQ(parse_csv(first).rows.size(), 50u);
}

}  // namespace
}  // namespace edm::rt
