// edmhmi watch VAR... | trace VAR... --out FILE.csv — variables live (docs/hmi.md).
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <cstdio>
#include <deque>
#include <fstream>
#include <mutex>
#include <thread>

#include "cli.hpp"

namespace edmhmi {

namespace {

using edm::bridge::Json;

std::string value_text(const Json& v) {
  if (v.is_number_float()) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.6g", v.get<double>());
    return buf;
  }
  return v.dump();
}

}  // namespace

int cmd_watch(const WatchArgs& args, const edm::hmi::ConnectionSettings& settings) {
  const double rate_hz = args.rate_hz, count = args.count;
  const std::vector<std::string>& names = args.names;
  edm::bridge::Client client;
  if (!connect(client, settings)) return kExitFailure;
  const auto period = std::chrono::duration<double>(1.0 / rate_hz);
  auto next = std::chrono::steady_clock::now();
  for (long n = 0; !interrupted().load() && (count <= 0.0 || n < static_cast<long>(count)); ++n) {
    const edm::bridge::Reply r = client.request("var.read", Json{{"names", names}});
    if (!r) return report_error("var.read", r);
    std::string line;
    for (const std::string& name : names) {
      line += name + "=" + value_text(r.body["values"].value(name, Json())) + "  ";
    }
    std::printf("%s\n", line.c_str());
    std::fflush(stdout);
    next += std::chrono::duration_cast<std::chrono::steady_clock::duration>(period);
    std::this_thread::sleep_until(next);  // pacing the display, not waiting for a thread
  }
  return kExitOk;
}

int cmd_trace(const TraceArgs& args, const edm::hmi::ConnectionSettings& settings) {
  const std::string& out_path = args.out_path;
  const double duration_s = args.duration_s;
  const std::vector<std::string>& names = args.names;
  std::ofstream csv(out_path);
  if (!csv) {
    std::fprintf(stderr, "%s: cannot write\n", out_path.c_str());
    return kExitBadInput;
  }

  edm::bridge::Client client;
  if (!connect(client, settings)) return kExitFailure;
  std::mutex m;
  std::condition_variable cv;
  std::deque<Json> events;
  client.set_event_handler([&](const Json& ev) {
    if (ev.value("event", std::string()) != "trace") return;
    std::lock_guard lock(m);
    events.push_back(ev);
    cv.notify_one();
  });
  const edm::bridge::Reply r = client.trace_start(names);
  if (!r) {
    client.set_event_handler(nullptr);
    return report_error("trace.start", r);
  }
  csv << "t_s,cycle";
  for (const std::string& n : names) csv << ',' << n;
  csv << '\n';
  // Each task streams its own rows; columns of variables of other tasks stay empty in its rows.
  std::uint64_t rows = 0, tap_dropped = 0;
  const auto t_end = std::chrono::steady_clock::now() +
                     std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                         std::chrono::duration<double>(duration_s));
  while (!interrupted().load() && (duration_s <= 0.0 || std::chrono::steady_clock::now() < t_end)) {
    std::deque<Json> batch;
    {
      std::unique_lock lock(m);
      cv.wait_for(lock, std::chrono::milliseconds(100), [&] { return !events.empty(); });
      batch.swap(events);
    }
    for (const Json& ev : batch) {
      const auto vars = ev.value("vars", std::vector<std::string>());
      std::vector<int> column(vars.size(), -1);
      for (std::size_t k = 0; k < vars.size(); ++k) {
        for (std::size_t c = 0; c < names.size(); ++c) {
          if (names[c] == vars[k]) column[k] = static_cast<int>(c);
        }
      }
      tap_dropped = std::max<std::uint64_t>(tap_dropped, ev.value("tap_dropped", 0ULL));
      for (const Json& row : ev.value("samples", Json::array())) {
        if (!row.is_array() || row.size() != vars.size() + 2) continue;
        std::vector<std::string> cells(names.size());
        for (std::size_t k = 0; k < vars.size(); ++k) {
          if (column[k] >= 0) cells[static_cast<std::size_t>(column[k])] = row[k + 2].dump();
        }
        // Every digit the machine sent (shortest round trip): %.6g would round t_s to 10 ms
        // after 1000 s of uptime and to whole seconds after a day.
        csv << row[0].dump() << ',' << row[1].dump();
        for (const std::string& c : cells) csv << ',' << c;
        csv << '\n';
        ++rows;
      }
    }
  }
  client.set_event_handler(nullptr);
  client.trace_stop();
  csv.flush();
  std::fprintf(stderr, "edmhmi: %llu rows to %s (tap dropped %llu)\n",
               static_cast<unsigned long long>(rows), out_path.c_str(),
               static_cast<unsigned long long>(tap_dropped));
  return csv ? kExitOk : kExitFailure;
}

}  // namespace edmhmi
