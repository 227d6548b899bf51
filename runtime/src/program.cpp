#include "edm/runtime/program.hpp"

namespace edm::rt {

Block& Program::add(std::string name, std::unique_ptr<Block> block) {
  Entry e;
  e.full_name = name_ + "." + name;
  e.name = std::move(name);
  e.block = std::move(block);
  blocks_.push_back(std::move(e));
  return *blocks_.back().block;
}

Block* Program::find(std::string_view block_name) const {
  for (const Entry& e : blocks_) {
    if (e.name == block_name) {
      return e.block.get();
    }
  }
  return nullptr;
}

BlockStatus Program::run(const CycleContext& ctx) noexcept {
  BlockStatus worst = BlockStatus::kOk;
  for (Entry& e : blocks_) {
    const BlockStatus s = e.block->update(ctx);
    if (s == BlockStatus::kFault) {
      if (e.last != BlockStatus::kFault) {
        // A C++ PROGRAM names the child that raised the fault ("cnc.job.drill.gap").
        const char* inner = e.block->fault_source();
        e.fault_source = inner != nullptr ? inner : e.full_name.c_str();
        const FaultCause why = e.block->fault_cause();
        Alarm a;
        a.code = AlarmCode::kBlockFault;
        a.severity = AlarmSeverity::kFault;
        a.time = ctx.release;
        a.source = e.fault_source;
        a.text = why.text != nullptr ? why.text : "block reported a fault (it gave no cause)";
        a.value = why.value;
        machine_->raise(a);
      }
      worst = BlockStatus::kFault;
    } else {
      if (e.last == BlockStatus::kFault) {
        machine_->clear_alarm(AlarmCode::kBlockFault, e.fault_source);
      }
      if (s == BlockStatus::kSaturated && worst == BlockStatus::kOk) {
        worst = BlockStatus::kSaturated;
      }
    }
    e.last = s;
  }
  return worst;
}

void Program::enter_safe_state(const SafeStateRequest& request) noexcept {
  for (Entry& e : blocks_) {
    e.block->enter_safe_state(request);
  }
}

void Program::activate() noexcept {
  for (Entry& e : blocks_) {
    e.block->activate();
    e.last = BlockStatus::kOk;
  }
}

}  // namespace edm::rt
