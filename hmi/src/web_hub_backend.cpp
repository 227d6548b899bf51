// The hub as the page's command backend (web_command.hpp): each command through the job, the
// manual functions or the one bridge session to edmplc.
#include "edm/hmi/web_hub.hpp"

namespace edm::hmi {

using bridge::Json;

Json WebHub::relay(std::string_view op, const Json& params) {
  return page_reply(client_.request(op, params));
}

Json WebHub::check(const std::string& text, const std::string& name) {
  return job_.check(text, name);
}

Json WebHub::upload(const std::string& text, const std::string& name) {
  return job_.upload(text, name);
}

Json WebHub::start_job(bool dry_run) { return page_reply(job_.start(dry_run)); }

Json WebHub::start_from(std::int32_t line, std::optional<double> depth_done_mm, bool dry_run) {
  return job_.start_from(line, depth_done_mm, dry_run);
}

Json WebHub::mdi(const std::string& line) { return job_.mdi(line); }

Json WebHub::jog_hold(std::uint64_t owner, const std::string& axis, double velocity_mm_s) {
  return manual_.hold(owner, axis, velocity_mm_s);
}

void WebHub::jog_stop_hold() { manual_.release_any(); }

void WebHub::jog_release(std::uint64_t owner) { manual_.release(owner); }

Json WebHub::touch(const std::string& target, const std::string& set_frame) {
  return manual_.touch(target, set_frame);
}

Json WebHub::offset_set(const Json& params) { return manual_.offset_set(params); }

void WebHub::acknowledge(std::uint64_t seq) { acknowledge_alarms(seq); }

Json WebHub::manual_status() { return manual_.manual_json(); }

Json WebHub::offsets() { return manual_.offsets_json(); }

Json WebHub::job_snapshot() { return job_.snapshot(); }

Json WebHub::queue_add(const QueueItem& item) {
  Json c =
      job_.check(item.text, item.part);  // against the machine's tables, with its errors located
  if (!c.value("ok", false)) {
    if (!c.contains("code")) {
      c["code"] = "bad_program";
      c["message"] =
          std::to_string(c.value("errors", Json::array()).size()) + " error(s) in the program";
    }
    c["ok"] = false;
    return c;
  }
  return shift_.add(item);
}

Json WebHub::queue_control(std::string_view action) { return shift_.control(action); }

Json WebHub::queue_snapshot() { return shift_.snapshot(); }

Json WebHub::electrode_measure(const std::string& reference, const std::string& frame) {
  return shift_.measure(reference, frame);
}

Json WebHub::condition_set(const Json& params) {
  Json r = relay("condition.set", params);
  if (r.value("ok", false)) {
    std::string error;
    if (!job_.refresh_machine(error)) r["warning"] = "machine.info after the edit: " + error;
  }
  return r;
}

Json WebHub::stats() {
  Json r = page_reply(client_.request("tasks.stats"));
  const Counters c = counters();
  r["web"] = {{"frames", c.frames},
              {"browsers", c.browsers},
              {"frames_dropped", c.frames_dropped},
              {"slow_disconnects", c.slow_disconnects},
              {"reply_overflows", c.reply_overflows},
              {"login_failures", c.login_failures},
              {"bridge_connects", c.bridge_connects}};
  return r;
}

}  // namespace edm::hmi
