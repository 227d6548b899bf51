#include "edm/sparkplug/inbound.hpp"

namespace edm::sparkplug {

namespace {

// Protobuf's wire types (developers.google.com/protocol-buffers/docs/encoding).
enum WireType : std::uint64_t { kVarint = 0, kFixed64 = 1, kLen = 2, kFixed32 = 5 };
constexpr std::uint64_t kMetricsField = 2;  // Payload.metrics (sparkplug_b.proto)

class Wire {
 public:
  explicit Wire(std::string_view b) noexcept : b_(b) {}
  [[nodiscard]] bool done() const noexcept { return at_ == b_.size(); }
  bool varint(std::uint64_t& v) noexcept {
    v = 0;
    for (int shift = 0; shift < 64; shift += 7) {
      if (at_ == b_.size()) return false;
      const auto byte = static_cast<unsigned char>(b_[at_++]);
      v |= static_cast<std::uint64_t>(byte & 0x7Fu) << shift;
      if ((byte & 0x80u) == 0) return true;
    }
    return false;  // more than 10 bytes
  }
  bool skip(std::uint64_t n) noexcept {
    if (n > b_.size() - at_) return false;
    at_ += static_cast<std::size_t>(n);
    return true;
  }

 private:
  std::string_view b_;
  std::size_t at_{0};
};

}  // namespace

ScreenResult screen_payload(std::string_view bytes, const InboundLimits& limits) noexcept {
  ScreenResult r;
  r.bytes = bytes.size();
  if (bytes.size() > limits.max_payload_bytes) {
    r.verdict = Screen::kTooLarge;
    return r;
  }
  Wire w(bytes);
  while (!w.done()) {
    std::uint64_t tag = 0;
    std::uint64_t v = 0;
    if (!w.varint(tag) || (tag >> 3) == 0) {
      r.verdict = Screen::kMalformed;
      return r;
    }
    const std::uint64_t field = tag >> 3;
    bool ok = false;
    switch (tag & 7u) {
      case kVarint: ok = field != kMetricsField && w.varint(v); break;
      case kFixed64: ok = field != kMetricsField && w.skip(8); break;
      case kFixed32: ok = field != kMetricsField && w.skip(4); break;
      case kLen:
        ok = w.varint(v) && w.skip(v);
        if (field == kMetricsField) ++r.metrics;
        break;
      default:  // groups (3, 4: deprecated, not in the schema) and the unused 6, 7
        break;
    }
    if (!ok) {
      r.verdict = Screen::kMalformed;
      return r;
    }
  }
  if (r.metrics > limits.max_metrics) r.verdict = Screen::kTooManyMetrics;
  return r;
}

}  // namespace edm::sparkplug
