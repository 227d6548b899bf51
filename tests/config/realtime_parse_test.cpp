// machine.realtime (rt_environment.hpp): defaults, every key, `off`, and errors at file:line:col.
// The bad-value cases with their exact locations are files in tests/configs/bad/realtime_*.yaml.

#include <gtest/gtest.h>

#include <string>

#include "edm/runtime/config.hpp"

namespace edm::rt {
namespace {

std::string rt_config_with(const std::string& realtime_lines) {
  return "version: 1\n"
         "machine:\n"
         "  name: m\n" +
         realtime_lines +
         "tasks:\n"
         "  - {name: fast, interval: 1ms, programs: [p]}\n"
         "programs:\n"
         "  - {name: p, blocks: []}\n";
}

// The first diagnostic of a config that must not parse, as "file:line:col: message".
std::string rt_first_error(const std::string& text) {
  try {
    parse_config_text(text, "rt.yaml");
  } catch (const ConfigError& e) {
    return e.diagnostics().front().str();
  }
  return "no error";
}

TEST(RealtimeConfig, absent_section_asks_for_zero_latency_on_the_kernel_device_and_locked_memory) {
  const Config cfg = parse_config_text(rt_config_with(""), "rt.yaml");
  ASSERT_TRUE(cfg.machine.realtime.pm_qos_latency_us.has_value());
  EXPECT_EQ(*cfg.machine.realtime.pm_qos_latency_us, 0);
  EXPECT_EQ(cfg.machine.realtime.pm_qos_device, "/dev/cpu_dma_latency");
  EXPECT_TRUE(cfg.machine.realtime.lock_memory);
}

TEST(RealtimeConfig, every_key_is_read) {
  const Config cfg = parse_config_text(rt_config_with("  realtime:\n"
                                                      "    pm_qos_latency: 20us\n"
                                                      "    pm_qos_device: /run/test/qos\n"
                                                      "    lock_memory: false\n"),
                                       "rt.yaml");
  ASSERT_TRUE(cfg.machine.realtime.pm_qos_latency_us.has_value());
  EXPECT_EQ(*cfg.machine.realtime.pm_qos_latency_us, 20);
  EXPECT_EQ(cfg.machine.realtime.pm_qos_device, "/run/test/qos");
  EXPECT_FALSE(cfg.machine.realtime.lock_memory);
  EXPECT_EQ(cfg.machine.realtime.loc.line, 5);
}

TEST(RealtimeConfig, latency_takes_any_unit_in_whole_microseconds) {
  const Config cfg =
      parse_config_text(rt_config_with("  realtime: {pm_qos_latency: 1ms}\n"), "rt.yaml");
  EXPECT_EQ(cfg.machine.realtime.pm_qos_latency_us, 1000);
}

TEST(RealtimeConfig, off_makes_no_request) {
  const Config cfg =
      parse_config_text(rt_config_with("  realtime: {pm_qos_latency: off}\n"), "rt.yaml");
  EXPECT_FALSE(cfg.machine.realtime.pm_qos_latency_us.has_value());
}

TEST(RealtimeConfig, quoted_off_is_not_the_keyword) {
  EXPECT_EQ(rt_first_error(rt_config_with("  realtime: {pm_qos_latency: \"off\"}\n"))
                .rfind("rt.yaml:4:30: ", 0),
            0u);
}

TEST(RealtimeConfig, bad_values_are_reported_at_their_value) {
  EXPECT_EQ(rt_first_error(rt_config_with("  realtime: {pm_qos_latency: -5us}\n")),
            "rt.yaml:4:30: machine.realtime.pm_qos_latency: must not be negative (got '-5us')");
  EXPECT_EQ(rt_first_error(rt_config_with("  realtime: {pm_qos_latency: 2500ns}\n")),
            "rt.yaml:4:30: machine.realtime.pm_qos_latency: must be whole microseconds (got "
            "2500ns)");
  EXPECT_EQ(rt_first_error(rt_config_with("  realtime: {pm_qos_device: \"\"}\n"))
                .rfind("rt.yaml:4:29: ", 0),
            0u);
  EXPECT_EQ(rt_first_error(rt_config_with("  realtime: {lock_memory: 1}\n")),
            "rt.yaml:4:27: machine.realtime.lock_memory: must be one of true, false (got '1')");
  EXPECT_EQ(rt_first_error(rt_config_with("  realtime: [0us]\n")).rfind("rt.yaml:4:13: ", 0), 0u);
}

}  // namespace
}  // namespace edm::rt
