#include "edm/telemetry/command_intake.hpp"

#include <algorithm>
#include <unordered_set>
#include <utility>

#include "edm/runtime/log_escape.hpp"

namespace edm::telemetry {

namespace {

namespace sp = sparkplug;

// By CommandIntake::Drop: the rate limiter's key, and what a summary counts.
constexpr std::array<std::string_view, 6> kKey{
    {"foreign", "retained", "too_large", "inbox_full", "too_many_metrics", "malformed"}};
constexpr std::array<std::string_view, 6> kWhat{{
    "messages on topics that are not this node's NCMD/DCMD dropped",
    "retained NCMD/DCMD dropped",
    "NCMD/DCMD over mqtt.limits.max_payload_bytes dropped unread",
    "NCMD/DCMD dropped with the inbox full",
    "NCMD/DCMD over mqtt.limits.max_metrics dropped unread",
    "NCMD/DCMD that are not Sparkplug B payloads dropped",
}};

std::string value_text(const sp::Metric& m) {
  if (const auto* s = std::get_if<std::string>(&m.value)) return rt::log_quote(*s, 40);
  return sp::to_text(m.value);
}

std::string type_text(sp::MessageType t) { return std::string(sp::to_string(t)); }

}  // namespace

CommandIntake::CommandIntake(IntakeOptions options, CommandHandler handler)
    : opt_(std::move(options)),
      handler_(std::move(handler)),
      inbox_cap_bytes_(
          std::max<std::size_t>(std::size_t{1} << 20, 4 * opt_.limits.max_payload_bytes)) {
  static_assert(kKey.size() == kDropCount && kWhat.size() == kDropCount);
}

void CommandIntake::offer(std::string_view topic, std::string_view payload, bool retained) {
  const bool dcmd = topic == opt_.dcmd_topic;
  Drop why = kDropCount;
  if (!dcmd && topic != opt_.ncmd_topic) {
    why = kForeign;
  } else if (retained) {
    why = kRetained;
  } else if (payload.size() > opt_.limits.max_payload_bytes) {
    why = kTooLarge;  // not copied, not looked into
  }
  std::lock_guard lock(mu_);
  if (why == kDropCount &&
      (inbox_.size() >= kInboxMessages || payload.size() > inbox_cap_bytes_ - inbox_bytes_)) {
    why = kInboxFull;
  }
  if (why != kDropCount) {
    Seen& s = seen_[why];
    if (s.count++ == 0) {
      s.bytes = payload.size();
      s.dcmd = dcmd;
      s.topic.assign(topic.substr(0, kTopicKept));
    }
    return;
  }
  inbox_.push_back({dcmd ? sp::MessageType::kDCmd : sp::MessageType::kNCmd, std::string(payload)});
  inbox_bytes_ += payload.size();
}

bool CommandIntake::process(Clock::time_point now) {
  std::deque<Message> inbox;
  std::array<Seen, kOfferDrops> seen{};
  {
    std::lock_guard lock(mu_);
    inbox.swap(inbox_);
    inbox_bytes_ = 0;
    seen.swap(seen_);
  }
  sweep(now, kEpisode);
  for (std::size_t k = 0; k < kOfferDrops; ++k) {
    const Seen& s = seen[k];
    if (s.count == 0) continue;
    const std::string type = s.dcmd ? "DCMD" : "NCMD";
    drop_seen(static_cast<Drop>(k), s.count, now, [&] {
      switch (k) {
        case kForeign:
          return "mqtt: dropped a message on " + rt::log_quote(s.topic) +
                 ": not this node's NCMD or DCMD topic";
        case kRetained:
          return "mqtt: dropped a retained " + type +
                 ": Sparkplug commands are never retained (one would be replayed at every "
                 "connect; clear it on the broker)";
        case kTooLarge:
          return "mqtt: dropped a " + type + " of " + std::to_string(s.bytes) +
                 " bytes unread: over mqtt.limits.max_payload_bytes (" +
                 std::to_string(opt_.limits.max_payload_bytes) + ")";
        default:
          return "mqtt: dropped a " + type + ": the inbox is full (" +
                 std::to_string(kInboxMessages) + " messages or " +
                 std::to_string(inbox_cap_bytes_) + " bytes wait for the publisher)";
      }
    });
  }
  bool rebirth = false;
  for (const Message& m : inbox) rebirth = handle(m, now) || rebirth;
  return rebirth;
}

void CommandIntake::finish(Clock::time_point now) { sweep(now, std::chrono::milliseconds(0)); }

template <class Line>
void CommandIntake::drop_seen(Drop kind, std::uint64_t count, Clock::time_point now, Line line) {
  dropped_.fetch_add(count, std::memory_order_relaxed);
  std::uint64_t held = 0;  // lines the limiter held back: untold_ has their messages
  if (!drop_lines_.admit(kKey[kind], now, held)) {
    untold_[kind] += count;
    return;
  }
  const std::uint64_t more = count - 1 + std::exchange(untold_[kind], 0);
  std::string text = line();
  if (more > 0) text += "; " + std::to_string(more) + " more like it not logged one by one";
  text += "; Commands/dropped " + std::to_string(dropped()) + " (told at most once per " +
          std::to_string(kEpisode.count()) + " s)";
  if (opt_.warn) opt_.warn(text);
}

void CommandIntake::audit(const std::string& key, const std::string& line, Clock::time_point now) {
  std::uint64_t held = 0;
  if (audit_lines_.admit(key, now, held) && opt_.info) opt_.info(line + rt::suppressed_note(held));
}

void CommandIntake::sweep(Clock::time_point now, std::chrono::milliseconds quiet) {
  drop_lines_.sweep(now, quiet, [&](const std::string& key, std::uint64_t /*lines*/) {
    const auto at = std::find(kKey.begin(), kKey.end(), key);
    if (at == kKey.end()) return;
    const auto k = static_cast<std::size_t>(at - kKey.begin());
    const std::uint64_t n = std::exchange(untold_[k], 0);
    if (n > 0 && opt_.warn) {
      opt_.warn("mqtt: " + std::to_string(n) + " more " + std::string(kWhat[k]) +
                ", not logged one by one; Commands/dropped " + std::to_string(dropped()));
    }
  });
  audit_lines_.sweep(now, quiet, [&](const std::string& key, std::uint64_t n) {
    if (opt_.info) {
      opt_.info("mqtt audit: " + std::to_string(n) + " more command lines (" + key +
                ") not logged one by one; Commands/accepted " + std::to_string(accepted()) +
                ", Commands/refused " + std::to_string(refused()));
    }
  });
}

bool CommandIntake::handle(const Message& msg, Clock::time_point now) {
  const std::string type = type_text(msg.type);
  const sp::ScreenResult sr = sp::screen_payload(msg.payload, opt_.limits);
  if (sr.verdict == sp::Screen::kTooManyMetrics) {
    drop_seen(kTooManyMetrics, 1, now, [&] {
      return "mqtt: dropped a " + type + " of " + std::to_string(sr.metrics) +
             " metrics unread: over mqtt.limits.max_metrics (" +
             std::to_string(opt_.limits.max_metrics) + ")";
    });
    return false;
  }
  std::optional<sp::Payload> p;
  if (sr.verdict == sp::Screen::kOk) p = sp::decode(msg.payload);
  if (!p) {
    drop_seen(kMalformed, 1, now, [&] {
      return "mqtt: dropped a " + type + " of " + std::to_string(sr.bytes) +
             " bytes: not a Sparkplug B payload";
    });
    return false;
  }
  {
    // A metric twice in one message: which value was meant? None of its metrics is written.
    std::unordered_set<std::string_view> names;
    names.reserve(p->metrics.size());
    for (const sp::Metric& m : p->metrics) {
      if (m.name.empty() || names.insert(m.name).second) continue;
      refused_.fetch_add(p->metrics.size(), std::memory_order_relaxed);
      audit("refused",
            "mqtt audit: " + type + " from broker " + opt_.broker + ": refused: the metric " +
                rt::log_quote(m.name) + " appears more than once; none of its " +
                std::to_string(p->metrics.size()) + " metrics is written",
            now);
      return false;
    }
  }
  bool rebirth = false;
  for (const sp::Metric& m : p->metrics) {
    std::string why = "commands are off (mqtt.commands.enabled)";
    CommandOutcome out = CommandOutcome::kRefused;
    if (m.name.empty()) {
      why = m.alias ? "a metric by alias " + std::to_string(*m.alias) +
                          " only: edmplc defines no aliases (send the metric's name)"
                    : "a metric without a name";
    } else if (msg.type == sp::MessageType::kNCmd && m.name == sp::kRebirth) {
      if (m.type == sp::DataType::kBoolean && m.value_ok && std::holds_alternative<bool>(m.value)) {
        rebirth = rebirth || std::get<bool>(m.value);
        continue;
      }
      why = "Node Control/Rebirth takes a Boolean";
    } else if (handler_) {
      out = handler_(msg.type, m, why);
    }
    const bool ok = out == CommandOutcome::kWritten;
    (ok ? accepted_ : refused_).fetch_add(1, std::memory_order_relaxed);
    if (out == CommandOutcome::kOutOfRange) out_of_range_.fetch_add(1, std::memory_order_relaxed);
    std::uint64_t held = 0;
    if (!audit_lines_.admit(ok ? "written" : "refused", now, held) || !opt_.info) continue;
    opt_.info("mqtt audit: " + type + " " + rt::log_quote(m.name) + "=" + value_text(m) + " (" +
              std::string(sp::to_string(m.type)) + ") from broker " + opt_.broker + ": " +
              (ok ? std::string("written") : "refused: " + why) + rt::suppressed_note(held));
  }
  return rebirth;
}

}  // namespace edm::telemetry
