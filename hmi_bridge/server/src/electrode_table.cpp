#include "electrode_table.hpp"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <system_error>

#include "edm/runtime/retain.hpp"

namespace edm::bridge {
namespace {

using Json = nlohmann::json;

constexpr std::size_t kMaxFileBytes = 4u << 20;  // a table of its cap is far smaller
constexpr const char* kFormat = "edmplc electrodes 1";

bool printable(const std::string& s) {
  return std::all_of(s.begin(), s.end(), [](char c) { return c >= 0x20 && c < 0x7f; });
}

double positive(const Json& j, const char* key, double max) {
  const double v = j.at(key).get<double>();
  if (!std::isfinite(v) || v < 0.0 || v > max) {
    throw std::runtime_error(std::string("'") + key + "' out of range");
  }
  return v;
}

}  // namespace

std::optional<double> ElectrodeEntry::measured_wear_ratio() const noexcept {
  if (!(measured_length_mm > 0.0) || !(drilled_at_measure_mm > 0.0)) return std::nullopt;
  return (new_length_mm - measured_length_mm) / drilled_at_measure_mm;
}

std::optional<double> ElectrodeEntry::estimated_wear_ratio() const noexcept {
  if (!(drilled_mm > 0.0)) return std::nullopt;
  return (new_length_mm - length_mm) / drilled_mm;
}

std::string ElectrodeTable::invalid_id(const std::string& id) {
  const bool ok = !id.empty() && id.size() <= 32 && std::all_of(id.begin(), id.end(), [](char c) {
    return std::isalnum(static_cast<unsigned char>(c)) != 0 || c == '.' || c == '_' || c == '-';
  });
  return ok ? "" : "'electrode' (its id) must be 1 to 32 of A-Z a-z 0-9 . _ -";
}

std::string ElectrodeTable::invalid_kind(const std::string& kind) {
  return kind == "round" || kind == "tube" || kind == "rect"
             ? ""
             : "'kind' must be \"round\", \"tube\" or \"rect\"";
}

std::string ElectrodeTable::invalid_material(const std::string& m) {
  return !m.empty() && m.size() <= 32 && printable(m)
             ? ""
             : "'material' must be 1 to 32 printable ASCII characters (copper, graphite, CuW, …)";
}

ElectrodeTable::ElectrodeTable(std::string path) : path_(std::move(path)) {
  if (!path_.empty()) load();
}

const ElectrodeEntry* ElectrodeTable::find(const std::string& id) const noexcept {
  for (const ElectrodeEntry& e : entries_) {
    if (e.id == id) return &e;
  }
  return nullptr;
}

const ElectrodeEntry* ElectrodeTable::current() const noexcept {
  return current_.empty() ? nullptr : find(current_);
}

ElectrodeEntry* ElectrodeTable::mutable_current() noexcept {
  return const_cast<ElectrodeEntry*>(current());
}

bool ElectrodeTable::change(const ElectrodeEntry& e, double previous_length_mm,
                            const std::string& when) {
  if (find(e.id) == nullptr && entries_.size() >= kCap) return false;
  if (ElectrodeEntry* prev = mutable_current()) prev->length_mm = previous_length_mm;
  auto it = std::find_if(entries_.begin(), entries_.end(),
                         [&](const ElectrodeEntry& x) { return x.id == e.id; });
  if (it == entries_.end()) {
    entries_.push_back(e);
    it = entries_.end() - 1;
  } else {
    it->kind = e.kind;
    it->size_mm = e.size_mm;
    it->material = e.material;
    if (e.new_length_mm > 0.0) it->new_length_mm = e.new_length_mm;
    if (e.length_mm > 0.0) it->length_mm = e.length_mm;
    it->unmeasured = e.unmeasured;
  }
  it->changed = when;
  current_ = e.id;
  return true;
}

void ElectrodeTable::add_job(const std::string& id, std::int64_t holes, double drilled_mm,
                             double length_mm) {
  auto it = std::find_if(entries_.begin(), entries_.end(),
                         [&](const ElectrodeEntry& x) { return x.id == id; });
  if (it == entries_.end()) return;
  if (holes > 0) it->holes += holes;
  if (std::isfinite(drilled_mm) && drilled_mm > 0.0) it->drilled_mm += drilled_mm;
  if (length_mm > 0.0 && id == current_) it->length_mm = length_mm;
}

void ElectrodeTable::measured(double length_mm) {
  ElectrodeEntry* c = mutable_current();
  if (c == nullptr) return;
  c->length_mm = length_mm;
  c->measured_length_mm = length_mm;
  c->drilled_at_measure_mm = c->drilled_mm;
  c->unmeasured = false;
  // A new electrode's first measurement is its new length: the table had only what was typed.
  if (c->drilled_mm <= 0.0) c->new_length_mm = length_mm;
}

void ElectrodeTable::set_length(double length_mm) {
  if (ElectrodeEntry* c = mutable_current()) c->length_mm = length_mm;
}

Json to_json(const ElectrodeEntry& e) {
  return {{"id", e.id},
          {"kind", e.kind},
          {"size_mm", e.size_mm},
          {"material", e.material},
          {"new_length_mm", e.new_length_mm},
          {"length_mm", e.length_mm},
          {"holes", e.holes},
          {"drilled_mm", e.drilled_mm},
          {"measured_length_mm", e.measured_length_mm},
          {"drilled_at_measure_mm", e.drilled_at_measure_mm},
          {"changed", e.changed},
          {"unmeasured", e.unmeasured}};
}

bool ElectrodeTable::save() const {
  if (path_.empty()) return true;
  Json list = Json::array();
  for (const ElectrodeEntry& e : entries_) list.push_back(to_json(e));
  const Json doc{{"format", kFormat}, {"current", current_}, {"electrodes", std::move(list)}};
  try {
    rt::write_file_atomic(path_, doc.dump(1) + "\n");
    return true;
  } catch (const std::exception& ex) {
    spdlog::warn("bridge: the electrode table could not be written: {}", ex.what());
    return false;
  }
}

void ElectrodeTable::load() {
  std::error_code ec;
  if (!std::filesystem::exists(path_, ec)) return;
  try {
    // Sized before it is read: a huge file put there is refused, never read into memory.
    const auto bytes = std::filesystem::file_size(path_, ec);
    if (ec || bytes > kMaxFileBytes) throw std::runtime_error("larger than 4 MiB, or unreadable");
    std::ifstream in(path_, std::ios::binary);
    std::ostringstream ss;
    ss << in.rdbuf();
    const Json doc = Json::parse(ss.str());
    if (doc.at("format") != kFormat) throw std::runtime_error("not an electrode table");
    std::vector<ElectrodeEntry> entries;
    for (const Json& j : doc.at("electrodes")) {
      ElectrodeEntry e;
      e.id = j.at("id").get<std::string>();
      e.kind = j.at("kind").get<std::string>();
      e.material = j.at("material").get<std::string>();
      if (!invalid_id(e.id).empty() || !invalid_kind(e.kind).empty() ||
          !invalid_material(e.material).empty() || entries.size() >= kCap ||
          std::any_of(entries.begin(), entries.end(),
                      [&](const ElectrodeEntry& x) { return x.id == e.id; })) {
        throw std::runtime_error("an invalid entry");
      }
      e.size_mm = positive(j, "size_mm", 1e4);
      e.new_length_mm = positive(j, "new_length_mm", 1e4);
      e.length_mm = positive(j, "length_mm", 1e4);
      e.holes = j.at("holes").get<std::int64_t>();
      e.drilled_mm = positive(j, "drilled_mm", 1e9);
      e.measured_length_mm = positive(j, "measured_length_mm", 1e4);
      e.drilled_at_measure_mm = positive(j, "drilled_at_measure_mm", 1e9);
      e.changed = j.at("changed").get<std::string>();
      e.unmeasured = j.at("unmeasured").get<bool>();
      if (e.holes < 0 || e.changed.size() > 40 || !printable(e.changed)) {
        throw std::runtime_error("an invalid entry");
      }
      entries.push_back(std::move(e));
    }
    entries_ = std::move(entries);
    current_ = doc.at("current").get<std::string>();
    if (!current_.empty() && find(current_) == nullptr) current_.clear();
  } catch (const std::exception& e) {
    entries_.clear();
    current_.clear();
    load_error_ = "the electrode table '" + path_ + "' could not be read (" + e.what() +
                  "): set aside as '" + path_ + ".bad', a new table begins";
    std::filesystem::rename(path_, path_ + ".bad", ec);
    spdlog::warn("bridge: {}", load_error_);
  }
}

}  // namespace edm::bridge
