// edmhmi home [AXES] | jog AXIS DIST | jog AXIS --velocity V [--for S] | touch TARGET [--set G5x]
// — the operator's manual functions (docs/hmi.md). The runtime moves the axes under its safety
// supervisor; edmhmi sends the op and follows manual.status every 50 ms until it is done.
#include <chrono>
#include <cstdio>
#include <thread>

#include "cli.hpp"
#include "edm/hmi/job_runner.hpp"
#include "edm/hmi/manual.hpp"

namespace edmhmi {

namespace {

using edm::bridge::Json;
using edm::bridge::Reply;
using Clock = std::chrono::steady_clock;

/// The seq of the last finished manual operation before ours (nullopt: none yet), so the wait
/// cannot take an older result for ours. Prints and returns false when manual.status fails.
bool seq_before(edm::bridge::Client& client, std::optional<std::uint64_t>& seq) {
  const Reply r = client.request("manual.status");
  if (!r) {
    report_error("manual.status", r);
    return false;
  }
  edm::hmi::ManualStatus s;
  std::string error;
  if (!edm::hmi::manual_status_from_json(r.body, s, error)) {
    std::fprintf(stderr, "edmhmi: manual.status: malformed reply: %s\n", error.c_str());
    return false;
  }
  seq = s.result ? std::optional(s.result->seq) : std::nullopt;
  return true;
}

/// Waits for the operation to end and prints its result. An interrupt sends jog.stop (the
/// runtime's stop of a manual motion) and waits for the stop. Returns the exit code and, through
/// `result`, what the runtime reported.
int finish(edm::bridge::Client& client, std::optional<std::uint64_t> seq,
           std::optional<edm::hmi::ManualResult>* result = nullptr) {
  edm::hmi::ManualWait w = edm::hmi::wait_manual(client, seq, interrupted());
  if (w.interrupted) {
    const Reply stop = client.request("jog.stop");
    std::fprintf(stderr, "edmhmi: interrupted: jog.stop %s\n",
                 stop ? "sent" : ("refused: " + stop.message).c_str());
    static const std::atomic<bool> kNever{false};
    w = edm::hmi::wait_manual(client, seq, kNever, std::chrono::milliseconds(50),
                              std::chrono::seconds(10));
    if (w.done) std::printf("%s\n", edm::hmi::format_manual_result(*w.status.result).c_str());
    return kExitInterrupted;
  }
  if (!w.done) {
    std::fprintf(stderr, "edmhmi: %s\n", w.error.c_str());
    return kExitFailure;
  }
  std::printf("%s\n", edm::hmi::format_manual_result(*w.status.result).c_str());
  std::fflush(stdout);
  if (result != nullptr) *result = w.status.result;
  return w.status.result->ok ? kExitOk : kExitFailure;
}

int continuous_jog(edm::bridge::Client& client, char axis, double velocity, double for_s,
                   std::optional<std::uint64_t> seq) {
  double deadman_ms = 500.0;  // a runtime that does not say: refresh often enough for any
  if (const Reply info = client.request("machine.info"); info) {
    const auto manual = info.body.find("manual");
    if (manual != info.body.end() && manual->is_object()) {
      deadman_ms = manual->value("deadman_ms", deadman_ms);
    }
  }
  const auto period = edm::hmi::jog_refresh_period(deadman_ms);
  const Json params = {{"axis", std::string(1, axis)}, {"velocity", velocity}};
  Reply r = client.request("jog", params);
  if (!r) return report_error("jog", r);
  std::fprintf(stderr, "edmhmi: jogging %c at %g mm/s%s (refreshed every %lld ms; Ctrl-C stops)\n",
               axis, velocity, for_s > 0.0 ? (" for " + std::to_string(for_s) + " s").c_str() : "",
               static_cast<long long>(period.count()));
  const Clock::time_point t0 = Clock::now();
  Clock::time_point next = t0 + period;
  int code = kExitOk;
  for (;;) {
    if (interrupted().load()) break;
    if (for_s > 0.0 && std::chrono::duration<double>(Clock::now() - t0).count() >= for_s) break;
    std::this_thread::sleep_until(next);  // the dead-man refresh deadline
    next += period;
    r = client.request("jog", params);
    if (!r) {  // e.g. a soft limit reached, an alarm: the runtime has stopped the axis
      code = report_error("jog", r);
      break;
    }
  }
  const Reply stop = client.request("jog.stop");
  if (!stop) report_error("jog.stop", stop);
  static const std::atomic<bool> kNever{false};
  const edm::hmi::ManualWait w = edm::hmi::wait_manual(client, seq, kNever);
  if (!w.done) {
    std::fprintf(stderr, "edmhmi: %s\n", w.error.c_str());
    return kExitFailure;
  }
  std::printf("%s\n", edm::hmi::format_manual_result(*w.status.result).c_str());
  if (code == kExitOk && !w.status.result->ok) code = kExitFailure;
  return interrupted().load() && code == kExitOk ? kExitOk : code;
}

}  // namespace

int cmd_home(const HomeArgs& args, const edm::hmi::ConnectionSettings& settings) {
  Json params = Json::object();
  if (!args.axes.empty()) {
    std::string error;
    params["axes"] = edm::hmi::normalise_axes(args.axes, error);
    if (!error.empty()) return usage("home: " + error);
  }
  edm::bridge::Client client;
  if (!connect(client, settings)) return kExitFailure;
  std::optional<std::uint64_t> seq;
  if (!seq_before(client, seq)) return kExitFailure;
  const Reply r = client.request("home", params);
  if (!r) return report_error("home", r);
  std::fprintf(stderr, "edmhmi: homing %s\n",
               r.body.value("axes", params.value("axes", std::string("XYZ"))).c_str());
  return finish(client, seq);
}

int cmd_jog(const JogArgs& args, const edm::hmi::ConnectionSettings& settings) {
  const std::optional<char> axis = edm::hmi::parse_axis(args.axis);
  if (!axis) return usage("jog: '" + args.axis + "' is not an axis (X, Y or Z)");
  if (args.distance.has_value() == args.velocity.has_value()) {
    return usage("jog: give either DIST (mm) or --velocity V (mm/s)");
  }
  if (args.distance && !edm::hmi::valid_jog_distance(*args.distance)) {
    char buf[48];
    std::snprintf(buf, sizeof buf, "%g", *args.distance);
    return usage("jog: " + std::string(buf) +
                 " mm: an incremental jog is 0.001..10 mm in magnitude");
  }
  if (args.velocity && *args.velocity == 0.0) return usage("jog: --velocity must not be 0");
  if (args.for_s > 0.0 && !args.velocity) return usage("jog: --for goes with --velocity");
  edm::bridge::Client client;
  if (!connect(client, settings)) return kExitFailure;
  std::optional<std::uint64_t> seq;
  if (!seq_before(client, seq)) return kExitFailure;
  if (args.velocity) return continuous_jog(client, *axis, *args.velocity, args.for_s, seq);
  const Reply r =
      client.request("jog", {{"axis", std::string(1, *axis)}, {"distance", *args.distance}});
  if (!r) return report_error("jog", r);
  return finish(client, seq);
}

int cmd_touch(const TouchArgs& args, const edm::hmi::ConnectionSettings& settings) {
  const std::optional<edm::hmi::TouchTarget> target = edm::hmi::parse_touch_target(args.target);
  if (!target) return usage("touch: '" + args.target + "': targets are z, x+, x-, y+, y-, center");
  std::string frame;
  if (!args.set_frame.empty()) {
    const std::optional<int> i = edm::hmi::frame_index(args.set_frame);
    if (!i) return usage("touch: --set '" + args.set_frame + "': work frames are G54..G59");
    frame = edm::hmi::frame_name(*i);
  }
  edm::bridge::Client client;
  if (!connect(client, settings)) return kExitFailure;
  std::optional<std::uint64_t> seq;
  if (!seq_before(client, seq)) return kExitFailure;
  const Reply r = client.request("touch", {{"target", std::string(edm::hmi::to_string(*target))}});
  if (!r) return report_error("touch", r);
  std::optional<edm::hmi::ManualResult> result;
  const int code = finish(client, seq, &result);
  if (code != kExitOk || frame.empty()) return code;
  const std::optional<Json> set = edm::hmi::offset_set_for_touch(frame, *target, *result);
  if (!set) {
    std::fprintf(stderr, "edmhmi: touch %s: the result has no coordinate to set %s from\n",
                 std::string(edm::hmi::to_string(*target)).c_str(), frame.c_str());
    return kExitFailure;
  }
  const Reply s = client.request("offset.set", *set);
  if (!s) return report_error("offset.set", s);
  const edm::machining::Vec3 v{s.body.value("x", 0.0), s.body.value("y", 0.0),
                               s.body.value("z", 0.0)};
  std::printf("offset.set: %s (generation %llu)\n",
              edm::hmi::format_frame(*edm::hmi::frame_index(frame), v).c_str(),
              static_cast<unsigned long long>(s.body.value("generation", std::uint64_t{0})));
  return kExitOk;
}

}  // namespace edmhmi
