// edmhmi queue PART.nc[*N[@DX,DY]] … — run part programs one after the other, each N times (each
// run DX,DY further), without an operator between them; stop before a hole the electrode cannot
// finish and go on once it is changed and measured (job_queue.hpp, docs/hmi.md "A job queue").
#include <cmath>
#include <cstdio>
#include <cstdlib>

#include "cli.hpp"
#include "edm/hmi/job_queue.hpp"
#include "edm/hmi/job_report.hpp"

namespace edmhmi {
namespace {

/// "part.nc" → 1 run, "part.nc*3" → 3, "part.nc*3@10,0" → 3 runs, each 10 mm further in X (a
/// name that itself ends in *N is given as "part*N*1").
bool parse_item(const std::string& word, edm::hmi::QueueItem& item) {
  item.part = word;
  item.repeat = 1;
  std::string spec = word;
  if (const auto at = spec.rfind('@'); at != std::string::npos && spec.rfind('*') < at) {
    const std::string step = spec.substr(at + 1);
    char* end = nullptr;
    item.step_x_mm = std::strtod(step.c_str(), &end);
    const bool comma = *end == ',';
    if (comma) item.step_y_mm = std::strtod(end + 1, &end);
    if (!comma || *end != '\0' || step.empty() || !std::isfinite(item.step_x_mm) ||
        !std::isfinite(item.step_y_mm)) {
      std::fprintf(stderr, "edmhmi: queue: '%s': the step after '@' is DX,DY in mm\n",
                   word.c_str());
      return false;
    }
    spec = spec.substr(0, at);
  }
  if (const auto star = spec.rfind('*'); star != std::string::npos && star + 1 < spec.size()) {
    char* end = nullptr;
    const long n = std::strtol(spec.c_str() + star + 1, &end, 10);
    if (*end != '\0' || n < 1 || n > 10000) {
      std::fprintf(stderr, "edmhmi: queue: '%s': the count after '*' must be 1..10000\n",
                   word.c_str());
      return false;
    }
    item.part = spec.substr(0, star);
    item.repeat = static_cast<int>(n);
  }
  return read_text_file(item.part, item.text);
}

}  // namespace

int cmd_queue(const std::vector<std::string>& words, const edm::hmi::ConnectionSettings& settings) {
  std::vector<edm::hmi::QueueItem> items;
  for (const std::string& w : words) {
    edm::hmi::QueueItem item;
    if (!parse_item(w, item)) return kExitBadInput;
    items.push_back(std::move(item));
  }
  edm::bridge::Client client;
  if (!connect(client, settings)) return kExitFailure;
  edm::hmi::QueueCallbacks cb;
  cb.run.alarm = [](const std::string& a) { std::fprintf(stderr, "ALARM %s\n", a.c_str()); };
  cb.run.note = [](const std::string& n) { std::fprintf(stderr, "edmhmi: %s\n", n.c_str()); };
  cb.note = [](const std::string& n) { std::fprintf(stderr, "edmhmi: queue: %s\n", n.c_str()); };
  std::size_t n = 0;
  cb.job_done = [&n](const edm::hmi::QueueJob& j) {
    ++n;
    std::printf("== job %zu: %s run %d%s%s\n", n, j.part.c_str(), j.run,
                j.from_line > 0 ? (" from line " + std::to_string(j.from_line)).c_str() : "",
                j.before_line > 0 ? (" up to line " + std::to_string(j.before_line)).c_str() : "");
    std::fputs(edm::hmi::format_report(j.result.report).c_str(), stdout);
    std::fflush(stdout);
  };
  edm::hmi::QueueResult r;
  try {
    r = edm::hmi::run_queue(client, items, cb, interrupted());
  } catch (const edm::bridge::ClientError& e) {
    std::fprintf(stderr, "edmhmi: queue: %s\n", e.what());
    return kExitFailure;
  }
  std::printf("queue: %zu jobs%s\n", r.jobs.size(), r.ok ? ", every one finished" : "");
  if (!r.ok) {
    std::fprintf(stderr, "edmhmi: queue stopped: %s\n", r.message.c_str());
    return interrupted().load() ? kExitInterrupted : kExitFailure;
  }
  return kExitOk;
}

}  // namespace edmhmi
