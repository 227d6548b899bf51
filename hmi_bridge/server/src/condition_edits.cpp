// The retained condition edits (condition_edits.hpp).
#include "condition_edits.hpp"

#include <spdlog/spdlog.h>

#include <filesystem>

#include "edm/bridge/codec.hpp"
#include "edm/machining/bounded_read.hpp"
#include "edm/runtime/log_escape.hpp"
#include "edm/runtime/retain.hpp"
#include "edm/runtime/runtime.hpp"

namespace edm::bridge {

void ConditionEdits::load_and_apply(rt::Runtime& rt) {
  std::error_code ec;
  if (path_.empty() || !std::filesystem::exists(path_, ec)) return;
  std::map<std::pair<int, std::string>, double> read;
  try {
    // The project's bounded reader: a regular file of at most 1 MiB, never read further.
    const machining::BoundedRead file =
        machining::read_bounded_file(path_, kMaxFileBytes, "condition edit file");
    if (!file.ok()) throw std::runtime_error(file.problem);
    const Json doc = Json::parse(file.text);
    if (doc.at("format") != kFormat) throw std::runtime_error("not a condition edit file");
    for (const Json& j : doc.at("edits")) {
      read[{j.at("E").get<int>(), j.at("field").get<std::string>()}] = j.at("value").get<double>();
    }
  } catch (const std::exception& e) {
    spdlog::warn(
        "bridge: the condition edits '{}' could not be read ({}): set aside as '{}.bad', "
        "the config's conditions are used",
        path_, e.what(), path_);
    std::filesystem::rename(path_, path_ + ".bad", ec);
    return;
  }
  for (const auto& [key, value] : read) {
    if (auto why = rt.set_condition_field(key.first, key.second, value)) {
      spdlog::warn("bridge: a retained condition edit is dropped: E{} {} = {}: {}", key.first,
                   rt::log_quote(key.second), value, rt::log_quote(*why));
      continue;
    }
    edits_[key] = value;
    spdlog::info("bridge: condition E{} {} = {} (an operator's edit, retained)", key.first,
                 key.second, value);  // an allowed field: one of the config's names
  }
  if (edits_.size() != read.size()) save();
}

std::optional<std::string> ConditionEdits::set(rt::Runtime& rt, int e, const std::string& field,
                                               double value) {
  if (auto why = rt.set_condition_field(e, field, value)) return why;
  edits_[{e, field}] = value;
  save();
  return std::nullopt;
}

bool ConditionEdits::save() {
  if (path_.empty()) return true;
  Json list = Json::array();
  for (const auto& [key, value] : edits_) {
    list.push_back({{"E", key.first}, {"field", key.second}, {"value", value}});
  }
  try {
    rt::write_file_atomic(path_, Json{{"format", kFormat}, {"edits", list}}.dump(1) + "\n");
    write_failed_ = false;
    return true;
  } catch (const std::exception& ex) {
    spdlog::warn("bridge: the condition edits could not be written: {}", ex.what());
    write_failed_ = true;
    return false;
  }
}

}  // namespace edm::bridge
