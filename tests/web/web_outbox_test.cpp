// The byte-bounded outgoing queue per browser (hmi/include/edm/hmi/web_outbox.hpp, issue 31
// item 3), the connection caps and the back-off (web_limits.hpp, web_backoff.hpp, item 4).
#include "edm/hmi/web_outbox.hpp"

#include <gtest/gtest.h>

#include <vector>

#include "edm/hmi/web_backoff.hpp"
#include "edm/hmi/web_limits.hpp"

namespace edm::hmi::test {
namespace {

using namespace std::chrono_literals;

std::shared_ptr<const std::string> bytes(std::size_t n) {
  return std::make_shared<const std::string>(n, 'j');
}

// A socket that asks for the 2 MiB job again and again and never reads.
TEST(WebOutbox, a_reader_that_never_reads_is_closed_at_the_byte_bound) {
  std::size_t total = 0;
  WebOutbox out(total);
  const std::size_t job = 2u << 20;
  EXPECT_EQ(out.push(bytes(job + 100), WebOutbox::Kind::kReply), WebOutbox::Push::kStartWrite);
  EXPECT_EQ(out.push(bytes(job / 2), WebOutbox::Kind::kReply), WebOutbox::Push::kQueued);
  EXPECT_EQ(out.push(bytes(job), WebOutbox::Kind::kReply), WebOutbox::Push::kOverflow);
  EXPECT_LE(out.bytes(), kMaxQueuedBytes);
  EXPECT_EQ(total, out.bytes());
  // Frames fill what is left, then are dropped and counted, never queued past the bound.
  std::size_t queued = 0;
  for (int i = 0; i < 1000; ++i) {
    queued += out.push(bytes(4096), WebOutbox::Kind::kFrame) == WebOutbox::Push::kQueued;
  }
  EXPECT_LE(out.bytes(), kMaxQueuedBytes);
  EXPECT_LE(queued * 4096, kMaxQueuedBytes - job - 100 - job / 2);
  EXPECT_EQ(out.dropped(), 1000u - queued);
}

TEST(WebOutbox, one_message_always_fits_an_empty_queue_and_writes_drain_it) {
  std::size_t total = 0;
  {
    WebOutbox out(total);
    EXPECT_EQ(out.push(bytes(kMaxQueuedBytes + 1), WebOutbox::Kind::kReply),
              WebOutbox::Push::kStartWrite);
    EXPECT_FALSE(out.pop());
    for (int i = 0; i < 10; ++i) out.push(bytes(1000), WebOutbox::Kind::kFrame);
    EXPECT_EQ(out.front().size(), 1000u);
    EXPECT_EQ(total, 10000u);
  }
  EXPECT_EQ(total, 0u) << "a closed socket gives its bytes back";
}

TEST(WebOutbox, messages_count_too) {
  std::size_t total = 0;
  WebOutbox out(total);
  std::size_t queued = 0;
  for (std::size_t i = 0; i < 2 * kMaxQueuedMessages; ++i) {
    const auto r = out.push(bytes(1), WebOutbox::Kind::kFrame);
    queued += r == WebOutbox::Push::kQueued || r == WebOutbox::Push::kStartWrite;
  }
  EXPECT_EQ(queued, kMaxQueuedMessages);
}

// N sockets that never read: the bytes held by all of them stay under the shared bound plus one
// message each.
TEST(WebOutbox, the_servers_total_is_bounded_across_sockets) {
  std::size_t total = 0;
  std::vector<std::unique_ptr<WebOutbox>> sockets;
  for (int i = 0; i < 64; ++i) sockets.push_back(std::make_unique<WebOutbox>(total));
  const std::size_t msg = 3u << 20;  // a welcome with a 2 MiB program and its toolpath
  for (auto& s : sockets) {
    for (int k = 0; k < 4; ++k) {
      if (s->push(bytes(msg), WebOutbox::Kind::kReply) == WebOutbox::Push::kOverflow) break;
    }
  }
  EXPECT_LE(total, kMaxTotalQueuedBytes + sockets.size() * msg);
  std::size_t sum = 0;
  for (auto& s : sockets) sum += s->bytes();
  EXPECT_EQ(sum, total);
}

TEST(WebLimits, connection_slots_per_address_and_in_all) {
  auto c = std::make_shared<ConnectionCounter>(5, 2);
  auto a1 = c->acquire("a");
  auto a2 = c->acquire("a");
  EXPECT_TRUE(a1 && a2);
  EXPECT_FALSE(c->acquire("a")) << "a third from one address";
  auto b1 = c->acquire("b"), b2 = c->acquire("b"), d1 = c->acquire("d");
  EXPECT_TRUE(b1 && b2 && d1);
  EXPECT_FALSE(c->acquire("e")) << "five in all";
  a1.reset();
  EXPECT_EQ(c->total(), 4u);
  EXPECT_TRUE(c->acquire("e"));
}

TEST(WebBackoff, ten_ms_doubling_to_one_second_one_episode) {
  Backoff b(10ms, 1000ms);
  bool first = false;
  EXPECT_EQ(b.fail(&first), 10ms);
  EXPECT_TRUE(first);
  std::chrono::milliseconds last{};
  for (int i = 0; i < 20; ++i) {
    last = b.fail(&first);
    EXPECT_FALSE(first) << "logged once per episode";
  }
  EXPECT_EQ(last, 1000ms);
  EXPECT_EQ(b.succeed(), 21u);
  EXPECT_EQ(b.fail(&first), 10ms);
  EXPECT_TRUE(first);
}

}  // namespace
}  // namespace edm::hmi::test
