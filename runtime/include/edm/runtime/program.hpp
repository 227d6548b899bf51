#pragma once
// A program instance: an ordered network of block instances (IEC 61131-3 PROGRAM in FBD form).
//
// Evaluation order is the order of `blocks:` in the YAML (or of add() in C++): each block's
// update() runs once per cycle, in that order. A wire from a block that runs later (a wire
// "backwards") reads that block's value from the previous cycle — a one-cycle delay, which is
// how feedback loops are closed. C++ PROGRAM types (sequencers) are blocks too: a block class
// that owns and steps its own child blocks.
//
// Thread-safety: built non-RT, then run() only on the owning task's thread.

#include <memory>
#include <string>
#include <vector>

#include "edm/runtime/block.hpp"
#include "edm/runtime/machine.hpp"

namespace edm::rt {

class Program final : public SafeStateHandler {
 public:
  struct Entry {
    std::string name;       // block instance name
    std::string full_name;  // "program.block" (also the alarm source)
    std::unique_ptr<Block> block;
    BlockStatus last{BlockStatus::kOk};
    const char* fault_source{nullptr};  // alarm source of the running fault episode
  };

  Program(std::string name, Machine& machine) : name_(std::move(name)), machine_(&machine) {}
  Program(const Program&) = delete;
  Program& operator=(const Program&) = delete;

  /// Appends a block instance. Non-RT. Returns the block.
  Block& add(std::string name, std::unique_ptr<Block> block);
  [[nodiscard]] Block* find(std::string_view block_name) const;

  /// Runs every block once, in order. A block that starts returning kFault raises a
  /// kBlockFault alarm (once per fault episode), which puts the machine in FAULT. RT-safe.
  BlockStatus run(const CycleContext& ctx) noexcept;
  /// Forwards to every block, in order. RT-safe.
  void enter_safe_state(const SafeStateRequest& request) noexcept override;
  /// Calls activate() on every block. Non-RT.
  void activate() noexcept;

  [[nodiscard]] const std::string& name() const noexcept { return name_; }
  [[nodiscard]] const std::vector<Entry>& blocks() const noexcept { return blocks_; }

 private:
  std::string name_;
  Machine* machine_;
  std::vector<Entry> blocks_;
};

}  // namespace edm::rt
