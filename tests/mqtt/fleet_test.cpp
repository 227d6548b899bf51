// The fleet view (edmhmi fleet) hears whatever anyone publishes on the broker: it stays bounded,
// prints no control characters, never throws on a metric's bytes, and a stale will (spoofed or
// old) does not take a machine offline.
#include "edm/sparkplug/fleet.hpp"

#include <gtest/gtest.h>

#include <string>

#include "payloads.hpp"

namespace edm::sparkplug::test {
namespace {

Metric mk(std::string name, DataType type, Value v) {
  Metric m;
  m.name = std::move(name);
  m.type = type;
  m.value = std::move(v);
  m.timestamp = 1;
  return m;
}

std::string birth(std::uint64_t bdseq, const std::string& state = "READY") {
  Payload p;
  p.seq = 0;
  p.metrics.push_back(mk(std::string(kBdSeq), DataType::kUInt64, bdseq));
  p.metrics.push_back(mk("state", DataType::kString, state));
  return encode(p);
}

TEST(FleetTable, HostileTextNeitherEscapesToTheTerminalNorThrowsInJson) {
  FleetTable t;
  t.on_message("spBv1.0/g/NBIRTH/n", birth(0), 1);
  Payload d;
  d.seq = 1;
  d.metrics.push_back(mk("state", DataType::kString, std::string("\x1b[2J\x1b[HONLINE\n\xff\xfe")));
  t.on_message("spBv1.0/g/DBIRTH/n/d", encode(d), 1);
  const std::string text = render_text(t.machines(), 2);
  EXPECT_EQ(text.find('\x1b'), std::string::npos) << text;
  std::string json;
  EXPECT_NO_THROW(json = render_json(t.machines(), 2));
  EXPECT_NE(json.find("\\u001b[2J"), std::string::npos);
}

TEST(FleetTable, IsBoundedInNodesMetricsAndSizes) {
  FleetLimits lim;
  lim.max_nodes = 100;
  lim.max_metrics = 150;
  FleetTable t(lim);
  for (int i = 0; i < 300; ++i) t.on_message("spBv1.0/g/NBIRTH/n" + std::to_string(i), birth(0), 1);
  EXPECT_EQ(t.machines().size(), 100u);
  EXPECT_EQ(t.ignored_messages(), 200u);
  EXPECT_EQ(t.metrics_kept(), 150u);  // 2 per birth: 25 nodes are kept without theirs
  EXPECT_EQ(t.ignored_metrics(), 50u);
  FleetTable u;
  u.on_message("spBv1.0/g/NBIRTH/" + std::string(1000, 'n'), birth(0), 1);
  u.on_message("spBv1.0/g/NBIRTH/n", std::string(2 << 20, '\x08'), 1);
  u.on_message("spBv1.0/g/NBIRTH/n", many_metrics(5000), 1);
  EXPECT_TRUE(u.machines().empty());
  EXPECT_EQ(u.ignored_messages(), 3u);
  // A string value is cut; a birth replaces the node's metrics (the count follows).
  Payload p;
  p.seq = 0;
  p.metrics.push_back(mk("state", DataType::kString, std::string(5000, 's')));
  u.on_message("spBv1.0/g/NBIRTH/n", encode(p), 1);
  u.on_message("spBv1.0/g/NBIRTH/n", encode(p), 1);
  ASSERT_EQ(u.machines().size(), 1u);
  EXPECT_EQ(u.machines()[0].text("state").size(), 1024u);
  EXPECT_EQ(u.metrics_kept(), 1u);
}

TEST(FleetTable, AWillOfAnotherSessionDoesNotTakeTheNodeOffline) {
  FleetTable t;
  t.on_message("spBv1.0/g/NBIRTH/n", birth(7), 1);
  Payload death;
  death.metrics.push_back(mk(std::string(kBdSeq), DataType::kUInt64, std::uint64_t{6}));
  t.on_message("spBv1.0/g/NDEATH/n", encode(death), 2);
  ASSERT_EQ(t.machines().size(), 1u);
  EXPECT_TRUE(t.machines()[0].online);
  death.metrics[0].value = std::uint64_t{7};
  t.on_message("spBv1.0/g/NDEATH/n", encode(death), 3);
  EXPECT_FALSE(t.machines()[0].online);
}

}  // namespace
}  // namespace edm::sparkplug::test
