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

bool parse_positive(std::string_view text, double& out) {
  try {
    std::size_t used = 0;
    out = std::stod(std::string(text), &used);
    return used == text.size() && std::isfinite(out) && out > 0.0;
  } catch (const std::exception&) {
    return false;
  }
}

std::string value_text(const Json& v) {
  if (v.is_number_float()) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.6g", v.get<double>());
    return buf;
  }
  return v.dump();
}

}  // namespace

int cmd_watch(const Args& args, const edm::hmi::ConnectionSettings& settings) {
  double rate_hz = 5.0, count = 0.0;
  std::vector<std::string> names;
  for (std::size_t i = 0; i < args.size(); ++i) {
    if (args[i] == "--rate" || args[i] == "--count") {
      double* target = args[i] == "--rate" ? &rate_hz : &count;
      if (i + 1 >= args.size() || !parse_positive(args[i + 1], *target)) {
        return usage(std::string(args[i]) + " needs a positive number");
      }
      ++i;
    } else if (args[i].starts_with("--")) {
      return usage("watch: unknown option '" + std::string(args[i]) + "'");
    } else {
      names.emplace_back(args[i]);
    }
  }
  if (names.empty()) return usage("watch needs at least one variable");
  if (rate_hz > 100.0) return usage("watch: --rate is at most 100 Hz");
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

int cmd_trace(const Args& args, const edm::hmi::ConnectionSettings& settings) {
  std::string out_path;
  double duration_s = 0.0;
  std::vector<std::string> names;
  for (std::size_t i = 0; i < args.size(); ++i) {
    if (args[i] == "--out") {
      if (i + 1 >= args.size()) return usage("--out needs a file");
      out_path = std::string(args[++i]);
    } else if (args[i] == "--duration") {
      if (i + 1 >= args.size() || !parse_positive(args[i + 1], duration_s)) {
        return usage("--duration needs a positive number of seconds");
      }
      ++i;
    } else if (args[i].starts_with("--")) {
      return usage("trace: unknown option '" + std::string(args[i]) + "'");
    } else {
      names.emplace_back(args[i]);
    }
  }
  if (names.empty()) return usage("trace needs at least one variable");
  if (out_path.empty()) return usage("trace needs --out FILE.csv");
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
