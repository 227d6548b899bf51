#include "edm/runtime/manual.hpp"

namespace edm::rt {

std::string_view to_string(ManualOp op) noexcept {
  switch (op) {
    case ManualOp::kNone: return "none";
    case ManualOp::kHome: return "home";
    case ManualOp::kJogDistance:
    case ManualOp::kJogVelocity: return "jog";
    case ManualOp::kTouch: return "touch";
    case ManualOp::kStop: return "stop";
  }
  return "none";
}

std::string_view to_string(TouchTarget t) noexcept {
  switch (t) {
    case TouchTarget::kZ: return "z";
    case TouchTarget::kXPlus: return "x+";
    case TouchTarget::kXMinus: return "x-";
    case TouchTarget::kYPlus: return "y+";
    case TouchTarget::kYMinus: return "y-";
    case TouchTarget::kCenter: return "center";
  }
  return "z";
}

bool touch_target_from_string(std::string_view s, TouchTarget& out) noexcept {
  for (TouchTarget t : {TouchTarget::kZ, TouchTarget::kXPlus, TouchTarget::kXMinus,
                        TouchTarget::kYPlus, TouchTarget::kYMinus, TouchTarget::kCenter}) {
    if (s == to_string(t)) {
      out = t;
      return true;
    }
  }
  return false;
}

std::string_view to_string(ManualMode m) noexcept {
  switch (m) {
    case ManualMode::kIdle: return "idle";
    case ManualMode::kHome: return "home";
    case ManualMode::kJog: return "jog";
    case ManualMode::kTouch: return "touch";
  }
  return "idle";
}

std::string_view to_string(ManualError e) noexcept {
  switch (e) {
    case ManualError::kNone: return "";
    case ManualError::kStopped: return "stopped by the operator";
    case ManualError::kDeadman: return "dead-man: the jog was not refreshed in time";
    case ManualError::kNoContact: return "no contact within the search distance";
    case ManualError::kAlreadyInContact: return "the electrode already touches the work";
    case ManualError::kSoftLimit: return "the move would leave the soft limits";
    case ManualError::kNoSwitch:
      return "the reference switch did not trip within the search distance";
    case ManualError::kInterrupted: return "interrupted: the machine left READY";
    case ManualError::kNotAvailable: return "not available on this machine";
    case ManualError::kBadRequest: return "out of range";
  }
  return "";
}

std::string_view error_code(ManualError e) noexcept {
  switch (e) {
    case ManualError::kNone: return "";
    case ManualError::kStopped: return "stopped";
    case ManualError::kDeadman: return "deadman";
    case ManualError::kNoContact: return "no_contact";
    case ManualError::kAlreadyInContact: return "in_contact";
    case ManualError::kSoftLimit: return "soft_limit";
    case ManualError::kNoSwitch: return "no_switch";
    case ManualError::kInterrupted: return "interrupted";
    case ManualError::kNotAvailable: return "not_available";
    case ManualError::kBadRequest: return "bad_request";
  }
  return "";
}

void ManualControl::attach(const ManualInfo& info, std::uint8_t referenced_at_start) noexcept {
  info_.store(info);
  reference_required_.store(info.reference_required, std::memory_order_release);
  referenced_.store(referenced_at_start, std::memory_order_release);
}

ManualInfo ManualControl::info() const noexcept { return info_.load(); }

std::uint64_t ManualControl::request(ManualRequest r) noexcept {
  const std::lock_guard<std::mutex> lock(writer_);
  r.seq = next_seq_ + 1;
  if (!queue_.push(r)) return 0;  // full: the RT side has not taken 16 requests
  next_seq_ = r.seq;
  newest_op_ = r.op;
  return r.seq;
}

ManualOp ManualControl::activity() const noexcept {
  // The status first: a request taken after this load still counts as pending (conservative).
  const ManualStatus st = status_.load();
  const std::lock_guard<std::mutex> lock(writer_);
  if (next_seq_ > st.seen_seq) {
    return newest_op_ == ManualOp::kStop ? ManualOp::kNone : newest_op_;
  }
  return st.busy ? st.op : ManualOp::kNone;
}

bool ManualControl::rt_poll(ManualRequest& out, std::uint64_t& last_seq) noexcept {
  ManualRequest r;
  while (queue_.pop(r)) {
    if (r.seq <= last_seq) continue;  // already seen (cannot happen with one consumer)
    last_seq = r.seq;
    out = r;
    return true;
  }
  return false;
}

}  // namespace edm::rt
