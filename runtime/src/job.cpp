#include "edm/runtime/job.hpp"

#include <utility>

namespace edm::rt {

LoadResult JobStore::load(std::vector<machining::MotionBlock> program, std::uint32_t program_id) {
  Phase expected = Phase::kIdle;
  if (!phase_.compare_exchange_strong(expected, Phase::kLoading, std::memory_order_acq_rel)) {
    return LoadResult::kBusy;
  }
  auto next = std::make_unique<const Program>(std::move(program));
  const std::size_t n = next->size();
  std::unique_ptr<const Program> old = std::exchange(program_, std::move(next));
  count_.store(n, std::memory_order_relaxed);
  index_.store(0, std::memory_order_relaxed);
  line_.store(0, std::memory_order_relaxed);
  program_id_.store(program_id, std::memory_order_relaxed);
  outcome_.store(JobOutcome::kNone, std::memory_order_relaxed);
  generation_.fetch_add(1, std::memory_order_relaxed);
  phase_.store(Phase::kIdle, std::memory_order_release);
  old.reset();  // freed here, on the loader's thread: the RT side cannot be reading it
  return LoadResult::kOk;
}

LoadResult JobStore::load_mdi(std::vector<machining::MotionBlock> program) {
  Phase expected = Phase::kIdle;
  if (!phase_.compare_exchange_strong(expected, Phase::kLoading, std::memory_order_acq_rel)) {
    return LoadResult::kBusy;
  }
  auto next = std::make_unique<const Program>(std::move(program));
  const std::size_t n = next->size();
  std::unique_ptr<const Program> old = std::exchange(mdi_, std::move(next));
  mdi_count_.store(n, std::memory_order_relaxed);
  phase_.store(Phase::kIdle, std::memory_order_release);
  old.reset();
  return LoadResult::kOk;
}

bool JobStore::rt_begin() noexcept {
  Phase expected = Phase::kIdle;
  if (!phase_.compare_exchange_strong(expected, Phase::kActive, std::memory_order_acq_rel)) {
    return false;
  }
  const bool dry = next_dry_run_.exchange(false, std::memory_order_acquire);
  const JobSlot slot = next_slot_.exchange(JobSlot::kMain, std::memory_order_relaxed);
  const Program* p = slot == JobSlot::kMdi ? mdi_.get() : program_.get();
  if (p == nullptr || p->empty()) {
    phase_.store(Phase::kIdle, std::memory_order_release);
    return false;
  }
  running_ = p;
  cur_slot_.store(slot, std::memory_order_relaxed);
  cur_dry_run_.store(dry, std::memory_order_release);
  index_.store(0, std::memory_order_relaxed);
  line_.store((*p)[0].line, std::memory_order_relaxed);
  outcome_.store(JobOutcome::kRunning, std::memory_order_relaxed);
  jobs_started_.fetch_add(1, std::memory_order_relaxed);
  return true;
}

const machining::MotionBlock* JobStore::rt_current() const noexcept {
  if (phase_.load(std::memory_order_acquire) != Phase::kActive) return nullptr;
  const std::size_t i = index_.load(std::memory_order_relaxed);
  return i < running_->size() ? &(*running_)[i] : nullptr;
}

void JobStore::rt_advance() noexcept {
  if (phase_.load(std::memory_order_acquire) != Phase::kActive) return;
  const std::size_t i = index_.load(std::memory_order_relaxed);
  if (i >= running_->size()) return;
  index_.store(i + 1, std::memory_order_relaxed);
  line_.store(i + 1 < running_->size() ? (*running_)[i + 1].line : 0, std::memory_order_relaxed);
}

void JobStore::rt_finish(JobOutcome outcome) noexcept {
  if (phase_.load(std::memory_order_acquire) != Phase::kActive) return;
  outcome_.store(outcome, std::memory_order_relaxed);
  phase_.store(Phase::kIdle, std::memory_order_release);
}

JobProgress JobStore::progress() const noexcept {
  JobProgress p;
  p.outcome = outcome_.load(std::memory_order_acquire);
  p.generation = generation_.load(std::memory_order_relaxed);
  p.jobs_started = jobs_started_.load(std::memory_order_relaxed);
  p.block_index = index_.load(std::memory_order_relaxed);
  p.slot = cur_slot_.load(std::memory_order_relaxed);
  p.block_count = (p.slot == JobSlot::kMdi ? mdi_count_ : count_).load(std::memory_order_relaxed);
  p.line = line_.load(std::memory_order_relaxed);
  p.program_id = program_id_.load(std::memory_order_relaxed);
  p.dry_run = cur_dry_run_.load(std::memory_order_relaxed);
  return p;
}

}  // namespace edm::rt
