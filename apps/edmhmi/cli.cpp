// The pieces every edmhmi command shares (cli.hpp).
#include "cli.hpp"

#include <cstdio>

#include "edm/machining/bounded_read.hpp"

namespace edmhmi {

bool connect(edm::bridge::Client& client, const edm::hmi::ConnectionSettings& s,
             bool auto_reconnect) {
  edm::bridge::ClientOptions o = edm::hmi::client_options(s);
  o.auto_reconnect = auto_reconnect;
  try {
    client.connect(o);
    return true;
  } catch (const edm::bridge::ClientError& e) {
    std::fprintf(stderr, "edmhmi: edmplc at %s:%u: %s\n", s.host.c_str(), unsigned{s.port},
                 e.what());
    if (e.code() == edm::bridge::ErrorCode::kUnauthorized) {
      std::fprintf(stderr, "edmhmi: token from %s\n",
                   s.token_source.empty() ? "nowhere (none given)" : s.token_source.c_str());
    }
    return false;
  }
}

std::optional<edm::hmi::MachineView> connect_and_fetch_machine(
    edm::bridge::Client& client, const edm::hmi::ConnectionSettings& settings) {
  if (!connect(client, settings, /*auto_reconnect=*/true)) return std::nullopt;
  return fetch([&] { return edm::hmi::fetch_machine(client); });
}

int report_error(std::string_view op, const edm::bridge::Reply& r) {
  const std::string code = r.code ? std::string(edm::bridge::to_string(*r.code)) : "transport";
  std::fprintf(stderr, "edmhmi: %s: %s: %s\n", std::string(op).c_str(), code.c_str(),
               r.message.c_str());
  return r.code == edm::bridge::ErrorCode::kBadRequest ? kExitBadInput : kExitFailure;
}

bool read_text_file(const std::string& path, std::string& out) {
  // Regular files only, bounded: a FIFO, /dev/zero or a huge file is a located error, never a
  // hang or an exhausted memory.
  edm::machining::BoundedRead file =
      edm::machining::read_bounded_file(path, edm::machining::kMaxPartProgramBytes, "part program");
  if (!file.ok()) {
    std::fprintf(stderr, "%s\n", file.error.c_str());
    return false;
  }
  out = std::move(file.text);
  return true;
}

}  // namespace edmhmi
