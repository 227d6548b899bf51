// condition.set (ops_handlers.hpp; docs/protocol.md "Conditions"): an operator changes one field
// of a machining condition, where the machine config allows it (machine.condition_edit), within
// the config's own ranges, with the machine READY and idle; the edit is retained
// (condition_edits.hpp) and machine.info gives the table as edited.
#include <cmath>
#include <string>

#include "edm/bridge/machine_info.hpp"
#include "edm/runtime/runtime.hpp"
#include "ops_body.hpp"
#include "ops_handlers.hpp"
#include "server_impl.hpp"

namespace edm::bridge::ops {

Body op_condition_set(Session& s, const Json& msg) {
  Server::Impl& srv = s.server();
  const auto e = msg.find("E");
  const auto field = msg.find("field");
  const auto value = msg.find("value");
  if (e == msg.end() || !e->is_number_integer() || field == msg.end() || !field->is_string() ||
      value == msg.end() || !value->is_number()) {
    return error(ErrorCode::kBadRequest,
                 "condition.set needs 'E' (an integer), 'field' (a string) and 'value' (a "
                 "number)");
  }
  const std::int64_t n = e->get<std::int64_t>();
  if (n < 1 || n > 1'000'000) return error(ErrorCode::kBadRequest, "'E' must be 1 .. 1000000");
  const std::string name = field->get<std::string>();
  if (auto why =
          srv.condition_edits->set(srv.rt, static_cast<int>(n), name, value->get<double>())) {
    return error(ErrorCode::kBadRequest, "condition E" + std::to_string(n) + ": " + *why);
  }
  const Json info = to_json(srv.rt.tables(), srv.rt.config().machine.name);
  Json out{{"E", n},
           {"field", name},
           {"conditions", info["conditions"]},
           {"retained", srv.condition_edits->retained() && !srv.condition_edits->write_failed()}};
  return out;
}

}  // namespace edm::bridge::ops
