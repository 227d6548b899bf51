// edmhmi home [AXES] | jog AXIS DIST | jog AXIS --velocity V [--for S] | touch TARGET [--set G5x]
// — the operator's manual functions (docs/hmi.md). The runtime moves the axes under its safety
// supervisor; edmhmi sends the op and follows manual.status every 50 ms until it is done.
#include <chrono>
#include <cstdio>
#include <thread>

#include "cli.hpp"
#include "edm/hmi/job_report.hpp"
#include "edm/hmi/manual.hpp"

namespace edmhmi {

namespace {

using edm::bridge::Json;
using edm::bridge::Reply;
using Clock = std::chrono::steady_clock;

const std::atomic<bool> kNever{false};

/// The request's sequence number from the op's reply; 0 (and a message) when it has none.
std::uint64_t request_seq(std::string_view op, const Reply& r) {
  const std::uint64_t seq = r.body.value("seq", std::uint64_t{0});
  if (seq == 0) {
    std::fprintf(stderr, "edmhmi: %s: the reply names no request seq; cannot follow it\n",
                 std::string(op).c_str());
  }
  return seq;
}

/// "position X .. Y .. Z .. (machine)" from the status, "" when it has none.
std::string position(edm::bridge::Client& client) {
  const Reply r = client.request("status");
  edm::bridge::StatusMessage s;
  std::string error;
  if (!r || !edm::bridge::from_json(r.body, s, error)) return "";
  const edm::hmi::JobFigures f = edm::hmi::figures_from_status(s);
  if (!f.x_mm || !f.y_mm || !f.z_mm) return "";
  return "position " + edm::hmi::format_xyz({*f.x_mm, *f.y_mm, *f.z_mm}) + " (machine)";
}

/// Prints the result of a finished wait (and where the axes are now); the exit code for it.
/// `stopped_ok`: an end by jog.stop is the expected end (a continuous jog).
int print_result(edm::bridge::Client& client, const edm::hmi::ManualWait& w,
                 bool stopped_ok = false) {
  if (!w.done) {
    std::fprintf(stderr, "edmhmi: %s\n", w.error.c_str());
    return kExitFailure;
  }
  const edm::hmi::ManualResult& r = *w.status.result;
  std::printf("%s\n", edm::hmi::format_manual_result(r).c_str());
  if (const std::string p = position(client); !p.empty()) std::printf("%s\n", p.c_str());
  std::fflush(stdout);
  return r.ok || (stopped_ok && r.error == edm::hmi::kStoppedByOperator) ? kExitOk : kExitFailure;
}

/// jog.stop, then waits (at most 10 s) until the runtime has taken it and ended the motion.
edm::hmi::ManualWait stop_and_wait(edm::bridge::Client& client, std::uint64_t result_from) {
  const Reply stop = client.request("jog.stop");
  if (!stop) {
    report_error("jog.stop", stop);
    edm::hmi::ManualWait w;
    w.error = "jog.stop refused: " + stop.message;
    return w;
  }
  return edm::hmi::wait_manual(client, stop.body.value("seq", result_from), result_from, kNever,
                               std::chrono::milliseconds(50), std::chrono::seconds(10));
}

/// Waits for request `seq` to end and prints its result. Ctrl-C sends jog.stop (it stops any
/// manual motion: home, jog, touch) and waits for the stop. `result` gets what the runtime said.
int finish(edm::bridge::Client& client, std::uint64_t seq,
           std::optional<edm::hmi::ManualResult>* result = nullptr) {
  const edm::hmi::ManualWait w = edm::hmi::wait_manual(client, seq, seq, interrupted());
  if (w.interrupted) {
    std::fprintf(stderr, "edmhmi: interrupted: sending jog.stop\n");
    const edm::hmi::ManualWait s = stop_and_wait(client, seq);
    if (s.done) print_result(client, s);
    return kExitInterrupted;
  }
  if (result != nullptr && w.done) *result = w.status.result;
  return print_result(client, w);
}

int continuous_jog(edm::bridge::Client& client, char axis, double velocity, double for_s) {
  const Json params = {{"axis", std::string(1, axis)}, {"velocity", velocity}};
  Reply r = client.request("jog", params);
  if (!r) return report_error("jog", r);
  const std::uint64_t first = request_seq("jog", r);
  if (first == 0) return kExitFailure;
  // Refreshed well inside the runtime's dead-man time: a dead edmhmi stops the axis there.
  const auto period = edm::hmi::jog_refresh_period(r.body.value("deadman_ms", 500.0));
  std::fprintf(
      stderr, "edmhmi: jogging %c at %g mm/s, refreshed every %lld ms; %s\n", axis, velocity,
      static_cast<long long>(period.count()),
      for_s > 0.0 ? ("stops after " + std::to_string(for_s) + " s").c_str() : "Ctrl-C stops");
  const Clock::time_point t0 = Clock::now();
  Clock::time_point next = t0 + period;
  int code = kExitOk;
  for (;;) {
    if (interrupted().load()) break;
    if (for_s > 0.0 && std::chrono::duration<double>(Clock::now() - t0).count() >= for_s) break;
    std::this_thread::sleep_until(next);  // the dead-man refresh deadline
    next += period;
    r = client.request("jog", params);
    if (!r) {  // e.g. the machine left READY: the runtime has stopped the axis
      code = report_error("jog", r);
      break;
    }
  }
  const int stopped = print_result(client, stop_and_wait(client, first), /*stopped_ok=*/true);
  return code != kExitOk ? code : stopped;
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
  const Reply r = client.request("home", params);
  if (!r) return report_error("home", r);
  const std::uint64_t seq = request_seq("home", r);
  if (seq == 0) return kExitFailure;
  std::fprintf(stderr, "edmhmi: homing %s\n", r.body.value("axes", std::string("?")).c_str());
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
  if (args.velocity) return continuous_jog(client, *axis, *args.velocity, args.for_s);
  const Reply r =
      client.request("jog", {{"axis", std::string(1, *axis)}, {"distance", *args.distance}});
  if (!r) return report_error("jog", r);
  const std::uint64_t seq = request_seq("jog", r);
  return seq == 0 ? kExitFailure : finish(client, seq);
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
  const Reply r = client.request("touch", {{"target", std::string(edm::hmi::to_string(*target))}});
  if (!r) return report_error("touch", r);
  const std::uint64_t seq = request_seq("touch", r);
  if (seq == 0) return kExitFailure;
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
