// fuzz_protocol: any bytes as what a client sends the bridge (hmi_bridge/, docs/protocol.md): the
// input is cut into lines as a session cuts its stream, and each line goes through the request
// parser, the error reply the server would send, and the payload decoders (motion blocks of
// program.chunk, the status message). A bad line is normal: it must give one well-formed error
// reply line and never crash or throw. What a decoder accepts must encode and decode unchanged.
// Then the whole input goes, after a hello, through a real session of a real bridge server (the
// framing, limits, dispatcher and every op against a runtime) over an in-memory transport: the
// session must answer a final ping or close, never hang.

#include <spdlog/spdlog.h>

#include <chrono>
#include <memory>
#include <string>
#include <string_view>

#include "edm/blocks/register.hpp"
#include "edm/bridge/codec.hpp"
#include "edm/bridge/protocol.hpp"
#include "edm/bridge/server.hpp"
#include "edm/runtime/config.hpp"
#include "edm/runtime/loopback_driver.hpp"
#include "edm/runtime/runtime.hpp"
#include "fuzz/fuzz_entry.hpp"
#include "support/bridge_test_config.hpp"
#include "support/memory_transport.hpp"

namespace edm::fuzz {
namespace {

using bridge::Json;

// A line the server writes: one JSON value, then exactly one '\n'.
void check_out_line(const std::string& line) {
  EDM_FUZZ_CHECK(!line.empty() && line.back() == '\n');
  EDM_FUZZ_CHECK(line.find('\n') == line.size() - 1);
  const Json back = Json::parse(line, nullptr, /*allow_exceptions=*/false);
  EDM_FUZZ_CHECK(!back.is_discarded());
}

// Decodes `j` as an M: a refusal must say why; an accepted M must decode again from its own
// encoding, with `same(first, again)`.
template <class M, class Same>
void check_decoder(const Json& j, Same same) {
  M m;
  std::string error;
  if (!bridge::from_json(j, m, error)) {
    EDM_FUZZ_CHECK(!error.empty());
    return;
  }
  M back;
  EDM_FUZZ_CHECK(bridge::from_json(bridge::to_json(m), back, error));
  EDM_FUZZ_CHECK(same(m, back));
}

void check_block(const Json& j) {
  check_decoder<machining::MotionBlock>(j, [](const auto& a, const auto& b) { return a == b; });
}

// A status message must encode to the same text again.
void check_status(const Json& j) {
  check_decoder<bridge::StatusMessage>(j, [](const auto& a, const auto& b) {
    return bridge::to_json(b).dump() == bridge::to_json(a).dump();
  });
}

// The decoders a request's payload meets: blocks (program.chunk) and, on the HMI side, a status
// body. Each is tried on whatever the line holds, so the fuzzer need not guess the op first.
void decode_payloads(const bridge::ParsedRequest& req) {
  check_status(req.msg);
  if (auto it = req.msg.find("blocks"); it != req.msg.end() && it->is_array()) {
    for (const Json& b : *it) {
      check_block(b);
    }
  } else {
    check_block(req.msg);
  }
  check_out_line(bridge::to_line(bridge::make_reply(req.id, Json::object())));
}

void one_line(std::string_view line) {
  if (!line.empty() && line.back() == '\r') {
    line.remove_suffix(1);
  }
  bridge::ErrorCode code{};
  std::string message;
  Json id;
  const auto req = bridge::parse_request(line, code, message, id);
  if (!req) {
    EDM_FUZZ_CHECK(!message.empty());
    EDM_FUZZ_CHECK(id.is_null() || id.is_number_integer() || id.is_string());
    check_out_line(bridge::to_line(bridge::make_error(id, code, message)));
    return;
  }
  EDM_FUZZ_CHECK(req->msg.is_object());
  decode_payloads(*req);
}

// A runtime (loopback I/O, one block, tasks not running) with its bridge server, built once.
struct SessionHarness {
  rt::BlockRegistry blocks;
  rt::DriverRegistry drivers;
  std::unique_ptr<rt::Runtime> runtime;
  std::unique_ptr<bridge::Server> server;
  std::uint32_t next_address{0};

  SessionHarness() {
#ifdef EDM_LIBFUZZER
    spdlog::set_level(spdlog::level::err);  // millions of sessions: their info lines are noise
#endif
    blocks::register_builtin_blocks(blocks);
    rt::register_runtime_drivers(drivers);
    const rt::Config cfg = rt::parse_config_text(test::kBridgeTestConfig, "fuzz.yaml");
    runtime = rt::Runtime::build(cfg, blocks, drivers);
    bridge::ServerOptions o;
    o.port = 0;  // listens on an ephemeral loopback port nobody dials
    server = std::make_unique<bridge::Server>(*runtime, o);
    server->start();
  }
  // Each input comes from its own loopback address, so the failed-hello throttle of one input
  // never slows the next.
  std::string address() {
    const std::uint32_t n = ++next_address & 0xFFFFFFu;
    return "127." + std::to_string(n >> 16) + "." + std::to_string((n >> 8) & 0xFF) + "." +
           std::to_string(n & 0xFF);
  }
};

void through_a_session(std::string_view input) {
  static SessionHarness h;
  test::MemoryPeer peer(h.server->io_context());
  h.server->adopt(peer.transport(h.address()));
  peer.send("{\"id\":0,\"op\":\"hello\",\"protocol\":1}\n");
  peer.send(std::string(input));
  peer.send("\n{\"id\":\"fuzz-end\",\"op\":\"ping\"}\n");
  const bool answered = peer.wait_for("\"fuzz-end\"", std::chrono::seconds(20));
  EDM_FUZZ_CHECK(answered || peer.wait_closed(std::chrono::milliseconds(0)));
  peer.close_input();
  EDM_FUZZ_CHECK(peer.wait_closed(std::chrono::seconds(20)));
  // Every line the server wrote is one JSON object.
  const std::string written = peer.output();
  std::string_view out = written;
  while (!out.empty()) {
    const std::size_t nl = out.find('\n');
    EDM_FUZZ_CHECK(nl != std::string_view::npos);
    check_out_line(std::string(out.substr(0, nl + 1)));
    out.remove_prefix(nl + 1);
  }
}

}  // namespace

int protocol_one_input(const std::uint8_t* data, std::size_t size) {
  std::string_view rest(reinterpret_cast<const char*>(data), size);
  while (!rest.empty()) {
    const std::size_t nl = rest.find('\n');
    const std::string_view line = rest.substr(0, nl);
    if (!line.empty()) {  // a blank line is a keep-alive
      one_line(line);
    }
    rest.remove_prefix(nl == std::string_view::npos ? rest.size() : nl + 1);
  }
  through_a_session(std::string_view(reinterpret_cast<const char*>(data), size));
  return 0;
}

}  // namespace edm::fuzz

EDM_FUZZ_MAIN(edm::fuzz::protocol_one_input)
