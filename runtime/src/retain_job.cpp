#include "retain_job.hpp"

#include <fmt/format.h>

#include <cmath>
#include <tuple>
#include <utility>

namespace edm::rt::retain_job {
namespace {

constexpr const char* kRunning = "job.running";
constexpr const char* kProgram = "job.program";
constexpr const char* kBlock = "job.block";
constexpr const char* kBlocks = "job.blocks";
constexpr const char* kLine = "job.line";
constexpr const char* kDepth = "job.depth_mm";
constexpr const char* kTouchZ = "job.touch_z_mm";
constexpr const char* kWear = "job.wear_mm";

}  // namespace

std::vector<RetainStore::Variable> variables(const JobStore& job,
                                             const std::optional<InterruptedJob>& kept,
                                             Readers readers) {
  // Until a job begins here, the interrupted record stays on disk.
  auto keep = [&job, &kept] { return kept.has_value() && job.progress().jobs_started == 0; };
  std::vector<RetainStore::Variable> out;
  out.push_back({kRunning, RetainType::kBool,
                 [&job, keep] { return RetainValue::make_bool(keep() || job.active()); },
                 /*urgent=*/true});
  out.push_back({kProgram, RetainType::kInt, [&job, &kept, keep] {
                   return RetainValue::make_int(keep() ? kept->program_id
                                                       : job.progress().program_id);
                 }});
  out.push_back({kBlock, RetainType::kInt, [&job, &kept, keep] {
                   return RetainValue::make_int(
                       keep() ? kept->block_index
                              : static_cast<std::int64_t>(job.progress().block_index));
                 }});
  out.push_back({kBlocks, RetainType::kInt, [&job, &kept, keep] {
                   return RetainValue::make_int(
                       keep() ? kept->block_count
                              : static_cast<std::int64_t>(job.progress().block_count));
                 }});
  out.push_back({kLine, RetainType::kInt, [&job, &kept, keep] {
                   return RetainValue::make_int(keep() ? kept->line : job.progress().line);
                 }});
  using Kept = std::optional<double> InterruptedJob::*;
  struct RealRecord {
    const char* name;
    std::function<double()>* read;
    Kept field;
  };
  for (const RealRecord& r : {RealRecord{kDepth, &readers.depth, &InterruptedJob::depth_mm},
                              RealRecord{kTouchZ, &readers.touch_z, &InterruptedJob::touch_z_mm},
                              RealRecord{kWear, &readers.wear, &InterruptedJob::wear_mm}}) {
    if (!*r.read) continue;
    out.push_back(
        {r.name, RetainType::kReal, [&kept, keep, f = std::move(*r.read), field = r.field] {
           return RetainValue::make_real(keep() ? ((*kept).*field).value_or(0.0) : f());
         }});
  }
  return out;
}

std::optional<InterruptedJob> take(RetainMap& values) {
  auto pop = [&values](const char* name) -> std::optional<RetainValue> {
    auto it = values.find(name);
    if (it == values.end()) return std::nullopt;
    RetainValue v = it->second;
    values.erase(it);
    return v;
  };
  const auto running = pop(kRunning);
  const auto program = pop(kProgram);
  const auto block = pop(kBlock);
  const auto blocks = pop(kBlocks);
  const auto line = pop(kLine);
  const auto depth = pop(kDepth);
  const auto touch_z = pop(kTouchZ);
  const auto wear = pop(kWear);
  if (!running || running->type != RetainType::kBool || !running->b) {
    return std::nullopt;
  }
  auto as_int = [](const std::optional<RetainValue>& v) -> std::int64_t {
    return v && v->type == RetainType::kInt ? v->i : 0;
  };
  InterruptedJob j;
  j.program_id = static_cast<std::uint32_t>(as_int(program));
  j.block_index = as_int(block);
  j.block_count = as_int(blocks);
  j.line = as_int(line);
  auto real = [](const std::optional<RetainValue>& v) -> std::optional<double> {
    if (v && v->type == RetainType::kReal && std::isfinite(v->r)) return v->r;
    return std::nullopt;
  };
  j.depth_mm = real(depth);
  j.touch_z_mm = real(touch_z);
  j.wear_mm = real(wear);
  return j;
}

std::string alarm_text(const InterruptedJob& j) {
  const std::string program =
      j.program_id != 0 ? fmt::format("program {:08x}", j.program_id) : "an unnamed program";
  const std::string depth =
      j.depth_mm ? fmt::format(", depth {:.3f} mm", *j.depth_mm) : std::string();
  return fmt::format(
      "job interrupted by an unclean stop: {}, block {} of {} (G-code line {}){}; the part "
      "program is not kept: check the work, reset, commit it again",
      program, j.block_index, j.block_count, j.line, depth);
}

}  // namespace edm::rt::retain_job
