#include "edm/hmi/web_hosts.hpp"

#include <stdexcept>

namespace edm::hmi {

namespace {

namespace ip = boost::asio::ip;

constexpr std::size_t kMaxHostBytes = 253;  // the longest DNS name

std::optional<std::uint16_t> parse_port(std::string_view s) {
  if (s.empty() || s.size() > 5) return std::nullopt;
  unsigned v = 0;
  for (const char c : s) {
    if (c < '0' || c > '9') return std::nullopt;
    v = v * 10 + static_cast<unsigned>(c - '0');
  }
  if (v == 0 || v > 65535) return std::nullopt;
  return static_cast<std::uint16_t>(v);
}

bool name_char(char c) {
  return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '-' ||
         c == '.' || c == '_';
}

std::optional<ip::address> as_address(const HostPort& hp) {
  boost::system::error_code ec;
  if (hp.ipv6) {
    const auto a = ip::make_address_v6(hp.host, ec);
    if (ec) return std::nullopt;
    if (a.is_v4_mapped()) return ip::address(ip::make_address_v4(ip::v4_mapped, a));
    return ip::address(a);
  }
  const auto a = ip::make_address_v4(hp.host, ec);
  if (ec) return std::nullopt;
  return ip::address(a);
}

ip::address unmapped(const ip::address& a) {
  if (a.is_v6() && a.to_v6().is_v4_mapped()) {
    return ip::make_address_v4(ip::v4_mapped, a.to_v6());
  }
  return a;
}

std::uint16_t default_port(bool tls) { return tls ? 443 : 80; }

}  // namespace

std::optional<HostPort> parse_host_port(std::string_view text) {
  HostPort hp;
  std::string_view rest;
  if (!text.empty() && text.front() == '[') {
    const auto close = text.find(']');
    if (close == std::string_view::npos) return std::nullopt;
    boost::system::error_code ec;
    const std::string inside(text.substr(1, close - 1));
    const auto a = ip::make_address_v6(inside, ec);
    if (ec || inside.find('%') != std::string::npos) return std::nullopt;  // no zone ids
    hp.host = a.to_string();
    hp.ipv6 = true;
    rest = text.substr(close + 1);
  } else {
    const auto colon = text.find(':');
    std::string_view name = text.substr(0, colon);
    rest = colon == std::string_view::npos ? std::string_view() : text.substr(colon);
    if (name.size() > 1 && name.back() == '.') name.remove_suffix(1);
    if (name.empty() || name.size() > kMaxHostBytes || name.front() == '.') return std::nullopt;
    for (const char c : name) {
      if (!name_char(c)) return std::nullopt;
    }
    hp.host.reserve(name.size());
    for (const char c : name) {
      hp.host.push_back(c >= 'A' && c <= 'Z' ? static_cast<char>(c - 'A' + 'a') : c);
    }
  }
  if (!rest.empty()) {
    if (rest.front() != ':') return std::nullopt;
    hp.port = parse_port(rest.substr(1));
    if (!hp.port) return std::nullopt;
  }
  return hp;
}

std::optional<WebOrigin> parse_origin(std::string_view text) {
  const auto sep = text.find("://");
  if (sep == std::string_view::npos) return std::nullopt;
  WebOrigin o;
  for (const char c : text.substr(0, sep)) {
    o.scheme.push_back(c >= 'A' && c <= 'Z' ? static_cast<char>(c - 'A' + 'a') : c);
  }
  if (o.scheme != "http" && o.scheme != "https") return std::nullopt;
  auto hp = parse_host_port(text.substr(sep + 3));
  if (!hp) return std::nullopt;
  if (!hp->port) hp->port = default_port(o.scheme == "https");
  o.authority = std::move(*hp);
  return o;
}

HostAllowList::HostAllowList(const ip::address& listen, const std::vector<std::string>& names,
                             bool tls)
    : tls_(tls) {
  if (!listen.is_unspecified()) listen_ = unmapped(listen);
  for (const std::string& n : names) {
    auto hp = parse_host_port(n);
    if (!hp) {
      throw std::invalid_argument("--allow-host '" + n + "': not a host name, IP or NAME:PORT");
    }
    names_.push_back(std::move(*hp));
  }
}

bool HostAllowList::configured(const HostPort& hp) const {
  for (const HostPort& n : names_) {
    if (n.host == hp.host && n.ipv6 == hp.ipv6 && (!n.port || n.port == hp.port)) return true;
  }
  return false;
}

bool HostAllowList::allowed(const HostPort& hp, const ip::address& local) const {
  if (!hp.ipv6 && hp.host == "localhost") return true;
  if (const auto a = as_address(hp)) {
    if (a->is_loopback()) return true;
    if (listen_ && *a == *listen_) return true;
    if (*a == unmapped(local)) return true;
  }
  return configured(hp);
}

bool HostAllowList::allows_host(std::string_view host_header, const ip::address& local) const {
  auto hp = parse_host_port(host_header);
  if (!hp) return false;
  if (!hp->port) hp->port = default_port(tls_);
  return allowed(*hp, local);
}

bool HostAllowList::allows_origin(std::string_view origin, std::string_view host_header,
                                  const ip::address& local) const {
  const auto o = parse_origin(origin);
  auto hp = parse_host_port(host_header);
  if (!o || !hp) return false;
  if (!hp->port) hp->port = default_port(tls_);
  if (configured(o->authority)) return true;
  const bool same = o->scheme == (tls_ ? "https" : "http") && o->authority.host == hp->host &&
                    o->authority.ipv6 == hp->ipv6 && o->authority.port == hp->port;
  return same && allowed(o->authority, local);
}

}  // namespace edm::hmi
