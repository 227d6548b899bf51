#include "job_log.hpp"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <system_error>

#include "edm/runtime/retain.hpp"

namespace edm::bridge {
namespace {

constexpr std::size_t kMaxFileBytes = 16u << 20;  // a log of its cap is far smaller
constexpr std::size_t kFirstColumns = 17;         // the columns of the first version

std::string quoted(const std::string& s) {
  if (s.find_first_of(",\"\n\r") == std::string::npos) return s;
  std::string out = "\"";
  for (const char c : s) {
    if (c == '"') out += '"';
    out += c;
  }
  return out + "\"";
}

std::string number(double v) {
  char b[32];
  std::snprintf(b, sizeof b, "%.6g", v);
  return b;
}

// One CSV record (RFC 4180 quoting) from `in` at `at`; false at the end or on a malformed one.
bool read_record(const std::string& in, std::size_t& at, std::vector<std::string>& fields) {
  fields.clear();
  if (at >= in.size()) return false;
  std::string f;
  bool quoted_field = false;
  while (at < in.size()) {
    const char c = in[at++];
    if (quoted_field) {
      if (c != '"') {
        f += c;
      } else if (at < in.size() && in[at] == '"') {
        f += '"';
        ++at;
      } else {
        quoted_field = false;
      }
    } else if (c == '"' && f.empty()) {
      quoted_field = true;
    } else if (c == ',') {
      fields.push_back(std::move(f));
      f.clear();
    } else if (c == '\n') {
      break;
    } else if (c != '\r') {
      f += c;
    }
  }
  if (quoted_field) return false;
  fields.push_back(std::move(f));
  return true;
}

double to_double(const std::string& s) {
  std::size_t used = 0;
  const double v = std::stod(s, &used);
  if (used != s.size()) throw std::invalid_argument(s);
  return v;
}

}  // namespace

const std::vector<std::string>& JobLog::columns() {
  static const std::vector<std::string> kColumns = {"n",
                                                    "start",
                                                    "end",
                                                    "outcome",
                                                    "slot",
                                                    "dry_run",
                                                    "program",
                                                    "blocks_done",
                                                    "blocks",
                                                    "line",
                                                    "time_s",
                                                    "depth_mm",
                                                    "wear_mm",
                                                    "electrode_start_mm",
                                                    "electrode_end_mm",
                                                    "cause",
                                                    "alarms",
                                                    "electrode",
                                                    "holes"};
  return kColumns;
}

JobLog::JobLog(std::string path, std::size_t cap) : path_(std::move(path)), cap_(cap) {
  if (!path_.empty()) load();
}

void JobLog::load() {
  std::error_code ec;
  if (!std::filesystem::exists(path_, ec)) return;
  std::string text;
  // Sized before it is read: a huge file put there is refused, never read into memory.
  const auto bytes = std::filesystem::file_size(path_, ec);
  if (!ec && bytes <= kMaxFileBytes) {
    std::ifstream in(path_, std::ios::binary);
    std::ostringstream ss;
    ss << in.rdbuf();
    text = ss.str();
  }
  std::size_t at = 0;
  std::vector<std::string> f;
  try {
    if (ec || bytes > kMaxFileBytes) throw std::runtime_error("larger than 16 MiB, or unreadable");
    // A log written before the electrode and holes columns has the first 17 of them.
    if (!read_record(text, at, f) || f.size() < kFirstColumns || f.size() > columns().size() ||
        !std::equal(f.begin(), f.end(), columns().begin())) {
      throw std::runtime_error("not a job log");
    }
    const std::size_t width = f.size();
    while (read_record(text, at, f)) {
      if (f.size() == 1 && f[0].empty()) continue;
      if (f.size() != width) throw std::runtime_error("a row of the wrong width");
      JobLogEntry e;
      e.n = static_cast<std::uint64_t>(to_double(f[0]));
      e.start = f[1];
      e.end = f[2];
      e.outcome = f[3];
      e.slot = f[4];
      e.dry_run = f[5] == "1";
      e.program = f[6];
      e.blocks_done = static_cast<std::uint64_t>(to_double(f[7]));
      e.blocks = static_cast<std::uint64_t>(to_double(f[8]));
      e.line = static_cast<int>(to_double(f[9]));
      e.time_s = to_double(f[10]);
      e.depth_mm = to_double(f[11]);
      e.wear_mm = to_double(f[12]);
      e.electrode_start_mm = to_double(f[13]);
      e.electrode_end_mm = to_double(f[14]);
      e.cause = static_cast<int>(to_double(f[15]));
      e.alarms = f[16];
      if (width > 17) e.electrode = f[17];
      if (width > 18) e.holes = static_cast<std::int64_t>(to_double(f[18]));
      next_n_ = std::max(next_n_, e.n + 1);
      entries_.push_back(std::move(e));
      if (entries_.size() > cap_) entries_.pop_front();
    }
  } catch (const std::exception& e) {
    entries_.clear();
    next_n_ = 1;
    load_error_ = std::string("the job log '") + path_ + "' could not be read (" + e.what() +
                  "): set aside as '" + path_ + ".bad', a new log begins";
    std::filesystem::rename(path_, path_ + ".bad", ec);
    spdlog::warn("bridge: {}", load_error_);
  }
}

std::string JobLog::csv() const {
  std::string out;
  for (std::size_t i = 0; i < columns().size(); ++i) out += (i ? "," : "") + columns()[i];
  out += "\n";
  for (const JobLogEntry& e : entries_) {
    const std::string row[] = {std::to_string(e.n),
                               quoted(e.start),
                               quoted(e.end),
                               quoted(e.outcome),
                               quoted(e.slot),
                               e.dry_run ? "1" : "0",
                               quoted(e.program),
                               std::to_string(e.blocks_done),
                               std::to_string(e.blocks),
                               std::to_string(e.line),
                               number(e.time_s),
                               number(e.depth_mm),
                               number(e.wear_mm),
                               number(e.electrode_start_mm),
                               number(e.electrode_end_mm),
                               std::to_string(e.cause),
                               quoted(e.alarms),
                               quoted(e.electrode),
                               std::to_string(e.holes)};
    for (std::size_t i = 0; i < std::size(row); ++i) out += (i ? "," : "") + row[i];
    out += "\n";
  }
  return out;
}

bool JobLog::add(JobLogEntry e) {
  e.n = next_n_++;
  entries_.push_back(std::move(e));
  while (entries_.size() > cap_) entries_.pop_front();
  if (path_.empty()) return true;
  try {
    rt::write_file_atomic(path_, csv());
    return true;
  } catch (const std::exception& ex) {
    spdlog::warn("bridge: the job log could not be written: {}", ex.what());
    return false;
  }
}

}  // namespace edm::bridge
