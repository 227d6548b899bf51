#include "edm/hal/driver.hpp"

#include <spdlog/spdlog.h>

#include <chrono>
#include <thread>

namespace edm::hal {

namespace {

constexpr const char* kStaleText =
    "hal: the HAL side's heartbeat stopped (value: cycles since its last change)";

struct AttachedHalDriver final : HalDriver {
  AttachedHalDriver() : HalDriver(true) {}
};
struct DetachedHalDriver final : HalDriver {
  DetachedHalDriver() : HalDriver(false) {}
};

}  // namespace

void HalDriverParams::visit(rt::ParamVisitor& v) {
  v.param("component", component,
          rt::load_time({"", "the HAL component's name: its pins are <component>.<hal>"}));
  v.param("stale_cycles", stale_cycles,
          rt::load_time({"",
                         "a heartbeat unchanged for more than this many I/O-task cycles is alarm "
                         "121 io_stale (the safe state)",
                         rt::closed(1, 1000000)}));
  v.param("start_timeout", start_timeout,
          rt::load_time({"s", "before the first cycle, wait this long at most for the heartbeat",
                         rt::closed(0.0, 60.0)}));
  v.param("pace_wait", pace_wait,
          rt::load_time({"s",
                         "> 0: each cycle first waits (spinning) up to this long for the next "
                         "heartbeat, latching the inputs just after the HAL side's step; 0: "
                         "free-running",
                         rt::closed(0.0, 1.0)}));
  v.param("online_pin", online_pin,
          rt::load_time(
              {"", "name of a BOOL output pin, true while the heartbeat is fresh (\"\": none)"}));
}

std::vector<rt::ParamError> HalDriverParams::validate() const {
  std::vector<rt::ParamError> errs;
  if (component.empty() || component.size() > 40) {
    errs.push_back({"component", "must be 1 to 40 characters (HAL names are at most 47)"});
  }
  for (const char c : component) {
    if (!((c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '-' ||
          c == '_')) {
      errs.push_back({"component", "must be letters, digits, '-' and '_'"});
      break;
    }
  }
  return errs;
}

HalDriver::HalDriver(bool attach) : attach_(attach) {}

HalDriver::~HalDriver() { component_.close(); }

std::vector<rt::PinMapError> HalDriver::set_pin_map(const std::vector<rt::PinMapEntry>& entries) {
  std::vector<rt::PinMapError> errs;
  map_ = parse_pin_map(entries, errs);
  return errs;
}

std::vector<rt::ParamError> HalDriver::configure(const rt::BlockSetup& setup) {
  machine_ = setup.machine;
  bool_in_.clear();
  real_in_.clear();
  int_in_.clear();
  bool_out_.clear();
  real_out_.clear();
  int_out_.clear();
  kind_slot_.clear();
  heartbeat_ = heartbeat_out_ = SIZE_MAX;
  for (std::size_t i = 0; i < map_.size(); ++i) {
    const HalPin& m = map_[i];
    if (!params_.online_pin.empty() && m.name == params_.online_pin) {
      return {{"online_pin", "'" + m.name + "' is also a mapped pin"}};
    }
    if (m.role == Role::kHeartbeat) heartbeat_ = i;
    if (m.role == Role::kHeartbeatOut) heartbeat_out_ = i;
    const auto add = [&](auto& in, auto& out) {
      using InPin = typename std::decay_t<decltype(in)>::value_type::element_type;
      using OutPin = typename std::decay_t<decltype(out)>::value_type::element_type;
      kind_slot_.push_back(m.input ? in.size() : out.size());
      m.input ? in.push_back(std::make_unique<InPin>()) : out.push_back(std::make_unique<OutPin>());
    };
    switch (m.io_type()) {
      case IoType::kBool: add(bool_in_, bool_out_); break;
      case IoType::kReal: add(real_in_, real_out_); break;
      case IoType::kInt: add(int_in_, int_out_); break;
    }
  }
  if (params_.pace_wait >= setup.period && setup.period.count() > 0) {
    return {{"pace_wait", "must be shorter than the I/O task's interval (" +
                              rt::format_duration(setup.period) + ")"}};
  }
  last_count_.assign(map_.size(), 0U);
  stale_source_ = "io.hal(" + params_.component + ")";
  slots_.assign(map_.size(), PinSlot{});
  local_ = std::make_unique<Local[]>(map_.size());
  for (std::size_t i = 0; i < map_.size(); ++i) {
    local_[i].addr = &local_[i].value;
    slots_[i] = {&local_[i].addr, map_[i].type};
  }
  if (attach_) {
    return attach();
  }
  return {};
}

std::vector<rt::ParamError> HalDriver::attach() {
  if (std::string e = component_.open(params_.component); !e.empty()) {
    return {{"component", e}};
  }
  for (std::size_t i = 0; i < map_.size(); ++i) {
    const HalPin& m = map_[i];
    const std::string at = "pins[" + std::to_string(i) + "] (io." + m.name + "): ";
    if (std::string e =
            component_.add_pin(m.hal, m.type, m.input ? HalDir::kIn : HalDir::kOut, slots_[i]);
        !e.empty()) {
      component_.close();
      return {{"", at + e}};
    }
  }
  write_safe(false);  // before any net: the outputs start safe
  for (std::size_t i = 0; i < map_.size(); ++i) {
    const HalPin& m = map_[i];
    if (m.signal.empty()) continue;
    if (std::string e = component_.link(m.hal, m.signal, m.type); !e.empty()) {
      component_.close();
      return {{"", "pins[" + std::to_string(i) + "] (io." + m.name + "): " + e}};
    }
  }
  if (std::string e = component_.ready(); !e.empty()) {
    component_.close();
    return {{"component", e}};
  }
  spdlog::info("hal: component '{}' ready, {} pins", params_.component, map_.size());
  return {};
}

void HalDriver::visit_pins(rt::PinVisitor& v) {
  for (std::size_t i = 0; i < map_.size() && i < kind_slot_.size(); ++i) {
    const HalPin& m = map_[i];
    const std::size_t k = kind_slot_[i];
    switch (m.io_type()) {
      case IoType::kBool:
        m.input ? v.output(m.name, *bool_in_[k]) : v.input(m.name, *bool_out_[k]);
        break;
      case IoType::kReal:
        m.input ? v.output(m.name, *real_in_[k], m.unit) : v.input(m.name, *real_out_[k], m.unit);
        break;
      case IoType::kInt:
        m.input ? v.output(m.name, *int_in_[k], m.unit) : v.input(m.name, *int_out_[k], m.unit);
        break;
    }
  }
  if (!params_.online_pin.empty()) {
    v.output(params_.online_pin, online_);
  }
}

void HalDriver::activate() noexcept {
  counted_ = false;
  beat_valid_ = false;
  age_ = 0;
  stale_ = false;
}

void HalDriver::start() {
  if (params_.pace_wait.count() > 0 && heartbeat_ == SIZE_MAX) {
    spdlog::warn("hal: pace_wait needs a heartbeat pin (role: heartbeat): free-running");
  }
  if (heartbeat_ == SIZE_MAX || !attached()) return;
  const std::uint32_t first = pin_read_u32(slots_[heartbeat_]);
  const auto deadline = std::chrono::steady_clock::now() + params_.start_timeout;
  while (std::chrono::steady_clock::now() < deadline) {
    if (pin_read_u32(slots_[heartbeat_]) != first) {
      spdlog::info("hal: the heartbeat {}.{} beats", params_.component, map_[heartbeat_].hal);
      return;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(1));  // polling, before the tasks
  }
  spdlog::warn("hal: the heartbeat {}.{} did not change within {}: alarm 121 follows",
               params_.component, map_[heartbeat_].hal, rt::format_duration(params_.start_timeout));
}

void HalDriver::stop() noexcept {
  write_safe(true);
  if (params_.pace_wait.count() > 0) {
    spdlog::info("hal: {} of {} cycles latched on a heartbeat within pace_wait {}", paced_, cycles_,
                 rt::format_duration(params_.pace_wait));
  }
}

void HalDriver::read_inputs(const rt::CycleContext& ctx) noexcept {
  if (params_.pace_wait.count() > 0 && heartbeat_ != SIZE_MAX) {
    // The HAL side's next step after this cycle's release: waiting for one newer than the last
    // cycle's would not wait at all once the phase puts the step before the release.
    const std::uint32_t at_release = pin_read_u32(slots_[heartbeat_]);
    const auto t0 = std::chrono::steady_clock::now();  // vDSO: no system call
    while (pin_read_u32(slots_[heartbeat_]) == at_release) {
      if (std::chrono::steady_clock::now() - t0 >= params_.pace_wait) break;
#if defined(__x86_64__) || defined(__i386__)
      __builtin_ia32_pause();
#endif
    }
    if (pin_read_u32(slots_[heartbeat_]) != at_release) ++paced_;
  }
  ++cycles_;
  for (std::size_t i = 0; i < map_.size(); ++i) {
    const HalPin& m = map_[i];
    if (!m.input) continue;
    const std::size_t k = kind_slot_[i];
    if (m.counter) {
      const std::uint32_t now = pin_read_u32(slots_[i]);
      const std::uint32_t delta = counted_ ? now - last_count_[i] : 0U;  // mod 2^32
      last_count_[i] = now;
      int_in_[k]->set(m.type == HalType::kS32 ? static_cast<std::int32_t>(delta)
                                              : static_cast<std::int64_t>(delta));
      continue;
    }
    switch (m.io_type()) {
      case IoType::kBool: bool_in_[k]->set(pin_read_u32(slots_[i]) != 0U); break;
      case IoType::kReal: real_in_[k]->set(pin_read(slots_[i]) * m.scale + m.offset); break;
      case IoType::kInt:
        int_in_[k]->set(
            m.type == HalType::kS32
                ? static_cast<std::int64_t>(static_cast<std::int32_t>(pin_read_u32(slots_[i])))
                : static_cast<std::int64_t>(pin_read_u32(slots_[i])));
        break;
    }
  }
  counted_ = true;
  if (heartbeat_ == SIZE_MAX) {
    online_.set(true);
    return;
  }
  // age_: cycles since the last change (0 in the cycle that sees one). The first reading is no
  // beat: until the first change the age counts from the first cycle.
  const std::uint32_t beat = pin_read_u32(slots_[heartbeat_]);
  if (beat_valid_ && beat != beat_seen_) {
    age_ = 0;
  } else if (age_ < UINT64_MAX) {
    ++age_;
  }
  beat_seen_ = beat;
  beat_valid_ = true;
  const auto limit = static_cast<std::uint64_t>(params_.stale_cycles);
  online_.set(age_ <= limit);
  if (machine_ == nullptr) return;
  if (age_ > limit) {
    // Every cycle while it lasts: after a reset the same condition faults again at once.
    rt::Alarm a;
    a.code = rt::AlarmCode::kIoStale;
    a.time = ctx.release;
    a.source = stale_source_.c_str();
    a.text = kStaleText;
    a.value = static_cast<double>(age_);
    machine_->raise(a);
    stale_ = true;
  } else if (stale_) {
    machine_->clear_alarm(rt::AlarmCode::kIoStale, stale_source_.c_str());
    stale_ = false;
  }
}

void HalDriver::write_outputs(const rt::CycleContext& ctx) noexcept {
  // The cycle that raises 121 already holds the safe values: the state the cycle started with
  // (ctx.state) only becomes FAULT in the next one.
  const bool fault = rt::is_safe_state(ctx.state) || stale_;
  const bool estop = ctx.state == rt::MachineState::kEstop;
  for (std::size_t i = 0; i < map_.size(); ++i) {
    const HalPin& m = map_[i];
    if (m.input) continue;
    if (i == heartbeat_out_) {
      pin_write_u32(slots_[i], ++beat_out_);
      continue;
    }
    const bool hold = m.safe_in == SafeIn::kEstopOnly ? estop : fault;
    double v = m.safe;
    if (!hold) {
      const std::size_t k = kind_slot_[i];
      switch (m.io_type()) {
        case IoType::kBool: v = bool_out_[k]->get() ? 1.0 : 0.0; break;
        case IoType::kReal: v = real_out_[k]->get(); break;
        case IoType::kInt: v = static_cast<double>(int_out_[k]->get()); break;
      }
    }
    pin_write(slots_[i], to_raw(m, v));
  }
}

void HalDriver::enter_safe_state(const rt::SafeStateRequest& request) noexcept {
  write_safe(request.state == rt::MachineState::kEstop);
}

void HalDriver::write_safe(bool estop) noexcept {
  for (std::size_t i = 0; i < map_.size() && i < slots_.size(); ++i) {
    const HalPin& m = map_[i];
    if (m.input || i == heartbeat_out_) continue;
    if (m.safe_in == SafeIn::kEstopOnly && !estop) continue;  // FAULT: the programs drive it
    pin_write(slots_[i], to_raw(m, m.safe));
  }
}

void register_hal_driver(rt::DriverRegistry& r, bool attach) {
  constexpr const char* kSummary = "LinuxCNC HAL userspace component (Debian's HAL), docs/hal.md";
  if (attach) {
    r.add<AttachedHalDriver>("hal", kSummary);
  } else {
    r.add<DetachedHalDriver>("hal", kSummary);
  }
}

}  // namespace edm::hal
