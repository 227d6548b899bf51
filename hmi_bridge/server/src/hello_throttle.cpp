#include "edm/bridge/hello_throttle.hpp"

#include <algorithm>

namespace edm::bridge {

HelloThrottle::Clock::time_point HelloThrottle::admit_at(const std::string& address,
                                                         Clock::time_point now) {
  const auto it = peers_.find(address);
  if (it == peers_.end()) {
    return now;
  }
  if (now - it->second.last_failure > kForgetAfter) {
    peers_.erase(it);
    return now;
  }
  return it->second.admit_at;
}

std::chrono::milliseconds HelloThrottle::on_failure(const std::string& address,
                                                    Clock::time_point now) {
  ++failures_;
  auto it = peers_.find(address);
  if (it == peers_.end()) {
    if (peers_.size() >= max_peers_) {
      forget_stalest();
    }
    it = peers_.emplace(address, Peer{}).first;
  }
  Peer& p = it->second;
  if (p.failures > 0 && now - p.last_failure > kForgetAfter) {
    p.failures = 0;
  }
  ++p.failures;
  p.last_failure = now;
  const int shift = static_cast<int>(std::min<std::uint32_t>(p.failures - 1, 16));
  const auto delay = std::min<std::chrono::milliseconds>(kBaseDelay * (1LL << shift), kMaxDelay);
  p.admit_at = now + delay;
  return delay;
}

void HelloThrottle::on_success(const std::string& address) { peers_.erase(address); }

void HelloThrottle::forget_stalest() {
  auto stalest = peers_.begin();
  for (auto it = peers_.begin(); it != peers_.end(); ++it) {
    if (it->second.last_failure < stalest->second.last_failure) {
      stalest = it;
    }
  }
  if (stalest != peers_.end()) {
    peers_.erase(stalest);
  }
}

}  // namespace edm::bridge
