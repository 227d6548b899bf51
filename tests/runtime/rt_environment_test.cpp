// The runtime's own real-time environment (rt_environment.hpp): the PM QoS request is held while
// the runtime runs and released after, tested on a FIFO standing in for /dev/cpu_dma_latency (a
// reader sees the request's value, EAGAIN while the request is held and EOF once it is closed);
// one start-up line per item, set up or not.

#include "edm/runtime/rt_environment.hpp"

#include <fcntl.h>
#include <gtest/gtest.h>
#include <sched.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstdint>
#include <fstream>
#include <future>
#include <optional>
#include <set>
#include <string>
#include <thread>
#include <vector>

#include "support/subprocess.hpp"
#include "support/temp_dir.hpp"

namespace edm::rt {
namespace {

using namespace std::chrono_literals;

/// The read end of a FIFO, opened non-blocking before any writer (a writer then never blocks).
class FifoReader {
 public:
  explicit FifoReader(const std::string& path) {
    if (mkfifo(path.c_str(), 0600) == 0) {
      fd_ = ::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC);
    }
  }
  ~FifoReader() {
    if (fd_ >= 0) {
      close(fd_);
    }
  }
  FifoReader(const FifoReader&) = delete;
  FifoReader& operator=(const FifoReader&) = delete;
  [[nodiscard]] bool ok() const { return fd_ >= 0; }

  /// The s32 a writer wrote, waiting up to `timeout` for it.
  std::optional<std::int32_t> value(std::chrono::milliseconds timeout) {
    const auto end = std::chrono::steady_clock::now() + timeout;
    std::int32_t v = 0;
    while (std::chrono::steady_clock::now() < end) {
      const ssize_t n = read(fd_, &v, sizeof v);
      if (n == static_cast<ssize_t>(sizeof v)) {
        return v;
      }
      std::this_thread::sleep_for(5ms);  // another process writes it: poll with a deadline
    }
    return std::nullopt;
  }
  /// "held": a writer has it open (EAGAIN); "released": every writer closed it (EOF).
  std::string state() {
    char c = 0;
    const ssize_t n = read(fd_, &c, 1);
    if (n == 0) {
      return "released";
    }
    if (n < 0 && errno == EAGAIN) {
      return "held";
    }
    return "unexpected";
  }

 private:
  int fd_{-1};
};

TEST(PmQosRequest, writes_the_latency_and_holds_it_until_released) {
  test::TempDir dir("edm-pmqos");
  FifoReader reader(dir.file("qos"));
  ASSERT_TRUE(reader.ok());
  PmQosRequest request;
  EXPECT_EQ(request.hold(dir.file("qos"), 12), "");
  EXPECT_TRUE(request.held());
  EXPECT_EQ(reader.value(1s), 12);
  EXPECT_EQ(reader.state(), "held");
  request.release();
  EXPECT_FALSE(request.held());
  EXPECT_EQ(reader.state(), "released");
}

TEST(PmQosRequest, says_why_it_could_not_and_never_blocks_on_a_fifo_without_reader) {
  test::TempDir dir("edm-pmqos");
  PmQosRequest request;
  EXPECT_EQ(request.hold(dir.file("missing"), 0), "open: No such file or directory");
  ASSERT_EQ(mkfifo(dir.file("no_reader").c_str(), 0600), 0);
  EXPECT_EQ(request.hold(dir.file("no_reader"), 0), "open: No such device or address");
  EXPECT_FALSE(request.held());
}

TEST(RtEnvironment, holds_the_configured_request_for_its_lifetime) {
  test::TempDir dir("edm-rtenv");
  FifoReader reader(dir.file("qos"));
  ASSERT_TRUE(reader.ok());
  RealtimeSpec spec;
  spec.pm_qos_latency_us = 7;
  spec.pm_qos_device = dir.file("qos");
  spec.lock_memory = false;  // a unit test does not lock the whole test process
  {
    RtEnvironment env(spec);
    EXPECT_TRUE(env.pm_qos_held());
    EXPECT_EQ(reader.value(1s), 7);
    EXPECT_EQ(reader.state(), "held");
    ASSERT_EQ(env.lines().size(), 2u);
    EXPECT_TRUE(env.lines()[0].ok);
    EXPECT_EQ(env.lines()[0].text, "PM QoS: holding a CPU latency request of 7 us on " +
                                       dir.file("qos") + " while running");
    EXPECT_EQ(env.lines()[1].text, "memory: not locked (machine.realtime.lock_memory: false)");
  }
  EXPECT_EQ(reader.state(), "released");
}

TEST(RtEnvironment, off_makes_no_request_and_a_refused_one_is_one_warning_line) {
  RealtimeSpec off;
  off.pm_qos_latency_us.reset();
  off.lock_memory = false;
  RtEnvironment a(off);
  EXPECT_FALSE(a.pm_qos_held());
  EXPECT_EQ(a.lines().at(0).text,
            "PM QoS: no CPU latency request (machine.realtime.pm_qos_latency: off)");

  RealtimeSpec refused;
  refused.pm_qos_device = "/nonexistent/cpu_dma_latency";
  refused.lock_memory = false;
  RtEnvironment b(refused);
  EXPECT_FALSE(b.pm_qos_held());
  EXPECT_FALSE(b.lines().at(0).ok);
  EXPECT_NE(b.lines().at(0).text.find("could not request 0 us on /nonexistent/cpu_dma_latency "
                                      "(open: No such file or directory)"),
            std::string::npos)
      << b.lines().at(0).text;
}

TEST(RtEnvironment, reports_each_thread_item_on_one_line) {
  RealtimeSpec spec;
  spec.pm_qos_latency_us.reset();
  spec.lock_memory = false;
  RtEnvironment env(spec);
  ThreadSetup fast{"fast", 90, 0, 1, 0, kPrefaultStackBytes};
  ThreadSetup slow{"slow", 85, EPERM, std::nullopt, 0, kPrefaultStackBytes};
  env.report_threads({fast, slow});
  ASSERT_EQ(env.lines().size(), 5u);
  EXPECT_FALSE(env.lines()[2].ok);
  EXPECT_EQ(env.lines()[2].text.rfind("SCHED_FIFO refused (Operation not permitted) for slow: "
                                      "they run under SCHED_OTHER",
                                      0),
            0u)
      << env.lines()[2].text;
  EXPECT_TRUE(env.lines()[3].ok);
  EXPECT_EQ(env.lines()[3].text, "CPU affinity: fast on CPU 1, slow on any CPU (no cpu: key)");
  EXPECT_EQ(env.lines()[4].text, "stacks: 256 KiB pre-faulted on 2 of 2 task threads");

  env.report_threads({ThreadSetup{"fast", 90, 0, 1, EINVAL, kPrefaultStackBytes}});
  EXPECT_FALSE(env.lines()[6].ok);
  EXPECT_EQ(env.lines()[6].text, "CPU affinity: fast NOT pinned to CPU 1 (Invalid argument)");
}

TEST(RtEnvironment, a_task_thread_sets_itself_up) {
  TaskSpec spec;
  spec.name = "t";
  spec.priority = 3;
  spec.cpu = 0;
  ThreadSetup s;
  std::thread([&] { s = setup_task_thread(spec); }).join();
  EXPECT_EQ(s.task, "t");
  EXPECT_EQ(s.fifo_priority, 87);
  EXPECT_EQ(s.affinity_error, 0);
  EXPECT_EQ(s.prefaulted_bytes, kPrefaultStackBytes);
  // fifo_error is 0 with the right to use SCHED_FIFO (root, CAP_SYS_NICE), EPERM without.
  EXPECT_TRUE(s.fifo_error == 0 || s.fifo_error == EPERM) << s.fifo_error;
}

/// The CPUs thread `tid` may run on.
std::set<int> cpus_of(int tid) {
  cpu_set_t set;
  CPU_ZERO(&set);
  std::set<int> out;
  if (sched_getaffinity(tid, sizeof set, &set) == 0) {
    for (int c = 0; c < CPU_SETSIZE; ++c) {
      if (CPU_ISSET(c, &set)) out.insert(c);
    }
  }
  return out;
}

/// A thread that reports its tid and waits until released (explicit synchronisation, no sleeps).
class ParkedThread {
 public:
  ParkedThread()
      : thread_([this] {
          tid_.set_value(static_cast<int>(gettid()));
          release_.get_future().wait();
        }) {
    tid = tid_.get_future().get();
  }
  ~ParkedThread() {
    release_.set_value();
    thread_.join();
  }
  ParkedThread(const ParkedThread&) = delete;
  ParkedThread& operator=(const ParkedThread&) = delete;
  int tid{0};

 private:
  std::promise<int> tid_;
  std::promise<void> release_;
  std::thread thread_;
};

// A task pinned to a CPU keeps it to itself: every other thread of the process (here the test's
// own and a parked "bridge" thread) moves to the other CPUs while the environment lives, and back
// after; a task thread is never moved.
TEST(RtEnvironment, the_non_rt_threads_leave_the_cpus_the_tasks_are_pinned_to) {
  const std::set<int> all = cpus_of(0);
  if (all.size() < 2) {
    GTEST_SKIP() << "needs 2 CPUs";
  }
  const int rt_cpu = *all.rbegin();
  ParkedThread bridge;
  ParkedThread task;
  ThreadSetup setup{"fast", 90, 0, rt_cpu, 0, kPrefaultStackBytes, task.tid};
  const std::set<int> task_before = cpus_of(task.tid);
  RealtimeSpec spec;
  spec.pm_qos_latency_us.reset();
  spec.lock_memory = false;
  {
    RtEnvironment env(spec);
    env.keep_off_rt_cpus({setup});
    std::set<int> others = all;
    others.erase(rt_cpu);
    EXPECT_EQ(cpus_of(bridge.tid), others);
    EXPECT_EQ(cpus_of(static_cast<int>(gettid())), others);
    EXPECT_EQ(cpus_of(task.tid), task_before);
    ASSERT_FALSE(env.lines().empty());
    EXPECT_TRUE(env.lines().back().ok) << env.lines().back().text;
    EXPECT_NE(env.lines().back().text.find("moved to CPU"), std::string::npos)
        << env.lines().back().text;
    // A thread started now inherits the restriction from its creator.
    ParkedThread later;
    EXPECT_EQ(cpus_of(later.tid), others);
  }
  EXPECT_EQ(cpus_of(bridge.tid), all);
  EXPECT_EQ(cpus_of(static_cast<int>(gettid())), all);
}

// No pinned task: nothing moves. Every CPU pinned: nothing moves, and one warning says why.
TEST(RtEnvironment, non_rt_threads_stay_when_no_task_is_pinned_or_no_cpu_is_left) {
  const std::set<int> all = cpus_of(0);
  RealtimeSpec spec;
  spec.pm_qos_latency_us.reset();
  spec.lock_memory = false;
  RtEnvironment env(spec);
  env.keep_off_rt_cpus({ThreadSetup{"fast", 90, 0, std::nullopt, 0, kPrefaultStackBytes, 0}});
  EXPECT_TRUE(env.lines().back().ok);
  EXPECT_EQ(env.lines().back().text, "non-RT threads: on any CPU (no task is pinned to a CPU)");
  std::vector<ThreadSetup> every;
  for (const int c : all) {
    every.push_back(ThreadSetup{"t" + std::to_string(c), 90, 0, c, 0, kPrefaultStackBytes, 0});
  }
  env.keep_off_rt_cpus(every);
  EXPECT_FALSE(env.lines().back().ok);
  EXPECT_EQ(env.lines().back().text.rfind("non-RT threads: share the tasks' CPUs", 0), 0u)
      << env.lines().back().text;
  EXPECT_EQ(cpus_of(static_cast<int>(gettid())), all);
}

// edmplc as shipped holds its own request from start to exit; the config points it at a FIFO.
TEST(RtEnvironment, edmplc_holds_its_request_while_it_runs_and_releases_it_at_exit) {
  test::TempDir dir("edm-rtenv-proc");
  FifoReader reader(dir.file("qos"));
  ASSERT_TRUE(reader.ok());
  std::ofstream(dir.file("m.yaml")) << "version: 1\n"
                                       "machine:\n"
                                       "  name: rt\n"
                                       "  io: {driver: loopback, params: {channels: 1}}\n"
                                       "  realtime: {pm_qos_latency: 3us, pm_qos_device: "
                                    << dir.file("qos")
                                    << "}\n"
                                       "tasks:\n"
                                       "  - {name: fast, interval: 1ms, cpu: 0, programs: [p]}\n"
                                       "programs:\n"
                                       "  - {name: p, blocks: []}\n";
  test::Child c({EDM_EDMPLC_PATH, "--config", dir.file("m.yaml"), "--clock", "real", "--run-for",
                 "1500ms", "--bridge-port", "0"});
  EXPECT_EQ(reader.value(10s), 3) << c.output();
  EXPECT_FALSE(c.poll().has_value()) << "edmplc ended before its run was over";
  EXPECT_EQ(reader.state(), "held");
  EXPECT_EQ(c.wait(), 0) << c.output();
  EXPECT_EQ(reader.state(), "released");
  const std::string out = c.output();
  for (const char* line :
       {"real-time: PM QoS: holding a CPU latency request of 3 us on ",
        "real-time: memory: ", "SCHED_", "real-time: CPU affinity: fast on CPU 0",
        "real-time: stacks: 256 KiB pre-faulted on 1 of 1 task threads"}) {
    EXPECT_NE(out.find(line), std::string::npos) << line << "\n" << out;
  }
}

}  // namespace
}  // namespace edm::rt
