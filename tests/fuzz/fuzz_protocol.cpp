// fuzz_protocol: any bytes as what a client sends the bridge (hmi_bridge/, docs/protocol.md): the
// input is cut into lines as a session cuts its stream, and each line goes through the request
// parser, the error reply the server would send, and the payload decoders (motion blocks of
// program.chunk, the status message). A bad line is normal: it must give one well-formed error
// reply line and never crash or throw. What a decoder accepts must encode and decode unchanged.

#include <string>
#include <string_view>

#include "edm/bridge/codec.hpp"
#include "edm/bridge/protocol.hpp"
#include "fuzz/fuzz_entry.hpp"

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

void check_block(const Json& j) {
  machining::MotionBlock b;
  std::string error;
  if (!bridge::from_json(j, b, error)) {
    EDM_FUZZ_CHECK(!error.empty());
    return;
  }
  machining::MotionBlock back;
  EDM_FUZZ_CHECK(bridge::from_json(bridge::to_json(b), back, error));
  EDM_FUZZ_CHECK(back == b);
}

void check_status(const Json& j) {
  bridge::StatusMessage s;
  std::string error;
  if (!bridge::from_json(j, s, error)) {
    EDM_FUZZ_CHECK(!error.empty());
    return;
  }
  const Json once = bridge::to_json(s);
  bridge::StatusMessage back;
  EDM_FUZZ_CHECK(bridge::from_json(once, back, error));
  EDM_FUZZ_CHECK(bridge::to_json(back).dump() == once.dump());
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
  return 0;
}

}  // namespace edm::fuzz

EDM_FUZZ_MAIN(edm::fuzz::protocol_one_input)
