// The Modbus TCP server's protocol over real sockets (docs/modbus.md "Exceptions", issue 31
// item 9): every one of the 256 function codes, headers and requests that lie, unit ids,
// quantities and addresses at the protocol's limits, writes to what is read-only; and the
// `modbus_server:` limits checked at file:line:col.

#include <gtest/gtest.h>

#include <set>

#include "modbus/raw_client.hpp"
#include "modbus/server_fixture.hpp"

namespace edm::test {
namespace {

using namespace std::chrono_literals;
using Bytes = std::vector<std::uint8_t>;

// The exception code of a reply to function fc, or -1 when it is not an exception reply to fc.
int exception_code_of(const Bytes& r, std::uint8_t fc) {
  if (r.size() != 9 || r[7] != (fc | 0x80U)) {
    return -1;
  }
  return r[8];
}

// A valid request of each served function against the fixture's map.
Bytes valid_request(std::uint8_t fc) {
  switch (fc) {
    case 1: return {1, 0, 0, 0, 2};  // coils 0-1
    case 2: return {2, 0, 0, 0, 1};
    case 3: return {3, 0, 2, 0, 1};
    case 4: return {4, 0, 0, 0, 2};
    case 5: return {5, 0, 1, 0xFF, 0};  // p.dsc.arcs_as_short = true
    case 6: return {6, 0, 3, 0, 20};    // p.lp.tau = 20 ms
    case 15: return {15, 0, 1, 0, 1, 1, 0};
    case 16: return {16, 0, 0, 0, 2, 4, 0x40, 0, 0, 0};  // p.g.k = 2.0f
    default: return {fc, 0, 0, 0, 1};
  }
}

// The MBAP of a reply matches its request: transaction, protocol 0, length, unit.
void expect_mbap(const Bytes& r, std::uint16_t tid, std::uint8_t unit) {
  ASSERT_GE(r.size(), 9U);
  EXPECT_EQ((r[0] << 8) | r[1], tid);
  EXPECT_EQ(r[2], 0);
  EXPECT_EQ(r[3], 0);
  EXPECT_EQ(static_cast<std::size_t>((r[4] << 8) | r[5]), r.size() - 6);
  EXPECT_EQ(r[6], unit);
}

// Issue 31 item 9: 0x83 was answered as function 3 (libmodbus wrapped fc + 0x80 in a byte).
TEST(ModbusServerProtocol, EveryFunctionCodeIsServedOrExceptionOneWithItsFunctionByteOr0x80) {
  ServerFixture s;
  RawClient c(s.port());
  ASSERT_TRUE(c.connected());
  const std::set<int> served{1, 2, 3, 4, 5, 6, 15, 16};
  for (int code = 0; code < 256; ++code) {
    const auto fc = static_cast<std::uint8_t>(code);
    const auto tid = static_cast<std::uint16_t>(0x1200 + code);
    ASSERT_TRUE(c.send(mb_frame(valid_request(fc), tid)));
    const Bytes r = c.reply();
    ASSERT_FALSE(r.empty()) << "fc " << code << ": no reply";
    expect_mbap(r, tid, 1);
    if (served.contains(code)) {
      EXPECT_EQ(r[7], fc) << "fc " << code << " not served normally";
    } else {
      EXPECT_EQ(exception_code_of(r, fc), 1) << "fc " << code << ": function byte " << int{r[7]};
    }
  }
  // A PDU of the function code alone: too short for a served function (03), still 01 for
  // every other one.
  for (int code = 0; code < 256; ++code) {
    const auto fc = static_cast<std::uint8_t>(code);
    ASSERT_TRUE(c.send(mb_frame({fc}, 7)));
    const Bytes r = c.reply();
    ASSERT_FALSE(r.empty()) << "fc " << code;
    EXPECT_EQ(exception_code_of(r, fc), served.contains(code) ? 3 : 1) << "fc " << code;
  }
  const auto k = s.counters();
  EXPECT_EQ(k.requests, 512U);
  EXPECT_EQ(k.exceptions, 512U - 8U);
  EXPECT_EQ(k.bad_frames, 0U);
}

TEST(ModbusServerProtocol, HeadersThatLieCloseTheConnection) {
  ServerFixture s;
  // Length 0 and 1 (no function code), 255 and 65535 (past the 260-byte frame), protocol ≠ 0.
  const std::vector<Bytes> bad{
      {0, 1, 0, 0, 0, 0, 1},
      {0, 1, 0, 0, 0, 1, 1},
      {0, 1, 0, 0, 0, 255, 1, 3},
      {0, 1, 0, 0, 0xFF, 0xFF, 1, 3},
      {0, 1, 0, 1, 0, 6, 1, 3, 0, 0, 0, 1},
      {0, 1, 0x0A, 0x0A, 0, 6, 1, 3, 0, 0, 0, 1},
  };
  std::uint64_t n = 0;
  for (const Bytes& b : bad) {
    RawClient c(s.port());
    ASSERT_TRUE(c.connected());
    ASSERT_TRUE(c.send(b));
    EXPECT_TRUE(c.closed_within(2s)) << "frame " << n;
    ++n;
    EXPECT_TRUE(ServerFixture::eventually([&] { return s.counters().bad_frames == n; }));
  }
  EXPECT_EQ(s.counters().requests, 0U);
  // A length that claims more than the PDU has: nothing to serve until the frame is complete;
  // the bytes that complete it are read as its end (a read with trailing bytes: 03).
  RawClient c(s.port());
  Bytes f = mb_frame({3, 0, 2, 0, 1});
  f[5] = 8;  // 7 PDU bytes announced, 5 sent
  ASSERT_TRUE(c.send(f));
  ASSERT_TRUE(c.send({0, 0}));
  EXPECT_EQ(exception_code_of(c.reply(), 3), 3);
}

TEST(ModbusServerProtocol, RequestsAtTheProtocolsLimitsGetTheirException) {
  ServerFixture s;
  RawClient c(s.port());
  ASSERT_TRUE(c.connected());
  const auto ex = [&](const Bytes& pdu) {
    EXPECT_TRUE(c.send(mb_frame(pdu)));
    return exception_code_of(c.reply(), pdu[0]);
  };
  // Quantity 0 and one over the limit of each function: 03.
  EXPECT_EQ(ex({1, 0, 0, 0, 0}), 3);
  EXPECT_EQ(ex({1, 0, 0, 0x07, 0xD1}), 3);  // 2001 bits
  EXPECT_EQ(ex({2, 0, 0, 0x07, 0xD1}), 3);
  EXPECT_EQ(ex({3, 0, 0, 0, 0}), 3);
  EXPECT_EQ(ex({3, 0, 0, 0, 126}), 3);
  EXPECT_EQ(ex({4, 0, 0, 0, 126}), 3);
  EXPECT_EQ(ex({15, 0, 1, 0, 0, 0}), 3);
  Bytes coils{15, 0, 0, 0x07, 0xB1, 247};  // 1969 coils in 247 bytes
  coils.resize(6 + 247);
  EXPECT_EQ(ex(coils), 3);
  Bytes regs{16, 0, 0, 0, 124, 248};  // 124 registers: not even a frame's room; still 03
  regs.resize(6 + 240);
  EXPECT_EQ(ex(regs), 3);
  EXPECT_EQ(ex({16, 0, 0, 0, 2, 3, 0, 0, 0}), 3);  // byte count ≠ 2·quantity
  EXPECT_EQ(ex({6, 0, 3, 0, 20, 0}), 3);           // a trailing byte
  EXPECT_EQ(ex({3, 0, 2, 0}), 3);                  // one byte short
  EXPECT_EQ(ex({5, 0, 1, 0x12, 0x34}), 3);         // a coil is 0xFF00 or 0x0000
  // The top of the address space: the float at 65534-65535 reads and writes whole or in part
  // for reads; one register past 65535 is 02.
  Bytes r;
  EXPECT_TRUE(c.send(mb_frame({3, 0xFF, 0xFE, 0, 2})));
  r = c.reply();
  ASSERT_EQ(r.size(), 13U);
  EXPECT_EQ(r[9], 0x40);  // 2.0f, high word first
  EXPECT_TRUE(c.send(mb_frame({3, 0xFF, 0xFF, 0, 1})));
  EXPECT_EQ(c.reply().size(), 11U);
  EXPECT_EQ(ex({3, 0xFF, 0xFF, 0, 2}), 2);
  EXPECT_EQ(ex({1, 0xFF, 0xFF, 0, 2}), 2);
  EXPECT_EQ(ex({16, 0xFF, 0xFF, 0, 2, 4, 0x40, 0, 0, 0}), 2);
  EXPECT_TRUE(c.send(mb_frame({16, 0xFF, 0xFE, 0, 2, 4, 0x40, 0x40, 0, 0})));
  r = c.reply();
  ASSERT_EQ(r.size(), 12U);
  EXPECT_EQ(r[7], 16);
  // What is not writable: a pin (holding 2, coil 0), half a float32, an unmapped address, an
  // input table's address through a write function: 02. A value the parameter refuses: 03.
  EXPECT_EQ(ex({6, 0, 2, 0, 7}), 2);
  EXPECT_EQ(ex({5, 0, 0, 0xFF, 0}), 2);
  EXPECT_EQ(ex({6, 0, 1, 0x40, 0x40}), 2);
  EXPECT_EQ(ex({16, 0, 1, 0, 2, 4, 0, 0, 0, 0}), 2);
  EXPECT_EQ(ex({6, 0x12, 0x34, 0, 1}), 2);
  EXPECT_EQ(ex({6, 0, 3, 0, 0}), 3);                        // tau 0
  EXPECT_EQ(ex({16, 0, 0, 0, 2, 4, 0x7F, 0xC0, 0, 0}), 3);  // k = NaN
  EXPECT_EQ(ex({16, 0, 0, 0, 2, 4, 0xFF, 0x80, 0, 0}), 3);  // k = -inf
  EXPECT_EQ(ex({3, 0x12, 0x34, 0, 1}), 2);
  // 125 registers, the longest reply, and 2000 bits.
  EXPECT_TRUE(c.send(mb_frame({3, 0, 100, 0, 125})));
  EXPECT_EQ(c.reply().size(), 9U + 250U);
  EXPECT_EQ(ex({1, 0, 0, 0x07, 0xD0}), 2);  // 2000 bits from 0: coil 2 is not mapped
  // Every unit id is served and echoed.
  for (const int unit : {0, 1, 17, 247, 255}) {
    EXPECT_TRUE(c.send(mb_frame({3, 0, 2, 0, 1}, 9, static_cast<std::uint8_t>(unit))));
    r = c.reply();
    expect_mbap(r, 9, static_cast<std::uint8_t>(unit));
    EXPECT_EQ(r[7], 3);
  }
  EXPECT_EQ(s.counters().bad_frames, 0U);
  EXPECT_EQ(s.counters().open, 1U);
}

TEST(ModbusServerProtocol, PipelinedAndSplitFramesAreServedInOrder) {
  ServerFixture s;
  RawClient c(s.port());
  Bytes three;
  for (std::uint16_t tid = 1; tid <= 3; ++tid) {
    const Bytes f = mb_frame({3, 0, 2, 0, 1}, tid);
    three.insert(three.end(), f.begin(), f.end());
  }
  ASSERT_TRUE(c.send(three));
  for (std::uint16_t tid = 1; tid <= 3; ++tid) {
    const Bytes r = c.reply();
    expect_mbap(r, tid, 1);
  }
  // A frame in two segments, within the frame deadline.
  const Bytes f = mb_frame({4, 0, 0, 0, 2}, 44);
  ASSERT_TRUE(c.send(Bytes(f.begin(), f.begin() + 5)));
  ASSERT_TRUE(ServerFixture::eventually([&] { return s.counters().requests == 3; }));
  ASSERT_TRUE(c.send(Bytes(f.begin() + 5, f.end())));
  const Bytes r = c.reply();
  expect_mbap(r, 44, 1);
  EXPECT_EQ(r[7], 4);
}

// The parameters written over Modbus are the registry's (queued to the task, as from the bridge).
TEST(ModbusServerProtocol, WritesReachTheParameters) {
  ServerFixture s;
  RawClient c(s.port());
  ASSERT_TRUE(c.send(mb_frame({16, 0, 0, 0, 2, 4, 0x40, 0x40, 0, 0})));  // 3.0f
  EXPECT_EQ(c.reply().size(), 12U);
  EXPECT_EQ(s.vars().read("p.g.k"), 3.0);
  ASSERT_TRUE(c.send(mb_frame({5, 0, 1, 0, 0})));
  EXPECT_EQ(c.reply().size(), 12U);
  EXPECT_EQ(s.vars().read("p.dsc.arcs_as_short"), 0.0);
  EXPECT_EQ(s.counters().writes, 2U);
}

TEST(ModbusServerConfig, LimitsHaveDefaultsAndBadValuesAreReportedAtTheirPlace) {
  ServerFixture s;
  const modbus::ServerConfig& d = s.config();
  EXPECT_EQ(d.max_clients, 16);
  EXPECT_EQ(d.effective_per_address(), 4);
  EXPECT_EQ(d.frame_timeout, 1000ms);
  EXPECT_EQ(d.idle_timeout, 60000ms);
  EXPECT_EQ(d.log_burst, 10);
  EXPECT_EQ(d.log_per_s, 1.0);
  const auto errors = [&](const std::string& limits) -> std::string {
    try {
      modbus::parse_server_text(
          "modbus_server:\n" + limits + "  map:\n    - {table: coil, address: 0, var: io.do0}\n",
          "bad.yaml", s.vars());
    } catch (const rt::ConfigError& e) {
      return e.what();
    }
    return "";
  };
  EXPECT_NE(errors("  max_clients: 8\n  max_clients_per_address: 9\n")
                .find("bad.yaml:3:28: modbus_server.max_clients_per_address: must be at most "
                      "max_clients (8)"),
            std::string::npos)
      << errors("  max_clients: 8\n  max_clients_per_address: 9\n");
  EXPECT_NE(errors("  max_clients: 65\n").find("bad.yaml:2:16: modbus_server.max_clients"),
            std::string::npos);
  EXPECT_NE(errors("  frame_timeout: 0ms\n")
                .find("bad.yaml:2:18: modbus_server.frame_timeout: "
                      "must be from 10ms to 60s"),
            std::string::npos)
      << errors("  frame_timeout: 0ms\n");
  EXPECT_NE(errors("  frame_timeout: 2min\n").find("bad.yaml:2:18:"), std::string::npos);
  EXPECT_NE(errors("  frame_timeout: 5s\n  idle_timeout: 2s\n")
                .find("bad.yaml:3:17: modbus_server.idle_timeout: must be at least frame_timeout"),
            std::string::npos)
      << errors("  frame_timeout: 5s\n  idle_timeout: 2s\n");
  EXPECT_NE(errors("  log_burst: 0\n").find("bad.yaml:2:14: modbus_server.log_burst"),
            std::string::npos);
  EXPECT_NE(errors("  log_per_s: -1\n").find("bad.yaml:2:14: modbus_server.log_per_s: must be"),
            std::string::npos)
      << errors("  log_per_s: -1\n");
  EXPECT_NE(errors("  max_client: 3\n").find("bad.yaml:2:3:"), std::string::npos);
}

}  // namespace
}  // namespace edm::test
