#include "soak_hostile.hpp"

#include <arpa/inet.h>
#include <fcntl.h>
#include <fmt/core.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <random>
#include <thread>

namespace edm::bench::soak {

ActionLog::ActionLog(const std::string& path, Clock::time_point t0)
    : file_(std::fopen(path.c_str(), "w")), t0_(t0) {
  recent_.reserve(kRecent);
}

ActionLog::~ActionLog() {
  if (file_ != nullptr) {
    std::fclose(file_);
  }
}

double ActionLog::now_s() const {
  return std::chrono::duration<double>(Clock::now() - t0_).count();
}

void ActionLog::add(int client, const std::string& what) {
  const double t = now_s();
  std::string line = fmt::format("{:9.3f} c{:02d} {}", t, client, what);
  const std::string kind = what.substr(0, what.find(' '));
  std::lock_guard lock(mutex_);
  if (file_ != nullptr) {
    std::fprintf(file_, "%s\n", line.c_str());
    std::fflush(file_);  // the tail must be on disk if edmplc (or this driver) dies
  }
  ++counts_[kind];
  if (recent_.size() < kRecent) {
    recent_.push_back({t, std::move(line)});
  } else {
    recent_[next_] = {t, std::move(line)};
  }
  next_ = (next_ + 1) % kRecent;
}

std::vector<std::string> ActionLog::between(double t_from_s, double t_to_s) const {
  std::lock_guard lock(mutex_);
  std::vector<Entry> hits;
  for (const Entry& e : recent_) {
    if (e.t_s >= t_from_s && e.t_s <= t_to_s) {
      hits.push_back(e);
    }
  }
  std::stable_sort(hits.begin(), hits.end(),
                   [](const Entry& a, const Entry& b) { return a.t_s < b.t_s; });
  std::vector<std::string> out;
  out.reserve(hits.size());
  for (Entry& e : hits) {
    out.push_back(std::move(e.line));
  }
  return out;
}

std::map<std::string, std::uint64_t> ActionLog::counts() const {
  std::lock_guard lock(mutex_);
  return counts_;
}

namespace {

using namespace std::chrono_literals;

/// One raw, non-blocking loopback socket; every wait is bounded and checks the stop flag.
class RawConn {
 public:
  RawConn(const std::atomic<bool>& stop) : stop_(stop) {}
  RawConn(const RawConn&) = delete;
  RawConn& operator=(const RawConn&) = delete;
  ~RawConn() { close_normal(); }

  [[nodiscard]] bool open() const { return fd_ >= 0; }
  [[nodiscard]] bool peer_closed() const { return peer_closed_; }
  [[nodiscard]] std::uint64_t bytes_read() const { return bytes_read_; }

  /// Blocking connect (loopback: immediate), then non-blocking I/O. Empty on success.
  std::string connect(std::uint16_t port) {
    close_normal();
    fd_ = ::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
    if (fd_ < 0) {
      return std::strerror(errno);
    }
    sockaddr_in addr{};
    addr.sin_family = AF_INET;
    addr.sin_port = htons(port);
    addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    if (::connect(fd_, reinterpret_cast<const sockaddr*>(&addr), sizeof addr) != 0) {
      const std::string err = std::strerror(errno);
      close_normal();
      return err;
    }
    fcntl(fd_, F_SETFL, fcntl(fd_, F_GETFL) | O_NONBLOCK);
    peer_closed_ = false;
    return {};
  }

  /// Sends all of `data` within `limit`. Returns the bytes sent (less: the server stopped
  /// reading, closed, or we were told to stop).
  std::size_t send_all(std::string_view data, std::chrono::milliseconds limit = 10s) {
    std::size_t sent = 0;
    const auto deadline = Clock::now() + limit;
    while (fd_ >= 0 && sent < data.size() && !stop_.load() && Clock::now() < deadline) {
      const ssize_t n = ::send(fd_, data.data() + sent, data.size() - sent, MSG_NOSIGNAL);
      if (n > 0) {
        sent += static_cast<std::size_t>(n);
        continue;
      }
      if (n < 0 && (errno == EAGAIN || errno == EWOULDBLOCK || errno == EINTR)) {
        pollfd p{fd_, POLLOUT, 0};
        ::poll(&p, 1, 100);
        continue;
      }
      peer_closed_ = true;
      break;
    }
    return sent;
  }

  /// Reads and discards for `d` (a well-behaved reader). Returns false if the server closed.
  bool drain(std::chrono::milliseconds d) {
    const auto deadline = Clock::now() + d;
    char buf[65536];
    while (fd_ >= 0 && !stop_.load() && Clock::now() < deadline) {
      pollfd p{fd_, POLLIN, 0};
      if (::poll(&p, 1, 100) <= 0) {
        continue;
      }
      const ssize_t n = ::recv(fd_, buf, sizeof buf, 0);
      if (n > 0) {
        bytes_read_ += static_cast<std::uint64_t>(n);
      } else if (n == 0 || (errno != EAGAIN && errno != EINTR)) {
        peer_closed_ = true;
        return false;
      }
    }
    return true;
  }

  void close_normal() {
    if (fd_ >= 0) {
      ::close(fd_);
      fd_ = -1;
    }
  }
  /// SO_LINGER 0: close() sends RST instead of FIN.
  void close_rst() {
    if (fd_ >= 0) {
      linger l{1, 0};
      ::setsockopt(fd_, SOL_SOCKET, SO_LINGER, &l, sizeof l);
      close_normal();
    }
  }

 private:
  const std::atomic<bool>& stop_;
  int fd_{-1};
  bool peer_closed_{false};
  std::uint64_t bytes_read_{0};
};

/// Sleeps `d` in 100 ms steps, returning early on stop.
void nap(std::chrono::milliseconds d, const std::atomic<bool>& stop) {
  const auto end = Clock::now() + d;
  while (!stop.load() && Clock::now() < end) {
    std::this_thread::sleep_for(std::min<Clock::duration>(100ms, end - Clock::now()));
  }
}

class Walker {
 public:
  Walker(const HostileOptions& o, ActionLog& log, const std::atomic<bool>& stop)
      : o_(o), log_(log), stop_(stop), rng_(o.seed), conn_(stop) {}

  void run() {
    while (!stop_.load()) {
      if (!conn_.open() || conn_.peer_closed()) {
        if (conn_.open()) {
          log("closed_by_server");
          conn_.close_normal();
          nap(ms(0, 1000), stop_);
        }
        connect();
        continue;
      }
      step();
    }
    conn_.close_normal();
  }

 private:
  void log(const std::string& what) { log_.add(o_.index, what); }
  std::chrono::milliseconds ms(int lo, int hi) {
    return std::chrono::milliseconds(std::uniform_int_distribution<int>(lo, hi)(rng_));
  }
  int pick(int lo, int hi) { return std::uniform_int_distribution<int>(lo, hi)(rng_); }
  std::string next_id() { return std::to_string(++id_); }

  void request(const std::string& op, const std::string& params = {}) {
    const std::string line = fmt::format(R"({{"id":{},"op":"{}"{}{}}})", next_id(), op,
                                         params.empty() ? "" : ",", params) +
                             "\n";
    const std::size_t n = conn_.send_all(line);
    log(fmt::format("{} {}{}", op, params, n < line.size() ? " (send stalled)" : ""));
  }

  void connect() {
    const std::string err = conn_.connect(o_.port);
    if (!err.empty()) {
      log("connect_failed " + err);
      nap(ms(200, 2000), stop_);
      return;
    }
    int how = pick(0, 99);
    if ((how >= 50 && how < 70 && o_.skip.contains("no_hello")) ||
        (how >= 70 && o_.skip.contains("wrong_token"))) {
      how = 0;
    }
    if (how < 50) {
      log("connect hello");
      request("hello", R"("protocol":1)");
    } else if (how < 70) {
      log("connect no_hello");
    } else if (how < 85) {
      log("connect wrong_token");
      request("hello", fmt::format(R"("protocol":1,"token":"guess-{}")", pick(0, 999999)));
    } else if (how < 95) {
      log("connect viewer_token");  // the shipped config has no tokens: any token is "wrong"
      request("hello", R"("protocol":1,"token":"viewer")");
    } else {
      log("connect bad_protocol");
      request("hello", R"("protocol":7)");
    }
    conn_.drain(ms(50, 500));
  }

  /// The action kind of a step's draw (the names --skip takes).
  static const char* kind_of(int r) {
    static constexpr std::pair<int, const char*> kKinds[] = {
        {18, "read_only"},  {30, "subscribe"},    {33, "unsubscribe"}, {41, "trace_start"},
        {44, "trace_stop"}, {54, "stall"},        {69, "drain"},       {73, "garbage_bytes"},
        {77, "bad_json"},   {79, "deep_nesting"}, {81, "long_line"},   {84, "pipelined"},
        {87, "half_line"},  {92, "close"},        {97, "rst"},         {100, "blank_line"}};
    for (const auto& [below, name] : kKinds) {
      if (r < below) return name;
    }
    return "blank_line";
  }

  void step() {
    int r = pick(0, 99);
    if (o_.skip.contains(kind_of(r))) {
      r = 60;  // a skipped kind: read for a while instead (the draw sequence stays the same)
    }
    if (r < 18) {
      static const char* kOps[] = {"status", "ping", "var.list", "tasks.stats", "machine.info"};
      const int k = pick(0, 5);
      if (k == 5 && !o_.vars.empty()) {
        request("var.read", fmt::format(R"("name":"{}")", o_.vars[pick_index(o_.vars.size())]));
      } else {
        request(kOps[k % 5]);
      }
      conn_.drain(ms(100, 2000));
    } else if (r < 30) {
      static const char* kTopics[] = {"status", "alarm", "progress"};
      std::string topics;
      for (const char* t : kTopics) {
        if (pick(0, 1) == 1) {
          topics += std::string(topics.empty() ? "" : ",") + "\"" + t + "\"";
        }
      }
      request("subscribe", fmt::format(R"("topics":[{}],"rate_hz":{})",
                                       topics.empty() ? "\"status\"" : topics, pick(1, 100)));
      conn_.drain(ms(100, 3000));
    } else if (r < 33) {
      request("unsubscribe");
      conn_.drain(ms(100, 1000));
    } else if (r < 41 && !o_.pins.empty()) {
      std::string vars;
      const int n = pick(1, 10);
      for (int i = 0; i < n; ++i) {
        vars += std::string(vars.empty() ? "" : ",") + "\"" + o_.pins[pick_index(o_.pins.size())] +
                "\"";
      }
      request("trace.start", fmt::format(R"("vars":[{}])", vars));
      conn_.drain(ms(100, 3000));
    } else if (r < 44) {
      request("trace.stop");
      conn_.drain(ms(100, 1000));
    } else if (r < 54) {
      const auto d = ms(1000, static_cast<int>(o_.max_stall.count()) * 1000);
      log(fmt::format("stall {} ms (not reading)", d.count()));
      nap(d, stop_);
      log("stall_end");
    } else if (r < 69) {
      conn_.drain(ms(500, 5000));
    } else if (r < 73) {
      std::string junk(static_cast<std::size_t>(pick(1, 4096)), '\0');
      for (char& c : junk) {
        c = static_cast<char>(pick(0, 255));
        if (c == '\n') c = ' ';
      }
      const std::size_t n = conn_.send_all(junk + "\n");
      log(fmt::format("garbage_bytes {} sent {}", junk.size() + 1, n));
      conn_.drain(ms(50, 1000));
    } else if (r < 77) {
      static const char* kBad[] = {R"({"op":"status")",
                                   R"({"op":)",
                                   "[1,2,3]",
                                   "\"status\"",
                                   R"({"id":1,"op":"status",})",
                                   "{op:status}",
                                   "null",
                                   R"({"op":"ping","op":"status"})",
                                   R"({"id":[],"op":"ping"})",
                                   R"({"op":"subscribe","topics":"status","rate_hz":1e308})"};
      const char* bad = kBad[pick_index(std::size(kBad))];
      conn_.send_all(std::string(bad) + "\n");
      log(fmt::format("bad_json {}", bad));
      conn_.drain(ms(50, 1000));
    } else if (r < 79) {
      const int depth = pick(1000, 100000);
      std::string line = R"({"id":1,"op":"subscribe","topics":)";
      line.append(static_cast<std::size_t>(depth), '[');
      line.append(static_cast<std::size_t>(depth), ']');
      line += ",\"rate_hz\":10}\n";
      const std::size_t n = conn_.send_all(line);
      log(fmt::format("deep_nesting {} levels (sent {} of {} bytes)", depth, n, line.size()));
      conn_.drain(ms(100, 2000));
    } else if (r < 81) {
      const std::size_t len = static_cast<std::size_t>(pick(1 << 20, 2 << 20)) + 16;
      std::string line = R"({"op":"ping","pad":")";
      line.append(len, 'x');
      line += "\"}\n";
      const std::size_t n = conn_.send_all(line, 20s);
      log(fmt::format("long_line {} bytes (sent {})", line.size(), n));
      conn_.drain(ms(100, 2000));
    } else if (r < 84) {
      const int count = pick(50, 500);
      std::string lines;
      for (int i = 0; i < count; ++i) {
        lines += fmt::format(R"({{"id":{},"op":"var.list"}})", next_id()) + "\n";
      }
      const std::size_t n = conn_.send_all(lines);
      const auto d = ms(1000, 30000);
      log(fmt::format("pipelined var.list x{} (sent {} of {} bytes), not reading for {} ms", count,
                      n, lines.size(), d.count()));
      nap(d, stop_);
    } else if (r < 87) {
      conn_.send_all(R"({"id":1,"op":"sta)");
      const auto d = ms(1000, 30000);
      log(fmt::format("half_line then silence {} ms", d.count()));
      nap(d, stop_);
    } else if (r < 92) {
      log("disconnect close");
      conn_.close_normal();
      nap(ms(0, 2000), stop_);
    } else if (r < 97) {
      log("disconnect rst");
      conn_.close_rst();
      nap(ms(0, 2000), stop_);
    } else {
      conn_.send_all("\n");  // a keep-alive
      log("blank_line");
      conn_.drain(ms(100, 1000));
    }
  }

  std::size_t pick_index(std::size_t n) {
    return std::uniform_int_distribution<std::size_t>(0, n - 1)(rng_);
  }

  const HostileOptions& o_;
  ActionLog& log_;
  const std::atomic<bool>& stop_;
  std::mt19937_64 rng_;
  RawConn conn_;
  std::uint64_t id_{0};
};

}  // namespace

void run_hostile(const HostileOptions& o, ActionLog& log, const std::atomic<bool>& stop) {
  Walker(o, log, stop).run();
}

}  // namespace edm::bench::soak
