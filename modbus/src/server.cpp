#include "edm/modbus/server.hpp"

#include <arpa/inet.h>
#include <fmt/format.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <poll.h>
#include <spdlog/spdlog.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <cstring>
#include <stdexcept>

#include "edm/modbus/server_slots.hpp"

namespace edm::modbus {

namespace {

using namespace std::chrono_literals;

constexpr std::size_t kMbapBytes = 7;      // transaction, protocol, length, unit
constexpr std::size_t kMaxFrame = 260;     // MBAP + the largest PDU (253)
constexpr std::uint16_t kMaxLength = 254;  // MBAP length: unit + PDU
constexpr int kFramesPerRound = 16;        // then the other clients' turn
constexpr auto kPollCap = 100ms;           // stop() is noticed this fast
constexpr auto kSweepEvery = 1s;           // suppressed log lines summed up
constexpr auto kSweepQuiet = 5s;
constexpr auto kBackoffMin = 10ms;
constexpr auto kBackoffMax = 1000ms;
constexpr const char* kAll = "all peers";  // all_limiter_'s one key

std::uint16_t be16(const std::uint8_t* p) noexcept {
  return static_cast<std::uint16_t>((p[0] << 8) | p[1]);
}

std::string hex(const std::uint8_t* p, std::size_t n) {
  std::string s;
  for (std::size_t i = 0; i < n; ++i) {
    s += fmt::format("{}{:02x}", i == 0 ? "" : " ", p[i]);
  }
  return s;
}

long long ms(std::chrono::milliseconds d) { return static_cast<long long>(d.count()); }

}  // namespace

enum class Server::Close : std::uint8_t {
  kKeep,
  kPeerClosed,
  kError,
  kBadFrame,
  kFrameTimeout,
  kStalled,
  kIdle,
  kEvicted,
  kStopping,
};

struct Server::Client {
  explicit Client(int socket) noexcept : fd(socket) {}
  ~Client() { ::close(fd); }
  Client(const Client&) = delete;
  Client& operator=(const Client&) = delete;

  int fd;
  std::uint32_t peer{0};    // IPv4, host order
  std::string address;      // "10.0.0.17": the log's and the rate limit's key
  std::string name;         // "10.0.0.17:51544"
  bool established{false};  // has completed a request
  std::array<std::uint8_t, kMaxFrame> in{};
  std::size_t have{0};
  std::array<std::uint8_t, kMaxFrame> out{};  // one reply at most: no request is read meanwhile
  std::size_t out_from{0};
  std::size_t out_to{0};
  Clock::time_point connected{};
  Clock::time_point frame_started{};  // the first byte of the unfinished frame in `in`
  Clock::time_point last_request{};
  Clock::time_point out_since{};  // when the reply in `out` was made

  [[nodiscard]] bool out_empty() const noexcept { return out_from == out_to; }
  [[nodiscard]] SlotState slot() const noexcept {
    if (!established) {
      return {peer, SlotState::Use::kNew, connected};
    }
    if (!out_empty()) {
      return {peer, SlotState::Use::kStuck, out_since};
    }
    if (have > 0) {
      return {peer, SlotState::Use::kStuck, frame_started};
    }
    return {peer, SlotState::Use::kServing, last_request};
  }
};

Server::Server(rt::VariableRegistry& vars, ServerConfig config)
    : vars_(vars),
      config_(std::move(config)),
      regs_(vars_, config_.map),
      limiter_(rt::LogRateLimiter::Options{static_cast<double>(std::max(1, config_.log_burst)),
                                           config_.log_per_s > 0 ? config_.log_per_s : 1.0, 1024}),
      all_limiter_(rt::LogRateLimiter::Options{
          10.0 * std::max(1, config_.log_burst),
          10.0 * (config_.log_per_s > 0 ? config_.log_per_s : 1.0), 1}) {
  config_.max_clients = std::clamp(config_.max_clients, 1, 64);
  config_.max_clients_per_address =
      std::clamp(config_.effective_per_address(), 1, config_.max_clients);
}

Server::~Server() { stop(); }

Server::Counters Server::counters() const noexcept {
  Counters c;
  c.requests = requests_.load();
  c.exceptions = exceptions_.load();
  c.writes = writes_.load();
  c.accepted = accepted_.load();
  c.refused_clients = refused_.load();
  c.evicted = evicted_.load();
  c.bad_frames = bad_frames_.load();
  c.frame_timeouts = frame_timeouts_.load();
  c.stalled = stalled_.load();
  c.idle_timeouts = idle_timeouts_.load();
  c.open = open_.load();
  c.log_suppressed = limiter_.suppressed_total() + all_limiter_.suppressed_total();
  return c;
}

void Server::start() {
  const int fd = ::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC | SOCK_NONBLOCK, 0);
  if (fd < 0) {
    throw std::runtime_error(std::string("modbus_server: socket: ") + std::strerror(errno));
  }
  const int one = 1;
  ::setsockopt(fd, SOL_SOCKET, SO_REUSEADDR, &one, sizeof one);
  sockaddr_in sa{};
  sa.sin_family = AF_INET;
  sa.sin_port = htons(static_cast<std::uint16_t>(config_.port));
  if (::inet_pton(AF_INET, config_.bind.c_str(), &sa.sin_addr) != 1 ||
      ::bind(fd, reinterpret_cast<sockaddr*>(&sa), sizeof sa) != 0 || ::listen(fd, 64) != 0) {
    const std::string why = std::strerror(errno);
    ::close(fd);
    throw std::runtime_error("modbus_server: cannot listen on " + config_.bind + ":" +
                             std::to_string(config_.port) + ": " + why);
  }
  socklen_t len = sizeof sa;
  ::getsockname(fd, reinterpret_cast<sockaddr*>(&sa), &len);
  bound_port_ = ntohs(sa.sin_port);
  listen_fd_ = fd;
  stopping_ = false;
  thread_ = std::thread([this] { run(); });
  spdlog::info(
      "modbus_server: listening on {}:{} ({} values, at most {} clients, {} per address; frame "
      "timeout {} ms, idle timeout {} ms)",
      config_.bind, bound_port_, config_.map.size(), config_.max_clients,
      config_.max_clients_per_address, ms(config_.frame_timeout), ms(config_.idle_timeout));
}

void Server::stop() noexcept {
  if (thread_.joinable()) {
    stopping_ = true;
    thread_.join();
  }
  if (listen_fd_ >= 0) {
    ::close(listen_fd_);
    listen_fd_ = -1;
  }
}

void Server::log_about(int level, const std::string& address, const std::string& line) {
  const Clock::time_point now = Clock::now();
  std::uint64_t dropped = 0;
  std::uint64_t dropped_all = 0;
  if (!limiter_.admit(address, now, dropped) || !all_limiter_.admit(kAll, now, dropped_all)) {
    return;
  }
  spdlog::log(static_cast<spdlog::level::level_enum>(level), "modbus_server: {}{}{}", line,
              rt::suppressed_note(dropped),
              dropped_all == 0
                  ? std::string()
                  : fmt::format(" ({} earlier lines about all peers suppressed)", dropped_all));
}

void Server::accept_one(std::vector<std::unique_ptr<Client>>& clients, Clock::time_point now) {
  sockaddr_in sa{};
  socklen_t len = sizeof sa;
  const int fd =
      ::accept4(listen_fd_, reinterpret_cast<sockaddr*>(&sa), &len, SOCK_CLOEXEC | SOCK_NONBLOCK);
  if (fd < 0) {
    if (errno == EMFILE || errno == ENFILE || errno == ENOBUFS || errno == ENOMEM) {
      if (accept_backoff_ == 0ms) {
        spdlog::warn("modbus_server: accept: {}: pausing new connections (10 ms to 1 s)",
                     std::strerror(errno));
      }
      accept_backoff_ = std::clamp(accept_backoff_ * 2, std::chrono::milliseconds(kBackoffMin),
                                   std::chrono::milliseconds(kBackoffMax));
      accept_resume_ = now + accept_backoff_;
    }
    return;  // EAGAIN, ECONNABORTED, EINTR: nothing to take
  }
  if (accept_backoff_ != 0ms) {
    spdlog::info("modbus_server: accepting connections again");
    accept_backoff_ = 0ms;
  }
  accepted_.fetch_add(1, std::memory_order_relaxed);
  std::unique_ptr<Client> c;
  try {
    c = std::make_unique<Client>(fd);
  } catch (...) {
    ::close(fd);
    throw;
  }
  c->peer = ntohl(sa.sin_addr.s_addr);
  std::array<char, INET_ADDRSTRLEN> text{};
  ::inet_ntop(AF_INET, &sa.sin_addr, text.data(), text.size());
  c->address = text.data();
  c->name = c->address + ":" + std::to_string(ntohs(sa.sin_port));
  c->connected = now;
  c->last_request = now;

  std::vector<SlotState> slots;
  slots.reserve(clients.size());
  for (const auto& o : clients) {
    slots.push_back(o->slot());
  }
  const Admission a = admit(slots, c->peer, static_cast<std::size_t>(config_.max_clients),
                            static_cast<std::size_t>(config_.max_clients_per_address));
  if (a.kind == Admission::Kind::kRefuse) {
    refused_.fetch_add(1, std::memory_order_relaxed);
    log_about(spdlog::level::warn, c->address,
              fmt::format("{}: refused: all {} connections are serving clients", c->name,
                          config_.max_clients));
    return;  // ~Client closes it
  }
  if (a.kind == Admission::Kind::kEvictAndAdmit) {
    log_about(spdlog::level::info, clients[a.victim]->address,
              fmt::format("{}: closed to make room for {}", clients[a.victim]->name, c->name));
    close_client(clients, a.victim, Close::kEvicted, now);
  }
  const int one = 1;
  ::setsockopt(fd, IPPROTO_TCP, TCP_NODELAY, &one, sizeof one);
  clients.push_back(std::move(c));
  open_.store(clients.size(), std::memory_order_relaxed);
  // A client that sent its request with the connection is served now, before anyone else can
  // take its slot.
  Client& added = *clients.back();
  if (const Close why = service(added, POLLIN, now); why != Close::kKeep) {
    close_client(clients, clients.size() - 1, why, now);
  }
}

bool Server::flush(Client& c) noexcept {
  while (!c.out_empty()) {
    const ssize_t n =
        ::send(c.fd, c.out.data() + c.out_from, c.out_to - c.out_from, MSG_NOSIGNAL | MSG_DONTWAIT);
    if (n > 0) {
      c.out_from += static_cast<std::size_t>(n);
    } else if (n < 0 && errno == EINTR) {
      continue;
    } else {
      return n < 0 && (errno == EAGAIN || errno == EWOULDBLOCK);
    }
  }
  c.out_from = c.out_to = 0;
  return true;
}

void Server::serve_frame(Client& c, std::size_t total, Clock::time_point now) {
  requests_.fetch_add(1, std::memory_order_relaxed);
  const std::uint8_t* f = c.in.data();
  std::uint8_t* r = c.out.data();
  r[0] = f[0];  // transaction id
  r[1] = f[1];
  r[2] = 0;  // protocol
  r[3] = 0;
  r[6] = f[6];  // unit id, echoed: any is served
  const std::size_t pdu = serve_pdu(f + kMbapBytes, total - kMbapBytes, r + kMbapBytes, regs_);
  r[4] = static_cast<std::uint8_t>((pdu + 1) >> 8);
  r[5] = static_cast<std::uint8_t>((pdu + 1) & 0xFF);
  if ((r[kMbapBytes] & 0x80U) != 0) {
    exceptions_.fetch_add(1, std::memory_order_relaxed);
  }
  c.out_from = 0;
  c.out_to = kMbapBytes + pdu;
  c.out_since = now;
  c.established = true;
  c.last_request = now;
  writes_.store(regs_.writes(), std::memory_order_relaxed);
  if (MapRegisters::Note note = regs_.take_note(); !note.text.empty()) {
    log_about(note.refused ? spdlog::level::warn : spdlog::level::info, c.address,
              fmt::format("{}: {}", c.name, note.text));
  }
}

Server::Close Server::serve_buffered(Client& c, Clock::time_point now) {
  while (c.out_empty() && c.have >= 4) {
    const std::uint8_t* h = c.in.data();
    const std::uint16_t protocol = be16(h + 2);
    const std::uint16_t length = c.have >= 6 ? be16(h + 4) : 2;
    if (protocol != 0 || length < 2 || length > kMaxLength) {
      bad_frames_.fetch_add(1, std::memory_order_relaxed);
      log_about(spdlog::level::warn, c.address,
                fmt::format("{}: not a Modbus TCP frame (protocol id {}, length {}; header {}): "
                            "closed",
                            c.name, protocol, c.have >= 6 ? std::to_string(length) : "?",
                            hex(h, std::min(c.have, kMbapBytes))));
      return Close::kBadFrame;
    }
    const std::size_t total = 6U + length;
    if (c.have < total) {
      break;
    }
    serve_frame(c, total, now);
    std::memmove(c.in.data(), c.in.data() + total, c.have - total);
    c.have -= total;
    c.frame_started = now;  // what is left is the next frame's beginning
    if (!flush(c)) {
      return Close::kError;
    }
  }
  return Close::kKeep;
}

Server::Close Server::receive(Client& c, Clock::time_point now) {
  for (int round = 0; round < kFramesPerRound && c.out_empty(); ++round) {
    const ssize_t got = ::recv(c.fd, c.in.data() + c.have, c.in.size() - c.have, MSG_DONTWAIT);
    if (got == 0) {
      return Close::kPeerClosed;
    }
    if (got < 0) {
      if (errno == EINTR) {
        continue;
      }
      return errno == EAGAIN || errno == EWOULDBLOCK ? Close::kKeep : Close::kError;
    }
    if (c.have == 0) {
      c.frame_started = now;
    }
    c.have += static_cast<std::size_t>(got);
    if (const Close why = serve_buffered(c, now); why != Close::kKeep) {
      return why;
    }
  }
  return Close::kKeep;
}

Server::Close Server::service(Client& c, short revents, Clock::time_point now) {
  if ((revents & POLLNVAL) != 0) {
    return Close::kError;
  }
  if (!c.out_empty() && (revents & (POLLOUT | POLLERR | POLLHUP)) != 0) {
    if (!flush(c)) {
      return Close::kError;
    }
    if (c.out_empty()) {
      c.frame_started = now;  // the frames waiting behind the reply start their clocks now
      if (const Close why = serve_buffered(c, now); why != Close::kKeep) {
        return why;
      }
    }
  }
  if (c.out_empty() && (revents & (POLLIN | POLLERR | POLLHUP)) != 0) {
    if (const Close why = receive(c, now); why != Close::kKeep) {
      return why;
    }
  }
  return check_deadlines(c, now);
}

Server::Close Server::check_deadlines(const Client& c, Clock::time_point now) const noexcept {
  if (!c.out_empty()) {
    return now - c.out_since >= config_.frame_timeout ? Close::kStalled : Close::kKeep;
  }
  if (c.have > 0) {
    return now - c.frame_started >= config_.frame_timeout ? Close::kFrameTimeout : Close::kKeep;
  }
  return now - c.last_request >= config_.idle_timeout ? Close::kIdle : Close::kKeep;
}

Server::Clock::time_point Server::deadline(const Client& c) const noexcept {
  if (!c.out_empty()) {
    return c.out_since + config_.frame_timeout;
  }
  if (c.have > 0) {
    return c.frame_started + config_.frame_timeout;
  }
  return c.last_request + config_.idle_timeout;
}

void Server::close_client(std::vector<std::unique_ptr<Client>>& clients, std::size_t i, Close why,
                          Clock::time_point now) {
  Client& c = *clients[i];
  switch (why) {
    case Close::kFrameTimeout:
      frame_timeouts_.fetch_add(1, std::memory_order_relaxed);
      log_about(
          spdlog::level::warn, c.address,
          fmt::format(
              "{}: a frame begun {} ms ago is not complete ({} bytes): closed", c.name,
              ms(std::chrono::duration_cast<std::chrono::milliseconds>(now - c.frame_started)),
              c.have));
      break;
    case Close::kStalled:
      stalled_.fetch_add(1, std::memory_order_relaxed);
      log_about(spdlog::level::warn, c.address,
                fmt::format("{}: a reply not taken for {} ms: closed", c.name,
                            ms(config_.frame_timeout)));
      break;
    case Close::kIdle:
      idle_timeouts_.fetch_add(1, std::memory_order_relaxed);
      log_about(spdlog::level::info, c.address,
                fmt::format("{}: no request for {} ms: closed", c.name, ms(config_.idle_timeout)));
      break;
    case Close::kEvicted: evicted_.fetch_add(1, std::memory_order_relaxed); break;
    default: break;
  }
  clients.erase(clients.begin() + static_cast<std::ptrdiff_t>(i));
  open_.store(clients.size(), std::memory_order_relaxed);
}

void Server::run() noexcept {
  std::vector<std::unique_ptr<Client>> clients;
  std::vector<pollfd> fds;
  clients.reserve(static_cast<std::size_t>(config_.max_clients) + 1);
  fds.reserve(static_cast<std::size_t>(config_.max_clients) + 2);
  Clock::time_point next_sweep = Clock::now() + kSweepEvery;
  while (!stopping_.load()) {
    const Clock::time_point before = Clock::now();
    const bool listening = before >= accept_resume_;
    fds.clear();
    fds.push_back({listening ? listen_fd_ : -1, POLLIN, 0});  // fd -1: not polled
    Clock::time_point wake = before + kPollCap;
    if (!listening) {
      wake = std::min(wake, accept_resume_);
    }
    for (const auto& c : clients) {
      fds.push_back({c->fd, static_cast<short>(c->out_empty() ? POLLIN : POLLOUT), 0});
      wake = std::min(wake, deadline(*c));
    }
    const auto wait = std::chrono::ceil<std::chrono::milliseconds>(wake - before);
    const int ready =
        ::poll(fds.data(), fds.size(), static_cast<int>(std::max<long long>(0, wait.count())));
    if (ready < 0 && errno != EINTR) {
      spdlog::error("modbus_server: poll: {}", std::strerror(errno));
      break;
    }
    const Clock::time_point now = Clock::now();
    try {
      // Clients from the last, so that a close leaves the earlier indexes (and fds) in place.
      for (std::size_t i = clients.size(); i-- > 0;) {
        const short revents = ready > 0 ? fds[i + 1].revents : 0;
        if (const Close why = service(*clients[i], revents, now); why != Close::kKeep) {
          close_client(clients, i, why, now);
        }
      }
      if (listening && ready > 0 && (fds[0].revents & POLLIN) != 0) {
        accept_one(clients, now);
      }
      if (now >= next_sweep) {
        next_sweep = now + kSweepEvery;
        const auto summary = [](const std::string& address, std::uint64_t n) {
          spdlog::info("modbus_server: {}: {} more lines about it suppressed", address, n);
        };
        const auto quiet = std::chrono::duration_cast<std::chrono::milliseconds>(kSweepQuiet);
        limiter_.sweep(now, quiet, summary);
        all_limiter_.sweep(now, quiet, summary);
      }
    } catch (const std::exception& e) {  // an allocation failed: drop the newest, keep serving
      spdlog::error("modbus_server: {}", e.what());
      if (!clients.empty()) {
        close_client(clients, clients.size() - 1, Close::kError, now);
      }
    }
  }
  const Clock::time_point now = Clock::now();
  for (std::size_t i = clients.size(); i-- > 0;) {
    close_client(clients, i, Close::kStopping, now);
  }
}

}  // namespace edm::modbus
