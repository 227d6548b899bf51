#pragma once
// Which names the page may be reached by (docs/security.md "The browser HMI"): the defence
// against DNS rebinding. A page at evil.example whose name is re-pointed at 127.0.0.1 reaches
// `edmhmi serve` with `Host: evil.example` and `Origin: http://evil.example`; same origin by
// string, a foreign host by name. So every HTTP request and the WebSocket upgrade must carry a
// Host on this list, and the upgrade an Origin on it:
//   - the loopback names `localhost`, `127.0.0.0/8` and `[::1]`, with any port (an SSH tunnel
//     picks its own);
//   - the `--listen` address and the address the connection came in on (an IP literal, so never
//     a rebound name), with any port;
//   - each `--allow-host NAME` or `NAME:PORT` (the name the shop's DNS or a proxy gives the
//     station): that name, with any port or that port.
// Names are compared case-insensitively without a trailing dot; a Host or Origin that does not
// parse (user info, a path, odd characters, a bad port) is refused.
// Origin: parsed as scheme://host[:port]; scheme http or https; accepted when it is the request's
// own origin (this server's scheme, the Host's name and port, default ports filled in) and its
// host is allowed, or when its host is a configured name (a proxy in front may change the
// scheme and port). `null`, a missing Origin and anything else are refused.
//
// Pure; thread-safe after construction (const).

#include <boost/asio/ip/address.hpp>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace edm::hmi {

/// A Host header's or an Origin's authority: `host` lower-case, without a trailing dot; an IPv6
/// literal without its brackets.
struct HostPort {
  std::string host;
  std::optional<std::uint16_t> port;
  bool ipv6{false};
};
[[nodiscard]] std::optional<HostPort> parse_host_port(std::string_view text);

struct WebOrigin {
  std::string scheme;  // http, https
  HostPort authority;  // port filled in from the scheme when absent
};
[[nodiscard]] std::optional<WebOrigin> parse_origin(std::string_view text);

class HostAllowList {
 public:
  /// `listen`: the address served on (unspecified 0.0.0.0/:: adds nothing); `names` as given to
  /// --allow-host. Throws std::invalid_argument naming a name that does not parse.
  HostAllowList(const boost::asio::ip::address& listen, const std::vector<std::string>& names,
                bool tls);

  /// The Host header of a request that came in on `local` (the connection's own address).
  [[nodiscard]] bool allows_host(std::string_view host_header,
                                 const boost::asio::ip::address& local) const;
  /// The Origin of a WebSocket upgrade whose Host is `host_header`.
  [[nodiscard]] bool allows_origin(std::string_view origin, std::string_view host_header,
                                   const boost::asio::ip::address& local) const;

 private:
  [[nodiscard]] bool allowed(const HostPort& hp, const boost::asio::ip::address& local) const;
  [[nodiscard]] bool configured(const HostPort& hp) const;

  std::optional<boost::asio::ip::address> listen_;
  std::vector<HostPort> names_;
  bool tls_{false};
};

}  // namespace edm::hmi
