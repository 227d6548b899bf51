#include "edm/modbus/driver.hpp"

#include <modbus.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <cerrno>
#include <set>
#include <utility>

#include "protocol_limits.hpp"

namespace edm::modbus {

namespace {

constexpr const char* kStaleText =
    "modbus: the remote I/O's process image is older than stale_cycles (value: its age, cycles)";
constexpr const char* kInterlockText =
    "safety interlock open (normally-closed contact reads false)";

}  // namespace

struct ModbusDriver::Span {
  Table table{Table::kCoil};
  std::uint16_t start{0};
  std::uint16_t count{0};
  std::vector<std::size_t> members;  // map_ indices
};

struct ModbusDriver::Link {
  modbus_t* ctx{nullptr};
  std::vector<std::uint8_t> bits = std::vector<std::uint8_t>(kMaxReadBits);
  std::vector<std::uint16_t> regs = std::vector<std::uint16_t>(kMaxReadRegisters);

  Link() = default;
  Link(const Link&) = delete;
  Link& operator=(const Link&) = delete;
  ~Link() { close(); }

  bool open(const ModbusDriverParams& p, std::string& error) {
    close();
    ctx = modbus_new_tcp_pi(p.host.c_str(), std::to_string(p.port).c_str());
    if (ctx == nullptr) {
      error = modbus_strerror(errno);
      return false;
    }
    const auto us = std::chrono::duration_cast<std::chrono::microseconds>(p.response_timeout);
    modbus_set_response_timeout(ctx, static_cast<std::uint32_t>(us.count() / 1000000),
                                static_cast<std::uint32_t>(us.count() % 1000000));
    modbus_set_slave(ctx, static_cast<int>(p.unit_id));
    if (modbus_connect(ctx) != 0) {
      error = modbus_strerror(errno);
      close();
      return false;
    }
    return true;
  }
  void close() noexcept {
    if (ctx != nullptr) {
      modbus_close(ctx);
      modbus_free(ctx);
      ctx = nullptr;
    }
  }
};

void ModbusDriverParams::visit(rt::ParamVisitor& v) {
  v.param("host", host, rt::load_time({"", "remote I/O host name or address (Modbus TCP server)"}));
  v.param("port", port, rt::load_time({"", "its TCP port", rt::closed(1, 65535)}));
  v.param("unit_id", unit_id,
          rt::load_time(
              {"", "Modbus unit identifier (slave id) sent in every request", rt::closed(0, 255)}));
  v.param("poll_interval", poll_interval,
          rt::load_time({"s", "one exchange (write outputs, read inputs) this often",
                         rt::closed(0.001, 10.0)}));
  v.param("response_timeout", response_timeout,
          rt::load_time({"s", "a request unanswered this long fails (the connection is reopened)",
                         rt::closed(0.001, 10.0)}));
  v.param("stale_cycles", stale_cycles,
          rt::load_time({"",
                         "an input image older than this many I/O-task cycles is alarm 121 "
                         "io_stale (the safe state)",
                         rt::closed(1, 1000000)}));
  v.param("reconnect_min", reconnect_min,
          rt::load_time({"s", "first wait before reconnecting; doubles on each failure",
                         rt::closed(0.001, 60.0)}));
  v.param("reconnect_max", reconnect_max,
          rt::load_time(
              {"s", "the longest wait between reconnection attempts", rt::closed(0.001, 600.0)}));
  v.param("online_pin", online_pin,
          rt::load_time(
              {"", "name of a BOOL output pin, true while the input image is fresh (\"\": none)"}));
}

std::vector<rt::ParamError> ModbusDriverParams::validate() const {
  std::vector<rt::ParamError> errs;
  if (reconnect_max < reconnect_min) {
    errs.push_back({"reconnect_max", "must be >= reconnect_min"});
  }
  if (host.empty()) {
    errs.push_back({"host", "must not be empty"});
  }
  return errs;
}

ModbusDriver::ModbusDriver() = default;

ModbusDriver::~ModbusDriver() { stop(); }  // Link is complete here (unique_ptr<Link>)

std::vector<rt::PinMapError> ModbusDriver::set_pin_map(
    const std::vector<rt::PinMapEntry>& entries) {
  std::vector<rt::PinMapError> errs;
  map_.clear();
  std::set<std::string> names;
  std::set<std::pair<int, std::uint32_t>> out_words;  // (table, address) written
  for (std::size_t i = 0; i < entries.size(); ++i) {
    const std::size_t before = errs.size();
    PinMapping m = parse_pin_entry(entries[i], i, errs);
    if (errs.size() != before) {
      map_.push_back(std::move(m));
      continue;
    }
    if (!names.insert(m.name).second) {
      errs.push_back({i, "name", "pin '" + m.name + "' is mapped twice"});
    }
    if (!m.input) {
      for (std::uint32_t w = 0; w < words_of(m.enc.type); ++w) {
        if (!out_words.insert({static_cast<int>(m.table), m.address + w}).second) {
          errs.push_back({i, "address",
                          std::string(to_string(m.table)) + " " + std::to_string(m.address + w) +
                              " is already written by another pin"});
          break;
        }
      }
    }
    map_.push_back(std::move(m));
  }
  if (entries.empty()) {
    errs.push_back({0, "", "the modbus driver needs at least one pin (`pins:`)"});
  }
  return errs;
}

std::vector<rt::ParamError> ModbusDriver::configure(const rt::BlockSetup& setup) {
  machine_ = setup.machine;
  bit_in_.clear();
  bit_out_.clear();
  reg_in_.clear();
  reg_out_.clear();
  pin_slot_.clear();
  pin_sources_.clear();
  for (const PinMapping& m : map_) {
    const bool bit = is_bit_table(m.table);
    if (bit && m.input) {
      pin_slot_.push_back(bit_in_.size());
      bit_in_.push_back(std::make_unique<rt::Output<bool>>());
    } else if (bit) {
      pin_slot_.push_back(bit_out_.size());
      bit_out_.push_back(std::make_unique<rt::Input<bool>>());
    } else if (m.input) {
      pin_slot_.push_back(reg_in_.size());
      reg_in_.push_back(std::make_unique<rt::Output<double>>());
    } else {
      pin_slot_.push_back(reg_out_.size());
      reg_out_.push_back(std::make_unique<rt::Input<double>>());
    }
    pin_sources_.push_back("io." + m.name);
  }
  for (const PinMapping& m : map_) {
    if (!params_.online_pin.empty() && m.name == params_.online_pin) {
      return {{"online_pin", "'" + m.name + "' is also a mapped pin"}};
    }
  }
  stale_source_ = "io.modbus(" + params_.host + ":" + std::to_string(params_.port) + ")";
  interlock_open_.assign(map_.size(), false);

  // Requests: adjacent addresses of one table and direction share one, up to the protocol's
  // limit per request.
  reads_.clear();
  writes_.clear();
  std::vector<std::size_t> order(map_.size());
  for (std::size_t i = 0; i < order.size(); ++i) {
    order[i] = i;
  }
  std::sort(order.begin(), order.end(), [this](std::size_t a, std::size_t b) {
    return std::tuple(map_[a].input, map_[a].table, map_[a].address) <
           std::tuple(map_[b].input, map_[b].table, map_[b].address);
  });
  for (const std::size_t i : order) {
    const PinMapping& m = map_[i];
    std::vector<Span>& spans = m.input ? reads_ : writes_;
    const std::uint16_t limit = is_bit_table(m.table)
                                    ? (m.input ? kMaxReadBits : kMaxWriteBits)
                                    : (m.input ? kMaxReadRegisters : kMaxWriteRegisters);
    const std::uint32_t end = std::uint32_t{m.address} + words_of(m.enc.type);
    if (!spans.empty() && spans.back().table == m.table &&
        m.address <= std::uint32_t{spans.back().start} + spans.back().count &&
        end - spans.back().start <= limit) {
      Span& s = spans.back();
      s.count = static_cast<std::uint16_t>(std::max<std::uint32_t>(s.count, end - s.start));
      s.members.push_back(i);
    } else {
      spans.push_back({m.table, m.address, static_cast<std::uint16_t>(end - m.address), {i}});
    }
  }
  for (Image& img : in_.slots()) {
    img.values.assign(map_.size(), 0.0);
    img.seq = 0;
  }
  for (Image& img : out_.slots()) {
    img.values.assign(map_.size(), 0.0);
    for (std::size_t i = 0; i < map_.size(); ++i) {
      img.values[i] = map_[i].safe;
    }
  }
  return {};
}

void ModbusDriver::visit_pins(rt::PinVisitor& v) {
  for (std::size_t i = 0; i < map_.size() && i < pin_slot_.size(); ++i) {
    const PinMapping& m = map_[i];
    const std::size_t k = pin_slot_[i];
    if (is_bit_table(m.table)) {
      m.input ? v.output(m.name, *bit_in_[k]) : v.input(m.name, *bit_out_[k]);
    } else {
      m.input ? v.output(m.name, *reg_in_[k], m.unit) : v.input(m.name, *reg_out_[k], m.unit);
    }
  }
  if (!params_.online_pin.empty()) {
    v.output(params_.online_pin, online_);
  }
}

void ModbusDriver::activate() noexcept {
  seen_seq_ = 0;
  age_ = 0;
  stale_ = false;
  std::fill(interlock_open_.begin(), interlock_open_.end(), false);
}

void ModbusDriver::read_inputs(const rt::CycleContext& ctx) noexcept {
  in_.update();
  const Image& img = in_.front();
  if (img.seq != seen_seq_) {
    seen_seq_ = img.seq;
    age_ = 0;
  } else if (age_ < UINT64_MAX) {
    ++age_;
  }
  const auto limit = static_cast<std::uint64_t>(params_.stale_cycles);
  const bool fresh = seen_seq_ != 0 && age_ <= limit;
  for (std::size_t i = 0; i < map_.size(); ++i) {
    const PinMapping& m = map_[i];
    if (!m.input || seen_seq_ == 0) {
      continue;
    }
    if (is_bit_table(m.table)) {
      bit_in_[pin_slot_[i]]->set(img.values[i] != 0.0);
    } else {
      reg_in_[pin_slot_[i]]->set(img.values[i]);
    }
  }
  online_.set(fresh);
  if (machine_ == nullptr) {
    return;
  }
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
  if (!fresh) {
    return;  // safety contacts are judged on fresh data only; a stale image is its own fault
  }
  for (std::size_t i = 0; i < map_.size(); ++i) {
    const PinMapping& m = map_[i];
    if (m.safety == SafetyRole::kNone) {
      continue;
    }
    const bool closed = img.values[i] != 0.0;
    if (m.safety == SafetyRole::kEstop) {
      if (!closed && machine_->state() != rt::MachineState::kEstop) {
        machine_->command(rt::MachineCommand::kEstop, ctx.release);
      }
    } else if (!closed) {
      rt::Alarm a;
      a.code = rt::AlarmCode::kInterlockOpen;
      a.time = ctx.release;
      a.source = pin_sources_[i].c_str();
      a.text = kInterlockText;
      machine_->raise(a);
      interlock_open_[i] = true;
    } else if (interlock_open_[i]) {
      machine_->clear_alarm(rt::AlarmCode::kInterlockOpen, pin_sources_[i].c_str());
      interlock_open_[i] = false;
    }
  }
}

void ModbusDriver::write_outputs(const rt::CycleContext& ctx) noexcept {
  const bool safe = rt::is_safe_state(ctx.state);
  Image& o = out_.back();
  for (std::size_t i = 0; i < map_.size(); ++i) {
    const PinMapping& m = map_[i];
    if (m.input) {
      continue;
    }
    if (safe) {
      o.values[i] = m.safe;
    } else if (is_bit_table(m.table)) {
      o.values[i] = bit_out_[pin_slot_[i]]->get() ? 1.0 : 0.0;
    } else {
      o.values[i] = reg_out_[pin_slot_[i]]->get();
    }
  }
  out_.publish();
}

void ModbusDriver::enter_safe_state(const rt::SafeStateRequest& /*request*/) noexcept {
  publish_safe_outputs();
}

void ModbusDriver::publish_safe_outputs() noexcept {
  Image& o = out_.back();
  for (std::size_t i = 0; i < map_.size(); ++i) {
    o.values[i] = map_[i].safe;
  }
  out_.publish();
}

ModbusDriver::Counters ModbusDriver::counters() const noexcept {
  return {exchanges_.load(std::memory_order_relaxed), errors_.load(std::memory_order_relaxed),
          connects_.load(std::memory_order_relaxed), clamped_.load(std::memory_order_relaxed)};
}

void ModbusDriver::start() {
  if (thread_.joinable()) {
    return;
  }
  {
    std::lock_guard lock(wake_mutex_);
    stopping_ = false;
  }
  // The first exchange before the first cycle (bounded by response_timeout): a remote I/O that
  // is there gives the tasks a fresh image from cycle 0, however slowly the thread starts.
  link_ = std::make_unique<Link>();
  std::string error;
  if (link_->open(params_, error)) {
    connects_.fetch_add(1, std::memory_order_relaxed);
    if (!exchange_once(*link_)) {
      link_->close();
    }
  }
  thread_ = std::thread([this] { run_exchange(); });
}

void ModbusDriver::stop() noexcept {
  if (!thread_.joinable()) {
    return;
  }
  {
    std::lock_guard lock(wake_mutex_);
    stopping_ = true;
  }
  wake_.notify_all();
  thread_.join();
}

void ModbusDriver::sleep_for(rt::Duration d) {
  std::unique_lock lock(wake_mutex_);
  wake_.wait_for(lock, d, [this] { return stopping_; });
}

bool ModbusDriver::exchange_once(Link& link) noexcept {
  out_.update();
  const Image& o = out_.front();
  for (const Span& s : writes_) {
    int rc = 0;
    if (is_bit_table(s.table)) {
      std::fill_n(link.bits.begin(), s.count, std::uint8_t{0});
      for (const std::size_t i : s.members) {
        link.bits[map_[i].address - s.start] = o.values[i] != 0.0 ? 1 : 0;
      }
      rc = modbus_write_bits(link.ctx, s.start, s.count, link.bits.data());
    } else {
      std::fill_n(link.regs.begin(), s.count, std::uint16_t{0});
      for (const std::size_t i : s.members) {
        if (!encode(o.values[i], map_[i].enc, &link.regs[map_[i].address - s.start])) {
          clamped_.fetch_add(1, std::memory_order_relaxed);
        }
      }
      rc = modbus_write_registers(link.ctx, s.start, s.count, link.regs.data());
    }
    if (rc != s.count) {
      return false;
    }
  }
  Image& img = in_.back();
  for (const Span& s : reads_) {
    int rc = 0;
    switch (s.table) {
      case Table::kCoil: rc = modbus_read_bits(link.ctx, s.start, s.count, link.bits.data()); break;
      case Table::kDiscreteInput:
        rc = modbus_read_input_bits(link.ctx, s.start, s.count, link.bits.data());
        break;
      case Table::kHoldingRegister:
        rc = modbus_read_registers(link.ctx, s.start, s.count, link.regs.data());
        break;
      case Table::kInputRegister:
        rc = modbus_read_input_registers(link.ctx, s.start, s.count, link.regs.data());
        break;
    }
    if (rc != s.count) {
      return false;
    }
    for (const std::size_t i : s.members) {
      const std::size_t at = map_[i].address - s.start;
      img.values[i] = is_bit_table(s.table) ? (link.bits[at] != 0 ? 1.0 : 0.0)
                                            : decode(&link.regs[at], map_[i].enc);
    }
  }
  img.seq = ++seq_;
  in_.publish();
  exchanges_.fetch_add(1, std::memory_order_relaxed);
  return true;
}

void ModbusDriver::run_exchange() noexcept {
  Link& link = *link_;
  rt::Duration backoff = params_.reconnect_min;
  bool was_up = link.ctx != nullptr;
  bool reported_down = false;
  const std::string where = params_.host + ":" + std::to_string(params_.port);
  if (was_up) {
    spdlog::info("modbus {}: connected (unit {})", where, params_.unit_id);
  }
  for (;;) {
    {
      std::lock_guard lock(wake_mutex_);
      if (stopping_) {
        break;
      }
    }
    if (link.ctx == nullptr) {
      std::string error;
      if (!link.open(params_, error)) {
        errors_.fetch_add(1, std::memory_order_relaxed);
        if (!reported_down) {
          spdlog::warn("modbus {}: cannot connect ({}); retrying, backoff {} to {}", where, error,
                       rt::format_duration(params_.reconnect_min),
                       rt::format_duration(params_.reconnect_max));
          reported_down = true;
        }
        sleep_for(backoff);
        backoff = std::min(backoff * 2, params_.reconnect_max);
        continue;
      }
      connects_.fetch_add(1, std::memory_order_relaxed);
      spdlog::info("modbus {}: connected (unit {})", where, params_.unit_id);
      was_up = true;
      reported_down = false;
      backoff = params_.reconnect_min;
    }
    const auto t0 = std::chrono::steady_clock::now();
    if (!exchange_once(link)) {
      errors_.fetch_add(1, std::memory_order_relaxed);
      spdlog::warn("modbus {}: exchange failed ({}); reconnecting", where, modbus_strerror(errno));
      link.close();
      reported_down = true;
      sleep_for(backoff);
      continue;
    }
    const auto next = t0 + params_.poll_interval;
    sleep_for(std::chrono::duration_cast<rt::Duration>(next - std::chrono::steady_clock::now()));
  }
  // Stopping: the tasks' final safe state is in the output image; send it once.
  if (link.ctx != nullptr) {
    exchange_once(link);
  }
  link.close();
  if (was_up) {
    spdlog::info("modbus {}: closed", where);
  }
}

void register_modbus_driver(rt::DriverRegistry& r) {
  r.add<ModbusDriver>("modbus", "Modbus TCP client of remote I/O (libmodbus), docs/modbus.md");
}

}  // namespace edm::modbus
