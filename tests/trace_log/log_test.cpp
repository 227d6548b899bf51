// The runtime's non-RT logging (log.hpp): the asynchronous logger and its orderly shutdown.
#include "edm/runtime/log.hpp"

#include <gtest/gtest.h>
#include <spdlog/spdlog.h>

#include <string>

namespace edm::rt {
namespace {

TEST(Logging, init_logs_asynchronously_and_shutdown_flushes_then_logs_synchronously) {
  ::testing::internal::CaptureStderr();
  init_logging(spdlog::level::info);
  init_logging(spdlog::level::info);  // idempotent
  spdlog::debug("below the level {}", 1);
  spdlog::warn("short circuit at {:.3f} mm", 1.25);
  spdlog::info("plain non-RT message {}", 42);
  shutdown_logging();                    // joins the async writer: everything is out now
  shutdown_logging();                    // idempotent
  spdlog::info("after shutdown {}", 7);  // still works, synchronously
  const std::string err = ::testing::internal::GetCapturedStderr();

  EXPECT_NE(err.find("short circuit at 1.250 mm"), std::string::npos) << err;
  EXPECT_NE(err.find("[warning]"), std::string::npos) << err;
  EXPECT_NE(err.find("plain non-RT message 42"), std::string::npos) << err;
  EXPECT_LT(err.find("short circuit"), err.find("plain non-RT message")) << "in order";
  EXPECT_EQ(err.find("below the level"), std::string::npos) << err;
  EXPECT_NE(err.find("after shutdown 7"), std::string::npos) << err;
}

}  // namespace
}  // namespace edm::rt
