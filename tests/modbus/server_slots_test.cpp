// Who keeps the Modbus server's connection slots (docs/modbus.md "Connections", issue 31 item
// 10): clients trickling partial frames or saying nothing, in every slot and from one or many
// addresses, against a legitimate client that must get every read; the per-address share;
// half-open, idle and non-reading connections; the slot rule itself. Real server, real sockets
// (127.0.0.0/8 gives a test many peer addresses); the server's counters and poll() deadlines
// are the only synchronisation.

#include "edm/modbus/server_slots.hpp"

#include <fcntl.h>
#include <gtest/gtest.h>
#include <sys/resource.h>
#include <time.h>

#include <algorithm>
#include <atomic>
#include <iostream>
#include <thread>

#include "modbus/raw_client.hpp"
#include "modbus/server_fixture.hpp"

namespace edm::test {
namespace {

using namespace std::chrono_literals;
using Bytes = std::vector<std::uint8_t>;
using Clock = std::chrono::steady_clock;

// Attackers on their own thread: each holds a connection and, every `step`, sends one more
// byte of a frame that announces 253 PDU bytes (260 bytes: 13 s at this pace), or — every
// second one — sends nothing at all. A connection the server closes is opened again at the
// next step, at once.
class Tricklers {
 public:
  Tricklers(int port, std::vector<std::string> from, std::chrono::milliseconds step = 50ms)
      : port_(port), from_(std::move(from)), step_(step) {
    thread_ = std::thread([this] { run(); });
  }
  ~Tricklers() {
    stop_ = true;
    thread_.join();
  }
  [[nodiscard]] std::uint64_t connections() const { return connections_.load(); }

 private:
  void run() {
    struct Slot {
      std::unique_ptr<RawClient> c;
      std::size_t sent{0};
    };
    std::vector<Slot> slots(from_.size());
    const Bytes frame = [] {
      Bytes f = mb_frame({3, 0, 2, 0, 1});
      f[4] = 0;
      f[5] = 254;
      return f;
    }();
    while (!stop_) {
      for (std::size_t i = 0; i < slots.size(); ++i) {
        Slot& s = slots[i];
        if (s.c && s.c->closed_within(0ms)) {
          s.c.reset();
        }
        if (!s.c) {
          s.c = std::make_unique<RawClient>(port_, from_[i]);
          s.sent = 0;
          connections_.fetch_add(1);
        }
        if (i % 2 == 0) {
          const std::uint8_t b = s.sent < frame.size() ? frame[s.sent] : 0;
          if (s.c->send({b})) {
            ++s.sent;
          } else {
            s.c.reset();
          }
        }
      }
      pollfd none{-1, 0, 0};
      ::poll(&none, 0, static_cast<int>(step_.count()));  // the attackers' pace
    }
  }

  int port_;
  std::vector<std::string> from_;
  std::chrono::milliseconds step_;
  std::atomic<bool> stop_{false};
  std::atomic<std::uint64_t> connections_{0};
  std::thread thread_;
};

struct Reads {
  int answered{0};
  Clock::duration worst{};
};

// A legitimate client: `n` reads of holding register 2, one connection for all of them or a new
// one per read (as mbpoll does); each must be answered within `bound`.
Reads legit_reads(int port, const std::string& from, int n, bool connection_per_read,
                  std::chrono::milliseconds bound) {
  Reads out;
  std::unique_ptr<RawClient> c;
  for (int i = 0; i < n; ++i) {
    const auto t0 = Clock::now();
    if (!c || connection_per_read) {
      c = std::make_unique<RawClient>(port, from);
    }
    const auto tid = static_cast<std::uint16_t>(i + 1);
    if (c->send(mb_frame({3, 0, 2, 0, 1}, tid))) {
      const Bytes r = c->reply(bound);
      if (r.size() == 11 && r[1] == (tid & 0xFF) && r[7] == 3) {
        ++out.answered;
        out.worst = std::max(out.worst, Clock::now() - t0);
      }
    }
    pollfd none{-1, 0, 0};
    ::poll(&none, 0, 20);  // the client's own poll period
  }
  return out;
}

std::vector<std::string> addresses(const std::string& prefix, int first, int n) {
  std::vector<std::string> v;
  for (int i = 0; i < n; ++i) v.push_back(prefix + std::to_string(first + i));
  return v;
}

double ms(Clock::duration d) { return std::chrono::duration<double, std::milli>(d).count(); }

// Runs the tricklers, then the legitimate client both ways, for at least `cuts` connections the
// server cut (frame deadline or eviction) while it reads; every read answered within 1 s.
void expect_every_read_answered(ServerFixture& s, const std::vector<std::string>& attackers,
                                const std::string& legit_from, std::uint64_t cuts) {
  Tricklers t(s.port(), attackers);
  // They hold what they can before the legitimate client comes.
  ASSERT_TRUE(ServerFixture::eventually([&] { return s.counters().accepted >= attackers.size(); }));
  const auto before = s.counters();
  int reads = 0;
  Reads persistent;
  Reads per_read;
  // Read while the server cuts the attackers' connections, again and again.
  while (reads < 20 || s.counters().frame_timeouts + s.counters().evicted <
                           before.frame_timeouts + before.evicted + cuts) {
    const Reads a = legit_reads(s.port(), legit_from, 5, false, 1s);
    const Reads b = legit_reads(s.port(), legit_from, 5, true, 1s);
    persistent.answered += a.answered;
    persistent.worst = std::max(persistent.worst, a.worst);
    per_read.answered += b.answered;
    per_read.worst = std::max(per_read.worst, b.worst);
    reads += 5;
    if (a.answered < 5 || b.answered < 5) {
      break;  // a read missed: fail now (below), not after 2000 reads
    }
    ASSERT_LT(reads, 2000) << "the server did not cut the attackers";
  }
  EXPECT_EQ(persistent.answered, reads);
  EXPECT_EQ(per_read.answered, reads);
  const auto k = s.counters();
  std::cout << reads << " + " << reads << " reads from " << legit_from << ", all answered; worst "
            << ms(persistent.worst) << " ms (one connection), " << ms(per_read.worst)
            << " ms (a connection per read); attackers' connections " << t.connections()
            << ", cut at the frame deadline " << k.frame_timeouts << ", evicted " << k.evicted
            << ", refused " << k.refused_clients << "\n";
  EXPECT_LT(persistent.worst, 1s);
  EXPECT_LT(per_read.worst, 1s);
}

// Issue 31 item 10, as the tester ran it: four tricklers in four slots, all on one address (the
// legitimate client too), so only the frame deadline and the slot rule can help. Main: 0 reads.
TEST(ModbusServerSlots, FourTricklersInFourSlotsNeverKeepAClientOfTheirAddressFromItsReads) {
  ServerFixture s("  max_clients: 4\n  max_clients_per_address: 4\n  frame_timeout: 250ms\n");
  expect_every_read_answered(s, std::vector<std::string>(4, "127.0.0.1"), "127.0.0.1", 8);
}

// Every one of max_clients (16) slots held by a trickler, each from an address of its own.
TEST(ModbusServerSlots, TricklersInEverySlotFromManyAddressesNeverKeepAClientFromItsReads) {
  ServerFixture s("  frame_timeout: 250ms\n");
  ASSERT_EQ(s.config().max_clients, 16);
  expect_every_read_answered(s, addresses("127.0.1.", 1, 16), "127.0.0.9", 16);
}

// max_clients tricklers from one address get its share (a quarter) and no more.
TEST(ModbusServerSlots, TricklersFromOneAddressHoldAtMostItsShare) {
  ServerFixture s("  frame_timeout: 250ms\n");
  const std::vector<std::string> one(16, "127.0.0.1");
  std::atomic<bool> done{false};
  std::atomic<std::uint64_t> most{0};
  std::thread watch([&] {  // the most connections open at once
    while (!done) {
      most = std::max<std::uint64_t>(most, s.counters().open);
      pollfd none{-1, 0, 0};
      ::poll(&none, 0, 1);
    }
  });
  expect_every_read_answered(s, one, "127.0.0.2", 16);
  done = true;
  watch.join();
  EXPECT_LE(most.load(), 4U + 2U);  // the share of 127.0.0.1, and the legitimate client's two
  EXPECT_GE(s.counters().evicted, 12U);
}

// A client that rebooted leaves a half-open socket: its next connection from that address
// takes the slot of the oldest one; an address never holds more than its share; when every
// slot serves a client a newcomer from a new address is refused, and none is taken from them.
TEST(ModbusServerSlots, TheNewestConnectionOfAnAddressWinsAndServingClientsAreNotEvicted) {
  ServerFixture s("  max_clients: 4\n  max_clients_per_address: 2\n");
  const auto read_ok = [](RawClient& c) {
    return c.send(mb_frame({3, 0, 2, 0, 1})) && c.reply().size() == 11;
  };
  RawClient a1(s.port(), "127.0.0.1");
  ASSERT_TRUE(read_ok(a1));
  RawClient a2(s.port(), "127.0.0.1");
  ASSERT_TRUE(read_ok(a2));
  // a1 goes silent (half-open); a3 from the same address: a1, the least recent, is closed.
  RawClient a3(s.port(), "127.0.0.1");
  ASSERT_TRUE(read_ok(a3));
  EXPECT_TRUE(a1.closed_within(2s));
  EXPECT_EQ(s.counters().evicted, 1U);
  EXPECT_TRUE(read_ok(a2));
  // Two more addresses fill the four slots; a fifth address is refused at once.
  RawClient b(s.port(), "127.0.0.2");
  ASSERT_TRUE(read_ok(b));
  RawClient c(s.port(), "127.0.0.3");
  ASSERT_TRUE(read_ok(c));
  RawClient d(s.port(), "127.0.0.4");
  EXPECT_TRUE(d.closed_within(2s));
  EXPECT_EQ(s.counters().refused_clients, 1U);
  for (RawClient* x : {&a2, &a3, &b, &c}) {
    EXPECT_TRUE(read_ok(*x));
  }
  EXPECT_EQ(s.counters().open, 4U);
  // A connection that says nothing yet is the first to go for a newcomer of another address.
  // a3 is now mid-frame: a3 goes, not a2, b or c. (Its bytes are queued before e connects, and
  // the server services its clients before it accepts, so it sees them first.)
  ASSERT_TRUE(a3.send({0, 1, 0}));
  RawClient e(s.port(), "127.0.0.5");
  ASSERT_TRUE(read_ok(e));
  EXPECT_TRUE(a3.closed_within(2s));
  for (RawClient* x : {&a2, &b, &c}) {
    EXPECT_TRUE(read_ok(*x));
  }
}

TEST(ModbusServerSlots, SilentAndUnfinishedConnectionsAreClosedAtTheirDeadline) {
  ServerFixture s("  frame_timeout: 100ms\n  idle_timeout: 300ms\n");
  const auto t0 = Clock::now();
  RawClient silent(s.port());
  RawClient partial(s.port());
  ASSERT_TRUE(partial.send({0, 1, 0}));
  EXPECT_TRUE(partial.closed_within(2s));
  const auto partial_at = Clock::now() - t0;
  EXPECT_TRUE(silent.closed_within(3s));
  const auto silent_at = Clock::now() - t0;
  EXPECT_GE(partial_at, 100ms);
  EXPECT_LT(partial_at, 300ms + 500ms);
  EXPECT_GE(silent_at, 300ms);
  EXPECT_EQ(s.counters().frame_timeouts, 1U);
  EXPECT_EQ(s.counters().idle_timeouts, 1U);
}

// A client that sends requests for the longest reply and never reads: once the kernel's buffers
// are full its reply waits, and it is closed a frame deadline later; meanwhile the server
// answers another client at once.
TEST(ModbusServerSlots, AClientThatDoesNotReadItsRepliesIsClosedAndNobodyWaitsForIt) {
  ServerFixture s("  frame_timeout: 100ms\n");
  RawClient hog(s.port(), "127.0.0.2", 4096);
  const int flags = ::fcntl(hog.fd(), F_GETFL);
  ::fcntl(hog.fd(), F_SETFL, flags | O_NONBLOCK);
  const Bytes req = mb_frame({3, 0, 100, 0, 125});
  RawClient other(s.port(), "127.0.0.3");
  std::size_t sent = 0;
  std::size_t at = 0;  // into req: a send may take part of a frame
  int checks = 0;
  Clock::duration worst{};
  while (s.counters().stalled == 0 && sent < 64U * 1024U * 1024U) {
    const ssize_t n = ::send(hog.fd(), req.data() + at, req.size() - at, MSG_NOSIGNAL);
    if (n > 0) {
      sent += static_cast<std::size_t>(n);
      at = (at + static_cast<std::size_t>(n)) % req.size();
    }
    if (n <= 0 || sent % (req.size() * 512) == 0) {  // now and then, and when the hog is full
      const auto t1 = Clock::now();
      ASSERT_TRUE(other.send(mb_frame({3, 0, 2, 0, 1})));
      ASSERT_EQ(other.reply(1s).size(), 11U);
      worst = std::max(worst, Clock::now() - t1);
      ++checks;
    }
    if (n <= 0) {
      pollfd p{hog.fd(), POLLOUT, 0};
      ::poll(&p, 1, 10);  // the hog waits for room, as a client would
      if ((p.revents & (POLLERR | POLLHUP)) != 0) {
        break;
      }
    }
  }
  EXPECT_TRUE(ServerFixture::eventually([&] { return s.counters().stalled == 1U; }));
  EXPECT_TRUE(hog.closed_within(2s));
  ASSERT_TRUE(other.send(mb_frame({3, 0, 2, 0, 1})));
  EXPECT_EQ(other.reply().size(), 11U);
  std::cout << "the hog sent " << sent << " bytes before it was closed; " << checks
            << " reads of another client meanwhile, the slowest " << ms(worst) << " ms\n";
  EXPECT_GT(checks, 0);
  EXPECT_LT(worst, 500ms);
}

// At EMFILE the listening socket stays readable: accept pauses (10 ms doubling to 1 s) instead of
// spinning, and takes the waiting connections once descriptors are free again.
TEST(ModbusServerSlots, OutOfDescriptorsAcceptPausesInsteadOfSpinning) {
  ServerFixture s;
  RawClient early(s.port());  // served before, and during, the shortage
  ASSERT_TRUE(early.send(mb_frame({3, 0, 2, 0, 1})));
  ASSERT_EQ(early.reply().size(), 11U);
  // The client's socket exists before the limit; connecting it needs no descriptor, the
  // server's accept does.
  const int fd = ::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
  ASSERT_GE(fd, 0);
  int open_fds = 0;
  int highest = 0;
  for (int i = 0; i < 4096; ++i) {
    if (::fcntl(i, F_GETFD) != -1) {
      ++open_fds;
      highest = i;
    }
  }
  rlimit before{};
  ASSERT_EQ(::getrlimit(RLIMIT_NOFILE, &before), 0);
  rlimit low = before;
  low.rlim_cur = static_cast<rlim_t>(highest + 1);
  ASSERT_EQ(::setrlimit(RLIMIT_NOFILE, &low), 0);
  std::vector<int> fillers;  // the free numbers below the limit, taken
  for (int d = ::dup(0); d >= 0; d = ::dup(0)) fillers.push_back(d);
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_port = htons(static_cast<std::uint16_t>(s.port()));
  a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  ASSERT_EQ(::connect(fd, reinterpret_cast<sockaddr*>(&a), sizeof a), 0);
  const Bytes req = mb_frame({3, 0, 2, 0, 1});
  ASSERT_EQ(::send(fd, req.data(), req.size(), MSG_NOSIGNAL), static_cast<ssize_t>(req.size()));
  timespec c0{};
  ::clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &c0);
  const auto w0 = Clock::now();
  pollfd p{fd, POLLIN, 0};
  EXPECT_EQ(::poll(&p, 1, 600), 0);  // not accepted: no reply
  ASSERT_TRUE(early.send(req));      // an open connection is still served
  EXPECT_EQ(early.reply().size(), 11U);
  timespec c1{};
  ::clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &c1);
  const double cpu_s = static_cast<double>(c1.tv_sec - c0.tv_sec) +
                       static_cast<double>(c1.tv_nsec - c0.tv_nsec) * 1e-9;
  const double wall_s = std::chrono::duration<double>(Clock::now() - w0).count();
  for (const int d : fillers) ::close(d);
  ASSERT_EQ(::setrlimit(RLIMIT_NOFILE, &before), 0);
  std::cout << "at EMFILE: " << cpu_s * 1000 << " ms of CPU in " << wall_s * 1000 << " ms ("
            << open_fds << " descriptors open)\n";
  EXPECT_LT(cpu_s, 0.25 * wall_s);  // a spinning accept loop takes a whole core
  // Descriptors again: the waiting connection is accepted within the back-off (≤ 1 s).
  EXPECT_EQ(::poll(&p, 1, 3000), 1);
  std::uint8_t r[32];
  EXPECT_EQ(::recv(fd, r, sizeof r, 0), 11);
  ::close(fd);
}

using modbus::Admission;
using modbus::SlotState;
using Use = SlotState::Use;

TEST(ModbusSlotPolicy, TheLeastUsefulGoesAndServingClientsOfOtherAddressesStay) {
  const Clock::time_point t{};
  const auto at = [&](int s) { return t + std::chrono::seconds(s); };
  // Full (4), the newcomer's address under its share: the oldest kNew goes, before kStuck.
  std::vector<SlotState> slots{{1, Use::kServing, at(1)},
                               {2, Use::kStuck, at(2)},
                               {3, Use::kNew, at(5)},
                               {4, Use::kNew, at(3)}};
  Admission a = modbus::admit(slots, 9, 4, 2);
  EXPECT_EQ(a.kind, Admission::Kind::kEvictAndAdmit);
  EXPECT_EQ(a.victim, 3U);
  slots[2].use = slots[3].use = Use::kServing;
  a = modbus::admit(slots, 9, 4, 2);
  EXPECT_EQ(a.victim, 1U);  // then a stuck one
  slots[1].use = Use::kServing;
  EXPECT_EQ(modbus::admit(slots, 9, 4, 2).kind, Admission::Kind::kRefuse);
  // At its share, an address's newcomer replaces its least recent serving connection.
  slots = {{7, Use::kServing, at(4)}, {7, Use::kServing, at(2)}, {8, Use::kNew, at(1)}};
  a = modbus::admit(slots, 7, 4, 2);
  EXPECT_EQ(a.kind, Admission::Kind::kEvictAndAdmit);
  EXPECT_EQ(a.victim, 1U);
  // Room: admitted.
  EXPECT_EQ(modbus::admit(slots, 8, 4, 2).kind, Admission::Kind::kAdmit);
  EXPECT_EQ(modbus::admit({}, 8, 1, 1).kind, Admission::Kind::kAdmit);
}

}  // namespace
}  // namespace edm::test
