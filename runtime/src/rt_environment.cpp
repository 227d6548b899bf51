#include "edm/runtime/rt_environment.hpp"

#include <fcntl.h>
#include <pthread.h>
#include <sched.h>
#include <spdlog/spdlog.h>
#include <sys/mman.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <set>
#include <utility>

#include "edm/runtime/scheduling.hpp"

namespace edm::rt {

namespace {

// Touches the stack the RT loop will use so it never page-faults mid-cycle.
[[gnu::noinline]] void prefault_stack() noexcept {
  volatile unsigned char buf[kPrefaultStackBytes];
  for (std::size_t i = 0; i < kPrefaultStackBytes; i += 4096) {
    buf[i] = 0;
  }
  (void)buf[0];
}

std::string join_names(const std::vector<const ThreadSetup*>& threads) {
  std::string out;
  for (const ThreadSetup* t : threads) {
    out += (out.empty() ? "" : ", ") + t->task;
  }
  return out;
}

}  // namespace

PmQosRequest& PmQosRequest::operator=(PmQosRequest&& other) noexcept {
  if (this != &other) {
    release();
    fd_ = std::exchange(other.fd_, -1);
  }
  return *this;
}

std::string PmQosRequest::hold(const std::string& device, std::int32_t latency_us) {
  release();
  const int fd = open(device.c_str(), O_WRONLY | O_CLOEXEC | O_NONBLOCK);
  if (fd < 0) {
    return std::string("open: ") + std::strerror(errno);
  }
  const ssize_t n = write(fd, &latency_us, sizeof latency_us);
  if (n != static_cast<ssize_t>(sizeof latency_us)) {
    const std::string why =
        n < 0 ? std::string("write: ") + std::strerror(errno) : std::string("write: short");
    close(fd);
    return why;
  }
  fd_ = fd;
  return {};
}

void PmQosRequest::release() noexcept {
  if (fd_ >= 0) {
    close(fd_);
    fd_ = -1;
  }
}

ThreadSetup setup_task_thread(const TaskSpec& spec) noexcept {
  ThreadSetup s;
  try {
    s.task = spec.name;
  } catch (...) {  // the name only labels the report line; the thread is set up without it
  }
  s.fifo_priority = fifo_priority(spec.priority);
  sched_param sp{};
  sp.sched_priority = s.fifo_priority;
  s.fifo_error = pthread_setschedparam(pthread_self(), SCHED_FIFO, &sp);
  s.cpu = spec.cpu;
  if (spec.cpu) {
    cpu_set_t set;
    CPU_ZERO(&set);
    CPU_SET(static_cast<std::size_t>(*spec.cpu), &set);
    s.affinity_error = pthread_setaffinity_np(pthread_self(), sizeof set, &set);
  }
  prefault_stack();
  s.prefaulted_bytes = kPrefaultStackBytes;
  s.tid = static_cast<int>(gettid());
  return s;
}

RtEnvironment::RtEnvironment(const RealtimeSpec& spec) {
  if (!spec.pm_qos_latency_us) {
    add(true, "PM QoS: no CPU latency request (machine.realtime.pm_qos_latency: off)");
  } else if (const std::string why = pm_qos_.hold(spec.pm_qos_device, *spec.pm_qos_latency_us);
             why.empty()) {
    add(true, fmt::format("PM QoS: holding a CPU latency request of {} us on {} while running",
                          *spec.pm_qos_latency_us, spec.pm_qos_device));
  } else {
    add(false, fmt::format("PM QoS: could not request {} us on {} ({}): idle CPUs may sleep in "
                           "deep C-states and wake late; run as root or give the edmplc group "
                           "write access to it (docs/deploy.md)",
                           *spec.pm_qos_latency_us, spec.pm_qos_device, why));
  }
  if (!spec.lock_memory) {
    add(true, "memory: not locked (machine.realtime.lock_memory: false)");
  } else if (mlockall(MCL_CURRENT | MCL_FUTURE) == 0) {
    memory_locked_ = true;
    add(true, "memory: locked (mlockall, current and future pages)");
  } else {
    add(false, fmt::format("memory: not locked, mlockall failed ({}): page faults may add "
                           "latency; run as root, with CAP_IPC_LOCK, or raise RLIMIT_MEMLOCK",
                           std::strerror(errno)));
  }
}

RtEnvironment::~RtEnvironment() {
  for (const Moved& m : moved_) {
    sched_setaffinity(m.tid, sizeof m.before, &m.before);  // a thread that has ended: ESRCH
  }
  pm_qos_.release();
  if (memory_locked_) {
    munlockall();
  }
}

void RtEnvironment::report_threads(const std::vector<ThreadSetup>& threads) {
  std::vector<const ThreadSetup*> refused;
  std::string fifo;
  int fifo_error = 0;
  for (const ThreadSetup& t : threads) {
    fifo += fmt::format("{}{} {}", fifo.empty() ? "" : ", ", t.task, t.fifo_priority);
    if (t.fifo_error != 0) {
      refused.push_back(&t);
      fifo_error = t.fifo_error;
    }
  }
  if (refused.empty()) {
    add(true, "SCHED_FIFO on the task threads only: " + fifo);
  } else {
    add(false, fmt::format("SCHED_FIFO refused ({}) for {}: they run under SCHED_OTHER and "
                           "release jitter will be large; run as root, with CAP_SYS_NICE, or "
                           "raise RLIMIT_RTPRIO",
                           std::strerror(fifo_error), join_names(refused)));
  }
  std::string pins;
  bool pins_ok = true;
  for (const ThreadSetup& t : threads) {
    std::string one = t.task;
    if (!t.cpu) {
      one += " on any CPU (no cpu: key)";
    } else if (t.affinity_error == 0) {
      one += fmt::format(" on CPU {}", *t.cpu);
    } else {
      pins_ok = false;
      one += fmt::format(" NOT pinned to CPU {} ({})", *t.cpu, std::strerror(t.affinity_error));
    }
    pins += (pins.empty() ? "" : ", ") + one;
  }
  add(pins_ok, "CPU affinity: " + pins);
  std::size_t prefaulted = 0;
  for (const ThreadSetup& t : threads) {
    prefaulted += t.prefaulted_bytes == kPrefaultStackBytes ? 1 : 0;
  }
  add(prefaulted == threads.size(),
      fmt::format("stacks: {} KiB pre-faulted on {} of {} task threads", kPrefaultStackBytes / 1024,
                  prefaulted, threads.size()));
}

void RtEnvironment::keep_off_rt_cpus(const std::vector<ThreadSetup>& threads) {
  std::set<int> rt_tids;
  cpu_set_t rt_cpus;
  CPU_ZERO(&rt_cpus);
  for (const ThreadSetup& t : threads) {
    rt_tids.insert(t.tid);
    if (t.cpu && t.affinity_error == 0 && *t.cpu >= 0 && *t.cpu < CPU_SETSIZE) {
      CPU_SET(static_cast<std::size_t>(*t.cpu), &rt_cpus);
    }
  }
  if (CPU_COUNT(&rt_cpus) == 0) {
    add(true, "non-RT threads: on any CPU (no task is pinned to a CPU)");
    return;
  }
  // The CPUs this (controlling) thread may use, less the tasks' ones.
  cpu_set_t allowed;
  CPU_ZERO(&allowed);
  if (sched_getaffinity(0, sizeof allowed, &allowed) != 0) {
    add(false, fmt::format("non-RT threads: left where they are (sched_getaffinity: {})",
                           std::strerror(errno)));
    return;
  }
  cpu_set_t others;
  CPU_ZERO(&others);
  for (int c = 0; c < CPU_SETSIZE; ++c) {
    if (CPU_ISSET(c, &allowed) && !CPU_ISSET(c, &rt_cpus)) {
      CPU_SET(static_cast<std::size_t>(c), &others);
    }
  }
  if (CPU_COUNT(&others) == 0) {
    add(false,
        "non-RT threads: share the tasks' CPUs (every CPU this process may use has a pinned "
        "task): the bridge and the logger can delay a task's wake-up; leave a CPU without tasks");
    return;
  }
  std::size_t moved = 0;
  std::size_t failed = 0;
  std::error_code ec;
  for (const auto& entry : std::filesystem::directory_iterator("/proc/self/task", ec)) {
    const int tid = std::atoi(entry.path().filename().c_str());
    if (tid <= 0 || rt_tids.count(tid) != 0) {
      continue;
    }
    Moved m{tid, {}};
    if (sched_getaffinity(tid, sizeof m.before, &m.before) != 0) {
      continue;  // ended meanwhile
    }
    if (sched_setaffinity(tid, sizeof others, &others) == 0) {
      moved_.push_back(m);
      ++moved;
    } else {
      ++failed;
    }
  }
  std::string cpus;
  for (int c = 0; c < CPU_SETSIZE; ++c) {
    if (CPU_ISSET(c, &others)) {
      cpus += fmt::format("{}{}", cpus.empty() ? "" : ",", c);
    }
  }
  add(failed == 0 && !ec,
      fmt::format(
          "non-RT threads: {} moved to CPU {} (off the tasks' CPUs){}", moved, cpus,
          failed == 0 && !ec ? std::string() : fmt::format(", {} could not be moved", failed)));
}

void RtEnvironment::add(bool ok, std::string text) {
  if (ok) {
    spdlog::info("real-time: {}", text);
  } else {
    spdlog::warn("real-time: {}", text);
  }
  lines_.push_back({ok, std::move(text)});
}

}  // namespace edm::rt
