#include "edm/modbus/server.hpp"

#include <arpa/inet.h>
#include <fcntl.h>
#include <modbus.h>
#include <netinet/in.h>
#include <poll.h>
#include <spdlog/spdlog.h>
#include <sys/socket.h>
#include <unistd.h>

#include <array>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <memory>
#include <stdexcept>

namespace edm::modbus {

namespace {

constexpr std::size_t kMbapBytes = 7;   // transaction, protocol, length, unit
constexpr std::size_t kMaxFrame = 260;  // MBAP + the largest PDU (253)
constexpr int kExIllegalFunction = MODBUS_EXCEPTION_ILLEGAL_FUNCTION;
constexpr int kExIllegalAddress = MODBUS_EXCEPTION_ILLEGAL_DATA_ADDRESS;
constexpr int kExIllegalValue = MODBUS_EXCEPTION_ILLEGAL_DATA_VALUE;
constexpr int kExDeviceFailure = MODBUS_EXCEPTION_SLAVE_OR_SERVER_FAILURE;
constexpr int kExBusy = MODBUS_EXCEPTION_SLAVE_OR_SERVER_BUSY;

std::size_t table_index(Table t) noexcept { return static_cast<std::size_t>(t); }

struct MappingDeleter {
  void operator()(modbus_mapping_t* m) const noexcept { modbus_mapping_free(m); }
};
using Mapping = std::unique_ptr<modbus_mapping_t, MappingDeleter>;

// A mapping that covers exactly [addr, addr + nb) of table t (what modbus_reply needs).
Mapping mapping_for(Table t, std::uint16_t addr, std::uint16_t nb) {
  const auto n = static_cast<unsigned>(nb);
  switch (t) {
    case Table::kCoil:
      return Mapping(modbus_mapping_new_start_address(addr, n, 0, 0, 0, 0, 0, 0));
    case Table::kDiscreteInput:
      return Mapping(modbus_mapping_new_start_address(0, 0, addr, n, 0, 0, 0, 0));
    case Table::kHoldingRegister:
      return Mapping(modbus_mapping_new_start_address(0, 0, 0, 0, addr, n, 0, 0));
    case Table::kInputRegister:
      return Mapping(modbus_mapping_new_start_address(0, 0, 0, 0, 0, 0, addr, n));
  }
  return nullptr;
}

std::uint16_t be16(const std::uint8_t* p) noexcept {
  return static_cast<std::uint16_t>((p[0] << 8) | p[1]);
}

}  // namespace

struct Server::Client {
  int fd{-1};
  std::array<std::uint8_t, kMaxFrame> buf{};
  std::size_t have{0};
  std::chrono::steady_clock::time_point last{};
};

Server::Server(rt::VariableRegistry& vars, ServerConfig config)
    : vars_(vars), config_(std::move(config)), index_(4, std::vector<int>(65536, -1)) {
  for (std::size_t i = 0; i < config_.map.size(); ++i) {
    const ServerEntry& e = config_.map[i];
    for (std::uint32_t w = 0; w < words_of(e.enc.type) && e.address + w <= 65535; ++w) {
      index_[table_index(e.table)][e.address + w] = static_cast<int>(i);
    }
  }
}

Server::~Server() { stop(); }

Server::Counters Server::counters() const noexcept {
  return {requests_.load(), exceptions_.load(), writes_.load(), refused_.load(),
          bad_frames_.load()};
}

void Server::start() {
  const int fd = ::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
  if (fd < 0) {
    throw std::runtime_error(std::string("modbus_server: socket: ") + std::strerror(errno));
  }
  const int one = 1;
  ::setsockopt(fd, SOL_SOCKET, SO_REUSEADDR, &one, sizeof one);
  sockaddr_in sa{};
  sa.sin_family = AF_INET;
  sa.sin_port = htons(static_cast<std::uint16_t>(config_.port));
  if (::inet_pton(AF_INET, config_.bind.c_str(), &sa.sin_addr) != 1 ||
      ::bind(fd, reinterpret_cast<sockaddr*>(&sa), sizeof sa) != 0 || ::listen(fd, 16) != 0) {
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
  spdlog::info("modbus_server: listening on {}:{} ({} values, at most {} clients)", config_.bind,
               bound_port_, config_.map.size(), config_.max_clients);
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

const ServerEntry* Server::entry_at(Table t, std::uint32_t addr) const noexcept {
  if (addr > 65535) {
    return nullptr;
  }
  const int i = index_[table_index(t)][addr];
  return i < 0 ? nullptr : &config_.map[static_cast<std::size_t>(i)];
}

int Server::read_values(Table t, std::uint16_t addr, std::uint16_t nb,
                        std::vector<std::uint16_t>& out) {
  out.assign(nb, 0);
  for (std::uint32_t a = addr; a < std::uint32_t{addr} + nb;) {
    const ServerEntry* e = entry_at(t, a);
    if (e == nullptr) {
      return kExIllegalAddress;
    }
    const std::optional<double> v = vars_.read(e->var);
    if (!v) {
      return kExDeviceFailure;
    }
    std::array<std::uint16_t, 2> w{};
    encode(*v, e->enc, w.data());
    // A read may start or end inside a 32-bit value: copy the words that fall in the request.
    for (std::uint32_t k = 0; k < words_of(e->enc.type); ++k) {
      const std::uint32_t at = e->address + k;
      if (at >= addr && at < std::uint32_t{addr} + nb) {
        out[at - addr] = w[k];
      }
    }
    a = std::uint32_t{e->address} + words_of(e->enc.type);
  }
  return 0;
}

int Server::write_values(Table t, std::uint16_t addr, std::uint16_t nb,
                         const std::uint16_t* words) {
  // Check everything first: a refused request writes nothing.
  for (std::uint32_t a = addr; a < std::uint32_t{addr} + nb;) {
    const ServerEntry* e = entry_at(t, a);
    if (e == nullptr || !e->writable || e->address != a ||
        a + words_of(e->enc.type) > std::uint32_t{addr} + nb) {
      return kExIllegalAddress;
    }
    a += words_of(e->enc.type);
  }
  for (std::uint32_t a = addr; a < std::uint32_t{addr} + nb;) {
    const ServerEntry* e = entry_at(t, a);
    const double v = decode(words + (a - addr), e->enc);
    const rt::VarStatus s = vars_.write(e->var, v);
    if (!s) {
      spdlog::info("modbus_server: write {} = {} refused: {}", e->var, v, s.message);
      switch (s.result) {
        case rt::VarResult::kBusy:
          return kExBusy;
        case rt::VarResult::kInvalid:
        case rt::VarResult::kTypeMismatch:
          return kExIllegalValue;
        default:
          return kExDeviceFailure;
      }
    }
    writes_.fetch_add(1, std::memory_order_relaxed);
    a += words_of(e->enc.type);
  }
  return 0;
}

bool Server::handle(Client& c, const std::uint8_t* frame, std::size_t n) noexcept {
  requests_.fetch_add(1, std::memory_order_relaxed);
  // libmodbus builds and sends every reply (normal and exception) on the client's socket.
  modbus_t* ctx = modbus_new_tcp("127.0.0.1", 502);
  if (ctx == nullptr) {
    return false;
  }
  modbus_set_socket(ctx, c.fd);
  const auto done = [&](int rc) {
    modbus_set_socket(ctx, -1);
    modbus_free(ctx);
    return rc >= 0;
  };
  const auto exception = [&](int code) {
    exceptions_.fetch_add(1, std::memory_order_relaxed);
    return done(modbus_reply_exception(ctx, frame, static_cast<unsigned>(code)));
  };
  const std::uint8_t* pdu = frame + kMbapBytes;
  const std::size_t pdu_len = n - kMbapBytes;
  const int function = pdu[0];
  Table t = Table::kCoil;
  bool write = false;
  switch (function) {
    case MODBUS_FC_READ_COILS:
      t = Table::kCoil;
      break;
    case MODBUS_FC_READ_DISCRETE_INPUTS:
      t = Table::kDiscreteInput;
      break;
    case MODBUS_FC_READ_HOLDING_REGISTERS:
      t = Table::kHoldingRegister;
      break;
    case MODBUS_FC_READ_INPUT_REGISTERS:
      t = Table::kInputRegister;
      break;
    case MODBUS_FC_WRITE_SINGLE_COIL:
    case MODBUS_FC_WRITE_MULTIPLE_COILS:
      t = Table::kCoil;
      write = true;
      break;
    case MODBUS_FC_WRITE_SINGLE_REGISTER:
    case MODBUS_FC_WRITE_MULTIPLE_REGISTERS:
      t = Table::kHoldingRegister;
      write = true;
      break;
    default:
      return exception(kExIllegalFunction);
  }
  if (pdu_len < 5) {
    return exception(kExIllegalValue);
  }
  const std::uint16_t addr = be16(pdu + 1);
  std::uint16_t nb = be16(pdu + 3);
  std::vector<std::uint16_t> words;
  if (!write) {
    const std::uint16_t max = is_bit_table(t) ? MODBUS_MAX_READ_BITS : MODBUS_MAX_READ_REGISTERS;
    if (nb < 1 || nb > max) {
      return exception(kExIllegalValue);
    }
    if (std::uint32_t{addr} + nb > 65536) {
      return exception(kExIllegalAddress);
    }
    if (const int ex = read_values(t, addr, nb, words); ex != 0) {
      return exception(ex);
    }
  } else if (function == MODBUS_FC_WRITE_SINGLE_COIL ||
             function == MODBUS_FC_WRITE_SINGLE_REGISTER) {
    const std::uint16_t value = nb;
    if (function == MODBUS_FC_WRITE_SINGLE_COIL && value != 0xFF00 && value != 0x0000) {
      return exception(kExIllegalValue);
    }
    nb = 1;
    words.assign(1, function == MODBUS_FC_WRITE_SINGLE_COIL ? (value != 0 ? 1 : 0) : value);
    if (const int ex = write_values(t, addr, 1, words.data()); ex != 0) {
      return exception(ex);
    }
  } else {
    const std::uint16_t max = is_bit_table(t) ? MODBUS_MAX_WRITE_BITS : MODBUS_MAX_WRITE_REGISTERS;
    const std::size_t bytes = is_bit_table(t) ? (nb + 7u) / 8u : nb * 2u;
    if (nb < 1 || nb > max || pdu_len < 6 || pdu[5] != bytes || pdu_len != 6 + bytes) {
      return exception(kExIllegalValue);
    }
    if (std::uint32_t{addr} + nb > 65536) {
      return exception(kExIllegalAddress);
    }
    words.assign(nb, 0);
    for (std::size_t k = 0; k < nb; ++k) {
      words[k] = is_bit_table(t) ? static_cast<std::uint16_t>((pdu[6 + k / 8] >> (k % 8)) & 1U)
                                 : be16(pdu + 6 + 2 * k);
    }
    if (const int ex = write_values(t, addr, nb, words.data()); ex != 0) {
      return exception(ex);
    }
  }
  Mapping m = mapping_for(t, addr, nb);
  if (!m) {
    return exception(kExDeviceFailure);
  }
  if (!write) {
    for (std::size_t k = 0; k < nb; ++k) {
      if (t == Table::kCoil) {
        m->tab_bits[k] = words[k] != 0 ? 1 : 0;
      } else if (t == Table::kDiscreteInput) {
        m->tab_input_bits[k] = words[k] != 0 ? 1 : 0;
      } else if (t == Table::kHoldingRegister) {
        m->tab_registers[k] = words[k];
      } else {
        m->tab_input_registers[k] = words[k];
      }
    }
  }
  return done(modbus_reply(ctx, frame, static_cast<int>(n), m.get()));
}

void Server::run() noexcept {
  std::vector<std::unique_ptr<Client>> clients;
  std::vector<pollfd> fds;
  const auto close_client = [&](std::size_t i) {
    ::close(clients[i]->fd);
    clients.erase(clients.begin() + static_cast<std::ptrdiff_t>(i));
  };
  while (!stopping_.load()) {
    fds.clear();
    fds.push_back({listen_fd_, POLLIN, 0});
    for (const auto& c : clients) {
      fds.push_back({c->fd, POLLIN, 0});
    }
    const int ready = ::poll(fds.data(), fds.size(), 100);
    const auto now = std::chrono::steady_clock::now();
    if (ready > 0 && (fds[0].revents & POLLIN) != 0) {
      const int fd = ::accept4(listen_fd_, nullptr, nullptr, SOCK_CLOEXEC | SOCK_NONBLOCK);
      if (fd >= 0) {
        if (clients.size() >= static_cast<std::size_t>(config_.max_clients)) {
          refused_.fetch_add(1, std::memory_order_relaxed);
          ::close(fd);
        } else {
          // A client that does not read its replies makes a send fail, not the server wait.
          timeval tv{0, 200000};
          ::setsockopt(fd, SOL_SOCKET, SO_SNDTIMEO, &tv, sizeof tv);
          ::fcntl(fd, F_SETFL, ::fcntl(fd, F_GETFL) & ~O_NONBLOCK);
          auto c = std::make_unique<Client>();
          c->fd = fd;
          c->last = now;
          clients.push_back(std::move(c));
        }
      }
    }
    for (std::size_t i = clients.size(); i-- > 0;) {
      Client& c = *clients[i];
      const pollfd* p = nullptr;
      for (const pollfd& f : fds) {
        if (f.fd == c.fd) {
          p = &f;
        }
      }
      bool keep = true;
      if (p != nullptr && (p->revents & (POLLIN | POLLHUP | POLLERR)) != 0) {
        const ssize_t got =
            ::recv(c.fd, c.buf.data() + c.have, c.buf.size() - c.have, MSG_DONTWAIT);
        if (got <= 0) {
          keep = got < 0 && (errno == EAGAIN || errno == EINTR);
        } else {
          c.have += static_cast<std::size_t>(got);
          c.last = now;
          // Every complete frame in the buffer, in order.
          while (keep && c.have >= kMbapBytes) {
            const std::uint16_t protocol = be16(c.buf.data() + 2);
            const std::uint16_t length = be16(c.buf.data() + 4);
            if (protocol != 0 || length < 2 || length > 254) {
              bad_frames_.fetch_add(1, std::memory_order_relaxed);
              keep = false;
              break;
            }
            const std::size_t total = 6u + length;
            if (c.have < total) {
              break;
            }
            keep = handle(c, c.buf.data(), total);
            std::memmove(c.buf.data(), c.buf.data() + total, c.have - total);
            c.have -= total;
          }
        }
      }
      if (keep && now - c.last > config_.idle_timeout) {
        keep = false;
      }
      if (!keep) {
        close_client(i);
      }
    }
  }
  for (std::size_t i = clients.size(); i-- > 0;) {
    close_client(i);
  }
}

}  // namespace edm::modbus
