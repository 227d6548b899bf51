#include "edm/runtime/scheduler.hpp"

#include <pthread.h>
#include <sched.h>
#include <unistd.h>

#include <csignal>
#include <stdexcept>

#include "edm/runtime/rt_environment.hpp"
#include "edm/runtime/scheduling.hpp"

namespace edm::rt {

namespace {

constexpr Duration kStartLead = std::chrono::milliseconds(5);

}  // namespace

void RealTimeScheduler::start(const std::vector<Task*>& tasks, const RealClock& clock,
                              std::optional<Duration> run_for) {
  clock_ = &clock;
  stop_.store(false);
  const long cpus = sysconf(_SC_NPROCESSORS_ONLN);
  for (const Task* t : tasks) {
    if (t->spec().cpu && (*t->spec().cpu >= cpus || *t->spec().cpu >= CPU_SETSIZE)) {
      throw std::runtime_error("task '" + t->name() + "': cpu " + std::to_string(*t->spec().cpu) +
                               " is not available (" + std::to_string(cpus) + " online)");
    }
  }
  ready_.store(0);
  t0_ns_.store(0);
  setups_.assign(tasks.size(), ThreadSetup{});
  for (std::size_t i = 0; i < tasks.size(); ++i) {
    Task* t = tasks[i];
    threads_.emplace_back([this, t, i] { task_main(*t, i); });
  }
  // The origin is chosen only once every thread runs at its RT priority with a pre-faulted
  // stack, so the first release is not late because of our own start-up.
  while (ready_.load() < tasks.size()) {
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  // One common, millisecond-aligned origin keeps tasks phase-locked like a PLC's.
  const std::int64_t ms = 1'000'000;
  const std::int64_t t0 = ((clock.now() + kStartLead).count() / ms + 1) * ms;
  end_ns_.store(run_for ? t0 + run_for->count() : std::numeric_limits<std::int64_t>::max());
  t0_ns_.store(t0);
  t0_ns_.notify_all();
}

void RealTimeScheduler::stop() {
  stop_.store(true);
  if (t0_ns_.load() == 0) {
    t0_ns_.store(1);  // release threads still waiting for an origin (start() failed midway)
    t0_ns_.notify_all();
  }
  for (std::thread& th : threads_) {
    if (th.joinable()) {
      th.join();
    }
  }
  threads_.clear();
}

void RealTimeScheduler::task_main(Task& task, std::size_t index) noexcept {
  const TaskSpec& spec = task.spec();
  // Signals go to the controlling thread, never into an RT cycle.
  sigset_t block;
  sigemptyset(&block);
  sigaddset(&block, SIGINT);
  sigaddset(&block, SIGTERM);
  pthread_sigmask(SIG_BLOCK, &block, nullptr);
  pthread_setname_np(pthread_self(), spec.name.substr(0, 15).c_str());
  // SCHED_FIFO, affinity and stack; the controlling thread reports them (rt_environment.hpp).
  ThreadSetup& setup = setups_[index];
  setup = setup_task_thread(spec);
  if (setup.fifo_error != 0) {
    degraded_.store(true);
  }
  ready_.fetch_add(1);
  t0_ns_.wait(0);

  TimePoint release{t0_ns_.load()};
  const TimePoint stop_at{end_ns_.load()};
  while (!stop_.load(std::memory_order_relaxed) && release < stop_at) {
    RealClock::sleep_until(release);
    if (stop_.load(std::memory_order_relaxed)) {
      break;
    }
    const TimePoint end = task.run_cycle(release, *clock_);
    const NextRelease n = next_release(release, end, spec.interval, spec.overrun);
    if (n.overrun) {
      task.stats().record_overrun(n.omitted);
    }
    release = n.release;
  }
}

VirtualScheduler::VirtualScheduler(std::vector<Task*> tasks, VirtualClock& clock)
    : tasks_(std::move(tasks)), next_(tasks_.size(), clock.now()), clock_(&clock) {}

void VirtualScheduler::run_until(TimePoint end, const std::function<void()>& between_cycles,
                                 const std::atomic<bool>* stop) {
  while (stop == nullptr || !stop->load(std::memory_order_relaxed)) {
    std::size_t pick = tasks_.size();
    for (std::size_t i = 0; i < tasks_.size(); ++i) {
      if (pick == tasks_.size() || next_[i] < next_[pick] ||
          (next_[i] == next_[pick] && tasks_[i]->spec().priority < tasks_[pick]->spec().priority)) {
        pick = i;
      }
    }
    if (pick == tasks_.size() || next_[pick] >= end) {
      break;
    }
    Task& task = *tasks_[pick];
    const TimePoint release = next_[pick];
    clock_->advance_to(release);
    const TimePoint done = task.run_cycle(release, *clock_);
    const NextRelease n =
        rt::next_release(release, done, task.spec().interval, task.spec().overrun);
    if (n.overrun) {
      task.stats().record_overrun(n.omitted);
    }
    next_[pick] = n.release;
    if (between_cycles) {
      between_cycles();
    }
  }
  if (stop == nullptr || !stop->load(std::memory_order_relaxed)) {
    clock_->advance_to(end);
  }
}

}  // namespace edm::rt
