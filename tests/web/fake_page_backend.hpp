#pragma once
// A PageBackend (hmi/include/edm/hmi/web_command.hpp) without edmplc: every call is recorded and
// answered from the arguments, so a test or the fuzz target (tests/fuzz/fuzz_page.cpp) can check
// what a command reached and how its reply came back. `throw_next` makes the next call throw.
//
// Not thread-safe (one test thread).

#include <stdexcept>
#include <string>
#include <vector>

#include "edm/hmi/web_command.hpp"

namespace edm::hmi::test {

class FakePageBackend : public PageBackend {
 public:
  using Json = bridge::Json;

  std::vector<std::string> calls;  // "relay:estop", "check", …
  Json last_params;
  bool throw_next{false};
  bool throw_non_std{false};

  Json relay(std::string_view op, const Json& params) override {
    hit("relay:" + std::string(op));
    last_params = params;
    return {{"ok", true}, {"body", {{"op", op}, {"params", params}}}};
  }
  Json check(const std::string& text, const std::string& name) override {
    hit("check");
    return {{"ok", true}, {"blocks", text.size()}, {"name", name}};
  }
  Json upload(const std::string& text, const std::string& name) override {
    hit("upload");
    return {{"ok", true}, {"blocks", text.size()}, {"name", name}};
  }
  Json start_job(bool dry_run) override {
    hit("start");
    return {{"ok", true}, {"body", {{"dry_run", dry_run}}}};
  }
  Json start_from(std::int32_t line, std::optional<double> depth, bool dry_run) override {
    hit("start_from");
    return {{"ok", true},
            {"line", line},
            {"depth", depth ? Json(*depth) : Json()},
            {"dry_run", dry_run}};
  }
  Json mdi(const std::string& line) override {
    hit("mdi");
    return {{"ok", true}, {"line", line}};
  }
  Json jog_hold(std::uint64_t owner, const std::string& axis, double v) override {
    hit("jog_hold");
    return {{"ok", true}, {"body", {{"owner", owner}, {"axis", axis}, {"velocity", v}}}};
  }
  void jog_stop_hold() override { hit("jog_stop_hold"); }
  void jog_release(std::uint64_t) override { hit("jog_release"); }
  Json touch(const std::string& target, const std::string& set) override {
    hit("touch");
    return {{"ok", true}, {"body", {{"target", target}, {"set", set}}}};
  }
  Json offset_set(const Json& params) override {
    hit("offset_set");
    last_params = params;
    return {{"ok", true}, {"body", params}};
  }
  void acknowledge(std::uint64_t) override { hit("ack"); }
  Json manual_status() override {
    hit("manual_status");
    return Json{{"mode", "idle"}};
  }
  Json offsets() override {
    hit("offsets");
    return nullptr;  // an edmplc without offset.get
  }
  Json job_snapshot() override {
    hit("job");
    return {{"part", "p.nc"}, {"text", std::string("\xff\xfe bad utf-8")}};
  }
  Json stats() override {
    hit("stats");
    return {{"ok", true}, {"body", Json::object()}};
  }
  Json queue_add(const QueueItem& item) override {
    hit("queue_add " + item.part + " x" + std::to_string(item.repeat));
    return {{"ok", true}};
  }
  Json queue_control(std::string_view action) override {
    hit("queue " + std::string(action));
    return {{"ok", true}};
  }
  Json queue_snapshot() override {
    hit("queue");
    return Json::object();
  }
  Json condition_set(const Json& params) override {
    hit("condition_set " + params.dump());
    return {{"ok", true}};
  }
  Json electrode_measure(const std::string& reference, const std::string& frame) override {
    hit("electrode_measure " + reference + " " + frame);
    return {{"ok", true}};
  }

 private:
  void hit(std::string what) {
    calls.push_back(std::move(what));
    if (throw_non_std) {
      throw_non_std = false;
      throw 42;
    }
    if (throw_next) {
      throw_next = false;
      throw std::runtime_error("backend failure");
    }
  }
};

}  // namespace edm::hmi::test
