#include "edm/runtime/rt_environment.hpp"

#include <fcntl.h>
#include <pthread.h>
#include <sched.h>
#include <spdlog/spdlog.h>
#include <sys/mman.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
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

void RtEnvironment::add(bool ok, std::string text) {
  if (ok) {
    spdlog::info("real-time: {}", text);
  } else {
    spdlog::warn("real-time: {}", text);
  }
  lines_.push_back({ok, std::move(text)});
}

}  // namespace edm::rt
