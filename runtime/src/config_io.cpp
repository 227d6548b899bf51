// Config parser, `machine.io` beyond driver/task/params: a driver's pin map (`pins:`, a list of
// flat maps the driver interprets) and a composite's drivers (`drivers:`). See
// config_sections.cpp for the rest of the section and docs/config.md for the schema.

#include <algorithm>

#include "config_parser_impl.hpp"

namespace edm::rt::config_detail {

namespace {
// A machine has a few drivers and a remote I/O a few hundred points; more is the wrong file.
constexpr std::size_t kMaxDrivers = 16;
constexpr std::size_t kMaxPinMapEntries = 4096;
}  // namespace

void Parser::parse_io_extras(const MapView& m, IoSpec& out) {
  if (const Field* f = m.find("pins")) {
    parse_pin_map(f->value, out.pins);
  }
  const Field* f = m.find("drivers");
  if (out.driver != "composite") {
    if (f != nullptr) {
      r_.error(f->key_loc, f->value.path,
               "only `driver: composite` lists drivers (this is '" + out.driver + "')");
    }
    return;
  }
  if (f == nullptr) {
    r_.error(m.self,
             "driver 'composite' needs `drivers:` (a list of {driver, name, params, pins})");
    return;
  }
  auto items = r_.list(f->value);
  if (!items) {
    return;
  }
  if (items->empty() || items->size() > kMaxDrivers) {
    r_.error(f->value, "must list 1 to " + std::to_string(kMaxDrivers) + " drivers");
    return;
  }
  UniqueNames names;
  for (const Value& item : *items) {
    IoSpec child;
    parse_io_child(item, child);
    if (!child.name.empty()) {
      if (const SourceLoc* first = names.add(child.name, child.name_loc)) {
        r_.error(
            child.name_loc, item.path + ".name",
            "duplicate driver name '" + child.name + "' (first at line " + line_of(*first) + ")");
      }
    }
    out.drivers.push_back(std::move(child));
  }
  if (!out.params.empty()) {
    r_.error(out.params.front().key_loc, "machine.io.params",
             "the composite driver has no parameters of its own: set them on its drivers");
  }
}

void Parser::parse_io_child(const Value& v, IoSpec& out) {
  out.loc = v.loc;
  out.driver_loc = v.loc;
  out.name_loc = v.loc;
  auto m = r_.map(v, {"driver", "name", "params", "pins"});
  if (!m) {
    return;
  }
  if (const Field* f = r_.require(*m, "driver")) {
    out.driver_loc = f->value.loc;
    if (auto s = r_.string(f->value)) {
      if (*s == "composite") {
        r_.error(f->value, "a composite cannot hold another composite");
      } else {
        out.driver = *s;
      }
    }
  }
  if (const Field* f = m->find("name")) {  // a namespace for its parameters: io.<name>.<param>
    out.name_loc = f->value.loc;
    out.name = identifier(f->value, "driver name").value_or("");
  }
  if (const Field* f = m->find("params")) {
    parse_params(f->value, out.params);
  }
  if (const Field* f = m->find("pins")) {
    parse_pin_map(f->value, out.pins);
  }
}

void Parser::parse_pin_map(const Value& v, std::vector<PinMapSpec>& out) {
  auto items = r_.list(v);
  if (!items) {
    return;
  }
  if (items->size() > kMaxPinMapEntries) {
    r_.error(v, "more than " + std::to_string(kMaxPinMapEntries) + " pins");
    return;
  }
  for (const Value& item : *items) {
    auto m = r_.map(item, {});
    if (!m) {
      continue;
    }
    PinMapSpec entry;
    entry.loc = item.loc;
    for (const Field& f : m->fields) {
      if (!yaml_util::is_identifier(f.key)) {
        r_.error(f.key_loc, item.path, "key " + yaml_util::quote(f.key) + " is not an identifier");
        continue;
      }
      if (!r_.scalar(f.value, "a scalar (number, true/false or string)")) {
        continue;
      }
      entry.fields.push_back(
          {f.key, f.value.node.Scalar(), Reader::is_quoted(f.value.node), f.key_loc, f.value.loc});
    }
    out.push_back(std::move(entry));
  }
}

}  // namespace edm::rt::config_detail
