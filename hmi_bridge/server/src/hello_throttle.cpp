#include "edm/bridge/hello_throttle.hpp"

#include <algorithm>

namespace edm::bridge {

std::string HelloThrottle::key_of(const std::string& address, std::string_view peer) {
  // A valid peer is printable ASCII, so the newline cannot occur in either part.
  std::string k = address;
  if (!peer.empty()) {
    k.push_back('\n');
    k.append(peer);
  }
  return k;
}

HelloThrottle::Clock::time_point HelloThrottle::aggregate_at(const std::string& address,
                                                             Clock::time_point now) {
  const auto it = addresses_.find(address);
  if (it == addresses_.end()) return now;
  const Address& a = it->second;
  if (now - a.newest() > kForgetAfter) {
    addresses_.erase(it);
    return now;
  }
  if (a.count < kAggregateFailures) return now;
  // Full: the oldest of the last kAggregateFailures must leave the window first.
  return std::max(now, a.times[a.next] + kForgetAfter);
}

HelloThrottle::Clock::time_point HelloThrottle::admit_at(const std::string& address,
                                                         std::string_view peer,
                                                         Clock::time_point now) {
  Clock::time_point at = aggregate_at(address, now);
  const auto it = keys_.find(key_of(address, peer));
  if (it == keys_.end()) return at;
  if (it->second.forgotten(now)) {
    keys_.erase(it);
    return at;
  }
  return std::max(at, it->second.admit_at);
}

std::chrono::milliseconds HelloThrottle::on_failure(const std::string& address,
                                                    std::string_view peer, Clock::time_point now) {
  ++failures_;
  const std::string k = key_of(address, peer);
  auto it = keys_.find(k);
  if (it == keys_.end()) {
    if (keys_.size() >= max_keys_) forget_stalest(keys_);
    it = keys_.emplace(k, Key{}).first;
  }
  Key& p = it->second;
  p.fail(now);

  auto a = addresses_.find(address);
  if (a == addresses_.end()) {
    if (addresses_.size() >= max_keys_) forget_stalest(addresses_);
    a = addresses_.emplace(address, Address{}).first;
  } else if (now - a->second.newest() > kForgetAfter) {
    a->second = Address{};
  }
  Address& ad = a->second;
  ad.times[ad.next] = now;
  ad.next = (ad.next + 1) % kAggregateFailures;
  ad.count = std::min(ad.count + 1, kAggregateFailures);

  const Clock::time_point at = std::max(p.admit_at, aggregate_at(address, now));
  return std::chrono::ceil<std::chrono::milliseconds>(at - now);
}

template <class Map>
void HelloThrottle::forget_stalest(Map& map) {
  const auto last = [](const auto& v) {
    if constexpr (std::is_same_v<std::decay_t<decltype(v)>, Key>) {
      return v.last_failure;
    } else {
      return v.newest();
    }
  };
  auto stalest = map.begin();
  for (auto it = map.begin(); it != map.end(); ++it) {
    if (last(it->second) < last(stalest->second)) stalest = it;
  }
  if (stalest != map.end()) map.erase(stalest);
}

}  // namespace edm::bridge
