// edmplc as a process with Modbus on both sides (docs/modbus.md): its Modbus TCP server against
// Debian's mbpoll and hostile raw clients, and config/machines/drill-modbus-sim.yaml against the
// pymodbus remote I/O of remote_io.py.

#include <arpa/inet.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <array>
#include <chrono>
#include <fstream>
#include <random>
#include <regex>
#include <sstream>
#include <thread>
#include <vector>

#include "modbus/remote_io.hpp"
#include "support/files.hpp"
#include "support/subprocess.hpp"
#include "support/temp_dir.hpp"

namespace edm::test {
namespace {

using namespace std::chrono_literals;

struct Mbpoll {
  int status;
  std::string out;
};

// mbpoll, 0-based references (-0), one poll (-1), 1 s timeout.
Mbpoll mbpoll(int port, const std::vector<std::string>& args) {
  std::vector<std::string> argv{
      "/usr/bin/mbpoll", "-m", "tcp", "-p", std::to_string(port), "-a", "1", "-0", "-1", "-o", "1"};
  argv.insert(argv.end(), args.begin(), args.end());
  Child c(argv);
  const int status = c.wait();
  return {status, c.output()};
}

std::string write_file(const TempDir& dir, const std::string& name, const std::string& text) {
  const std::string path = dir.file(name);
  std::ofstream(path) << text;
  edm::test::link_machine_fragments(dir.path().string());  // drill-modbus-sim's `include:`
  return path;
}

class Socket {
 public:
  explicit Socket(int port) : fd_(::socket(AF_INET, SOCK_STREAM, 0)) {
    sockaddr_in a{};
    a.sin_family = AF_INET;
    a.sin_port = htons(static_cast<std::uint16_t>(port));
    a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    connected_ = ::connect(fd_, reinterpret_cast<sockaddr*>(&a), sizeof a) == 0;
    timeval tv{2, 0};
    ::setsockopt(fd_, SOL_SOCKET, SO_RCVTIMEO, &tv, sizeof tv);
  }
  ~Socket() { ::close(fd_); }
  Socket(const Socket&) = delete;
  Socket& operator=(const Socket&) = delete;
  [[nodiscard]] bool connected() const { return connected_; }
  bool send(const std::vector<std::uint8_t>& b) {
    return ::send(fd_, b.data(), b.size(), MSG_NOSIGNAL) == static_cast<ssize_t>(b.size());
  }
  /// The reply's bytes; empty when the server closed the connection (or said nothing in 2 s).
  std::vector<std::uint8_t> recv() {
    std::array<std::uint8_t, 300> buf{};
    const ssize_t n = ::recv(fd_, buf.data(), buf.size(), 0);
    return n > 0 ? std::vector<std::uint8_t>(buf.begin(), buf.begin() + n)
                 : std::vector<std::uint8_t>{};
  }

 private:
  int fd_;
  bool connected_{false};
};

// A Modbus TCP frame: transaction 1, protocol 0, unit 1, then the PDU.
std::vector<std::uint8_t> frame(const std::vector<std::uint8_t>& pdu) {
  const auto len = static_cast<std::uint16_t>(pdu.size() + 1);
  std::vector<std::uint8_t> f(7 + pdu.size());
  f[1] = 1;
  f[4] = static_cast<std::uint8_t>(len >> 8);
  f[5] = static_cast<std::uint8_t>(len & 0xFF);
  f[6] = 1;
  for (std::size_t i = 0; i < pdu.size(); ++i) f[7 + i] = pdu[i];
  return f;
}

// The exception code of a reply to function fc, or -1 for a normal reply / no reply.
int exception_of(const std::vector<std::uint8_t>& reply, std::uint8_t fc) {
  if (reply.size() < 9 || int{reply[7]} != (int{fc} | 0x80)) {
    return -1;
  }
  return reply[8];
}

constexpr const char* kServerConfig = R"(version: 1
machine: {name: mbs, io: {driver: loopback, params: {channels: 1}}}
tasks: [{name: t, interval: 1ms, priority: 0, programs: [p]}]
programs:
  - name: p
    blocks:
      - {name: g, type: Gain, params: {k: 2, offset: 0.5}}
      - {name: lp, type: LowPass, params: {tau: 5ms}}
    wires: {g.in: 1.5, io.ao0: g.out, lp.in: g.out}
modbus_server:
  port: PORT
  max_clients: 4
  max_clients_per_address: 4
  map:
    - {table: holding_register, address: 0, var: p.g.k, type: float32, writable: true}
    - {table: holding_register, address: 2, var: p.g.out, type: int16, scale: 0.01}
    - {table: holding_register, address: 3, var: p.lp.tau, type: uint16, scale: 0.001,
       writable: true}
    - {table: input_register, address: 0, var: io.ai0, type: int32, scale: 0.001,
       word_order: little}
    - {table: coil, address: 0, var: io.do0}
    - {table: discrete_input, address: 0, var: io.di0}
)";

std::string with_port(std::string text, int port) {
  return std::regex_replace(text, std::regex("PORT"), std::to_string(port));
}

TEST(ModbusServer, MbpollReadsWritesAndIsRefusedWhereNotWritable) {
  TempDir dir;
  const int port = free_port();
  const std::string cfg = write_file(dir, "mbs.yaml", with_port(kServerConfig, port));
  Child map({EDM_EDMPLC_PATH, "--config", cfg, "--modbus-map"});
  ASSERT_EQ(map.wait(), 0) << map.output();
  EXPECT_NE(map.output().find("holding_register        0      2  float32  1            0       "
                              "     rw      p.g.k"),
            std::string::npos)
      << map.output();
  Child plc({EDM_EDMPLC_PATH, "--config", cfg, "--bridge-port", "0", "--run-for", "60s"});
  ASSERT_TRUE(plc.wait_for_output("modbus_server: listening")) << plc.output();
  ASSERT_TRUE(plc.wait_for_output("running 1 task(s)")) << plc.output();
  std::this_thread::sleep_for(200ms);  // the first cycles have run: g.out is computed

  // g.out = k·1.5 + 0.5 = 3.5 → 350 at scale 0.01; k = 2 as float32, high word first (-B).
  Mbpoll r = mbpoll(port, {"-t", "4", "-r", "2", "-c", "1", "127.0.0.1"});
  EXPECT_EQ(r.status, 0) << r.out;
  EXPECT_NE(r.out.find("[2]: \t350"), std::string::npos) << r.out;
  r = mbpoll(port, {"-t", "4:float", "-B", "-r", "0", "-c", "1", "127.0.0.1"});
  EXPECT_NE(r.out.find("[0]: \t2"), std::string::npos) << r.out;
  // A writable parameter: k = 3 → g.out = 5.0 from the next cycle.
  r = mbpoll(port, {"-t", "4:float", "-B", "-r", "0", "127.0.0.1", "3.0"});
  EXPECT_EQ(r.status, 0) << r.out;
  std::this_thread::sleep_for(50ms);
  r = mbpoll(port, {"-t", "4", "-r", "2", "-c", "1", "127.0.0.1"});
  EXPECT_NE(r.out.find("[2]: \t500"), std::string::npos) << r.out;
  // Not writable (a pin): exception 02; a value the parameter's range refuses (tau 0): 03.
  r = mbpoll(port, {"-t", "4", "-r", "2", "127.0.0.1", "7"});
  EXPECT_NE(r.status, 0);
  EXPECT_NE(r.out.find("Illegal data address"), std::string::npos) << r.out;
  r = mbpoll(port, {"-t", "4", "-r", "3", "127.0.0.1", "0"});
  EXPECT_NE(r.out.find("Illegal data value"), std::string::npos) << r.out;
  r = mbpoll(port, {"-t", "4", "-r", "3", "127.0.0.1", "20"});  // tau 20 ms: accepted
  EXPECT_EQ(r.status, 0) << r.out;
  // Unmapped: 02. Coils and discrete inputs of the loopback image read.
  r = mbpoll(port, {"-t", "4", "-r", "100", "-c", "1", "127.0.0.1"});
  EXPECT_NE(r.out.find("Illegal data address"), std::string::npos) << r.out;
  r = mbpoll(port, {"-t", "0", "-r", "0", "-c", "1", "127.0.0.1"});
  EXPECT_NE(r.out.find("[0]: \t0"), std::string::npos) << r.out;
  r = mbpoll(port, {"-t", "3:int", "-r", "0", "-c", "1", "127.0.0.1"});
  EXPECT_EQ(r.status, 0) << r.out;

  plc.signal(SIGTERM);
  EXPECT_EQ(plc.wait(), 0) << plc.output();
}

TEST(ModbusServer, HostileInputGetsExceptionsOrIsClosedAndNeverCrashesIt) {
  TempDir dir;
  const int port = free_port();
  const std::string cfg = write_file(dir, "mbs.yaml", with_port(kServerConfig, port));
  Child plc({EDM_EDMPLC_PATH, "--config", cfg, "--bridge-port", "0", "--run-for", "60s"});
  ASSERT_TRUE(plc.wait_for_output("modbus_server: listening")) << plc.output();
  ASSERT_TRUE(plc.wait_for_output("running 1 task(s)")) << plc.output();
  std::this_thread::sleep_for(200ms);  // the first cycles have run: g.out is computed
  {
    Socket s(port);
    ASSERT_TRUE(s.connected());
    // Functions it does not serve: 01 (diagnostics 0x08, read/write multiple 0x17, MEI 0x2B),
    // with the function byte | 0x80 for codes from 0x80 too (0x83: 83 01, never 03 01).
    for (const int code : {0x08, 0x17, 0x2B, 0x7F, 0x00, 0x80, 0x83, 0x90, 0xFF}) {
      const auto fc = static_cast<std::uint8_t>(code);
      ASSERT_TRUE(s.send(frame({fc, 0, 0, 0, 1})));
      EXPECT_EQ(exception_of(s.recv(), fc), 1) << int(fc);
    }
    // Quantity 0 and 126 registers: 03; a range past 65535 and unmapped addresses: 02.
    ASSERT_TRUE(s.send(frame({3, 0, 0, 0, 0})));
    EXPECT_EQ(exception_of(s.recv(), 3), 3);
    ASSERT_TRUE(s.send(frame({3, 0, 0, 0, 126})));
    EXPECT_EQ(exception_of(s.recv(), 3), 3);
    ASSERT_TRUE(s.send(frame({4, 0xFF, 0xFF, 0, 2})));
    EXPECT_EQ(exception_of(s.recv(), 4), 2);
    ASSERT_TRUE(s.send(frame({1, 0x12, 0x34, 0, 8})));
    EXPECT_EQ(exception_of(s.recv(), 1), 2);
    // Half a float32 written alone: 02; a coil value other than 0xFF00/0x0000: 03.
    ASSERT_TRUE(s.send(frame({6, 0, 1, 0x40, 0x40})));
    EXPECT_EQ(exception_of(s.recv(), 6), 2);
    ASSERT_TRUE(s.send(frame({5, 0, 0, 0x12, 0x34})));
    EXPECT_EQ(exception_of(s.recv(), 5), 3);
    // A byte count that does not match the quantity: 03.
    ASSERT_TRUE(s.send(frame({16, 0, 0, 0, 2, 3, 0, 0, 0, 0})));
    EXPECT_EQ(exception_of(s.recv(), 16), 3);
    // Still serving on the same connection.
    ASSERT_TRUE(s.send(frame({3, 0, 2, 0, 1})));
    const auto ok = s.recv();
    ASSERT_EQ(ok.size(), 11U);
    EXPECT_EQ(ok[7], 3);
  }
  {
    Socket s(port);  // a frame that is not Modbus TCP (protocol id 5): closed
    ASSERT_TRUE(s.send({0, 1, 0, 5, 0, 6, 1, 3, 0, 0, 0, 1}));
    EXPECT_TRUE(s.recv().empty());
  }
  {
    Socket s(port);  // random bytes: closed, whatever they are
    std::mt19937 rng(24);
    std::vector<std::uint8_t> junk(4096);
    for (auto& b : junk) b = static_cast<std::uint8_t>(rng());
    junk[2] = 0x42;  // not protocol 0
    s.send(junk);
    EXPECT_TRUE(s.recv().empty());
  }
  {
    // Many clients that say nothing yet: each one past the four slots takes the slot of the
    // oldest, so the last four are served; then they leave.
    std::vector<std::unique_ptr<Socket>> many;
    for (int i = 0; i < 12; ++i) many.push_back(std::make_unique<Socket>(port));
    std::this_thread::sleep_for(300ms);
    std::vector<int> served;
    for (int i = 0; i < 12; ++i) {
      if (many[i]->send(frame({3, 0, 2, 0, 1})) && many[i]->recv().size() == 11) {
        served.push_back(i);
      }
    }
    EXPECT_EQ(served, (std::vector<int>{8, 9, 10, 11}));
  }
  std::this_thread::sleep_for(300ms);
  const Mbpoll r = mbpoll(port, {"-t", "4", "-r", "2", "-c", "1", "127.0.0.1"});
  EXPECT_NE(r.out.find("[2]: \t350"), std::string::npos) << r.out;
  plc.signal(SIGTERM);
  EXPECT_EQ(plc.wait(), 0) << plc.output();
}

std::string drill_modbus_sim(int remote_port, int server_port) {
  std::ifstream in(std::string(EDM_SOURCE_DIR) + "/config/machines/drill-modbus-sim.yaml");
  std::stringstream ss;
  ss << in.rdbuf();
  std::string text = ss.str();
  text = std::regex_replace(text, std::regex("port: 1502"), "port: " + std::to_string(remote_port));
  text = std::regex_replace(text, std::regex("port: 1503"), "port: " + std::to_string(server_port));
  // A test host under load (pymodbus is slow Python): 300 ms, not the shipped 100 ms.
  text = std::regex_replace(text, std::regex("stale_cycles: 100"), "stale_cycles: 300");
  return text;
}

TEST(DrillModbusSim, RunsAgainstAPymodbusRemoteIoAndFaultsWhenItGoes) {
  RemoteIo io;
  ASSERT_TRUE(io.ready()) << io.output();
  ASSERT_TRUE(io.set("di", 0, 1));    // door closed
  ASSERT_TRUE(io.set("di", 1, 1));    // E-stop chain closed
  ASSERT_TRUE(io.set("ir", 0, 250));  // 2.50 bar
  ASSERT_TRUE(io.set("co", 0, 1));    // the pump left on by someone: edmplc turns it off
  TempDir dir;
  const int server_port = free_port();
  const std::string cfg =
      write_file(dir, "drill-modbus-sim.yaml", drill_modbus_sim(io.port(), server_port));
  Child plc({EDM_EDMPLC_PATH, "--config", cfg, "--bridge-port", "0", "--run-for", "60s"});
  ASSERT_TRUE(plc.wait_for_output("modbus_server: listening")) << plc.output();
  ASSERT_TRUE(plc.wait_for_output("connected (unit 1)")) << plc.output();
  std::this_thread::sleep_for(300ms);
  EXPECT_EQ(io.get("co", 0), 0);  // no job: flushing off
  // Through edmplc's own server: the remote I/O is online, the pressure scaled back.
  Mbpoll r = mbpoll(server_port, {"-t", "1", "-r", "1", "-c", "1", "127.0.0.1"});
  EXPECT_NE(r.out.find("[1]: \t1"), std::string::npos) << r.out;
  r = mbpoll(server_port, {"-t", "3", "-r", "5", "-c", "1", "127.0.0.1"});
  EXPECT_NE(r.out.find("[5]: \t250"), std::string::npos) << r.out;
  EXPECT_EQ(plc.output().find("ALARM"), std::string::npos) << plc.output();

  io.kill();  // the coupler goes away: alarm 121 within stale_cycles (100 ms)
  EXPECT_TRUE(plc.wait_for_output("ALARM 121 (io_stale)")) << plc.output();
  r = mbpoll(server_port, {"-t", "1", "-r", "1", "-c", "1", "127.0.0.1"});
  EXPECT_NE(r.out.find("[1]: \t0"), std::string::npos) << r.out;
  plc.signal(SIGTERM);
  EXPECT_EQ(plc.wait(), 1) << plc.output();  // stopped in FAULT
}

TEST(DrillModbusSim, AnOpenDoorIsAlarm131) {
  RemoteIo io;
  ASSERT_TRUE(io.ready()) << io.output();
  ASSERT_TRUE(io.set("di", 1, 1));  // E-stop chain closed, door open
  TempDir dir;
  const std::string cfg =
      write_file(dir, "drill-modbus-sim.yaml", drill_modbus_sim(io.port(), free_port()));
  Child plc({EDM_EDMPLC_PATH, "--config", cfg, "--bridge-port", "0", "--run-for", "2s"});
  EXPECT_EQ(plc.wait(), 1) << plc.output();
  EXPECT_NE(plc.output().find("ALARM 131 (interlock_open) from io.door_closed"), std::string::npos)
      << plc.output();
}

// A field bus's image ages in wall time: the virtual clock faster than 1x is refused before any
// cycle (no server needed: nothing connects); --check and 1x pass that point.
TEST(DrillModbusSim, TheVirtualClockFasterThanWallTimeIsRefused) {
  TempDir dir;
  const std::string cfg =
      write_file(dir, "drill-modbus-sim.yaml", drill_modbus_sim(free_port(), free_port()));
  for (const std::vector<std::string>& clock :
       {std::vector<std::string>{"--clock", "virtual"},
        std::vector<std::string>{"--clock", "virtual", "--speed", "10"}}) {
    std::vector<std::string> args{EDM_EDMPLC_PATH, "--config", cfg, "--bridge-port", "0",
                                  "--run-for",     "1s"};
    args.insert(args.end(), clock.begin(), clock.end());
    Child plc(args);
    EXPECT_EQ(plc.wait(), 2) << plc.output();
    EXPECT_NE(plc.output().find("drill-modbus-sim.yaml: its I/O driver exchanges with real "
                                "devices in wall time (modbus)"),
              std::string::npos)
        << plc.output();
  }
  Child check({EDM_EDMPLC_PATH, "--config", cfg, "--check", "--clock", "virtual"});
  EXPECT_EQ(check.wait(), 0) << check.output();
  // Paced at 1x it runs (the remote I/O is absent: alarm 121, as on the real clock).
  Child paced({EDM_EDMPLC_PATH, "--config", cfg, "--bridge-port", "0", "--run-for", "1s", "--clock",
               "virtual", "--speed", "1"});
  EXPECT_EQ(paced.wait(), 1) << paced.output();
  EXPECT_NE(paced.output().find("ALARM 121 (io_stale)"), std::string::npos) << paced.output();
}

}  // namespace
}  // namespace edm::test
