#include "edm/hmi/web_login.hpp"

#include <algorithm>

namespace edm::hmi {

std::optional<LoginThrottle::Clock::time_point> LoginThrottle::admit_at(const std::string& address,
                                                                        Clock::time_point now) {
  const auto it = peers_.find(address);
  if (it == peers_.end()) return now;
  Peer& p = it->second;
  if (p.checking) return std::nullopt;
  if (p.failures == 0 || p.forgotten(now)) {
    peers_.erase(it);
    return now;
  }
  return p.admit_at;
}

LoginThrottle::Peer& LoginThrottle::peer(const std::string& address) {
  auto it = peers_.find(address);
  if (it == peers_.end()) {
    if (peers_.size() >= max_addresses_) forget_stalest();
    it = peers_.emplace(address, Peer{}).first;
  }
  return it->second;
}

void LoginThrottle::begin(const std::string& address) { peer(address).checking = true; }

std::chrono::milliseconds LoginThrottle::on_failure(const std::string& address,
                                                    Clock::time_point now) {
  ++failures_;
  Peer& p = peer(address);
  p.checking = false;
  return p.fail(now);
}

void LoginThrottle::on_success(const std::string& address) {
  // The failures are kept (forgotten kForgetAfter after the last): a viewer's right token must
  // not reset the throttle of someone at that address guessing the operator's.
  on_abandon(address);
}

void LoginThrottle::on_abandon(const std::string& address) {
  const auto it = peers_.find(address);
  if (it == peers_.end()) return;
  it->second.checking = false;
  if (it->second.failures == 0) peers_.erase(it);
}

void LoginThrottle::forget_stalest() {
  // The stalest record that is not being checked (a check in progress keeps its record).
  auto stalest = peers_.end();
  for (auto it = peers_.begin(); it != peers_.end(); ++it) {
    if (it->second.checking) continue;
    if (stalest == peers_.end() || it->second.last_failure < stalest->second.last_failure) {
      stalest = it;
    }
  }
  if (stalest != peers_.end()) peers_.erase(stalest);
}

}  // namespace edm::hmi
