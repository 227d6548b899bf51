// The op surface once more, as an attacker would (issue 31, after items 6-8 and 14): what a
// valid session's small request could still make the server echo or allocate.
//  - a near-1 MiB name or duration text was quoted whole in the reply (the registry's and the
//    duration parser's messages);
//  - one program.begin of 1,000,000 blocks reserved 150 MB at once (8 sessions: 1.2 GB);
//  - one chunk "[0,0,0,…]" was decoded into a vector as long as the array (500,000 blocks, 70 MB)
//    before the first element was found bad.
#include <gtest/gtest.h>
#include <malloc.h>

#include "../../hmi_bridge/server/src/ops_body.hpp"  // decode_blocks: internal, header-only
#include "bridge_fixture.hpp"

namespace edm::bridge::test {
namespace {

using namespace std::chrono_literals;

class AttackerReview : public BridgeFixture {};

TEST_F(AttackerReview, a_huge_name_or_duration_is_never_echoed) {
  start();
  Client c;
  ASSERT_EQ(c.connect(client_opts()), Role::kOperator);
  const std::string huge(900'000, 'n');
  const std::vector<std::pair<const char*, Json>> requests = {
      {"var.write", {{"name", huge}, {"value", 1.0}}},
      {"var.write", {{"name", huge}, {"value", "2ms"}}},
      {"var.force", {{"name", huge}, {"value", 1.0}}},
      {"var.unforce", {{"name", huge}}},
      {"var.read", {{"name", huge}}},
      {"var.read", {{"names", {"io.ai0", huge}}}},
      {"trace.start", {{"vars", {huge}}}},
      {"var.write", {{"name", "chain.g.k"}, {"value", huge + "ms"}}},
      {"subscribe", {{"topics", {huge}}}},
      {"offset.set", {{"frame", huge}, {"x", 1.0}}},
      {"touch", {{"target", huge}}},
      {"home", {{"axes", huge}}},
      {"program.commit", {{"checksum", huge}}},
      {huge.c_str(), Json::object()},
  };
  for (const auto& [op, params] : requests) {
    const Reply r = c.request(op, params);
    ASSERT_FALSE(r.ok) << std::string(op).substr(0, 20);
    ASSERT_TRUE(r.code.has_value()) << std::string(op).substr(0, 20) << ": " << r.message;
    EXPECT_LT(r.body.dump().size(), 600u)
        << std::string(op).substr(0, 20) << " echoed: " << r.message.substr(0, 200);
  }
  EXPECT_TRUE(c.request("ping")) << "the session goes on";
}

TEST_F(AttackerReview, program_begin_does_not_reserve_the_announced_size_up_front) {
  start();
  std::vector<std::unique_ptr<Client>> clients;
  const std::size_t mapped_before = mallinfo2().hblkhd;
  for (int i = 0; i < 7; ++i) {
    clients.push_back(std::make_unique<Client>());
    ASSERT_EQ(clients.back()->connect(client_opts()), Role::kOperator);
    ASSERT_TRUE(clients.back()->request("program.begin", {{"blocks", kMaxProgramBlocks}}));
  }
  const std::size_t mapped_after = mallinfo2().hblkhd;
  const double grew_mb =
      (static_cast<double>(mapped_after) - static_cast<double>(mapped_before)) / (1024.0 * 1024.0);
  std::printf("7 uploads of 1,000,000 blocks announced: +%.1f MB mapped\n", grew_mb);
  EXPECT_LT(grew_mb, 50.0) << "about 150 MB a session before";
}

TEST(DecodeBlocks, a_hostile_array_costs_nothing_before_its_first_bad_element) {
  Json zeros = Json::array();
  for (int i = 0; i < 500'000; ++i) zeros.push_back(0);
  std::vector<machining::MotionBlock> out;
  std::string why;
  EXPECT_EQ(ops::decode_blocks(zeros, out, why), std::optional<std::size_t>(0));
  EXPECT_EQ(out.capacity(), 0u) << "nothing allocated for the 500,000 elements";
  Json some = Json::array({{{"kind", "end"}}, {{"kind", "end"}}, {{"kind", "nope"}}});
  EXPECT_EQ(ops::decode_blocks(some, out, why), std::optional<std::size_t>(2));
  EXPECT_EQ(out.size(), 2u);
  EXPECT_NE(why.find("kind"), std::string::npos) << why;
}

}  // namespace
}  // namespace edm::bridge::test
