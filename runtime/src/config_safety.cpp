// Config parser: the `machine.safety` section (the safety supervisor, supervisor.hpp): keys,
// types, ranges and the names of its axes. Whether the io.* pins exist, and have the right
// direction and type, is the builder's check (runtime_builder.cpp). docs/config.md: the schema.

#include <algorithm>

#include "config_parser_impl.hpp"

namespace edm::rt::config_detail {

std::optional<NameRef> Parser::io_pin_name(const Value& v) {
  auto s = r_.string(v);
  if (!s) {
    return std::nullopt;
  }
  if (s->rfind("io.", 0) != 0 || !yaml_util::is_dotted_name(*s, 2, 2)) {
    r_.error(v, yaml_util::quote(*s) +
                    " is not a process-image pin (io.<pin>): the supervisor watches the I/O "
                    "driver, not a program");
    return std::nullopt;
  }
  return NameRef{*s, v.loc};
}

void Parser::parse_safety_axis(const Value& v, const MachineSpec& machine, SafetyAxisSpec& out) {
  out.loc = v.loc;
  auto m = r_.map(v, {"name", "velocity", "position", "ferror_mm", "min_ferror_mm", "retract"});
  if (!m) {
    return;
  }
  if (const Field* f = r_.require(*m, "name")) {
    if (auto s = r_.string(f->value)) {
      const bool known =
          s->size() == 1 && std::any_of(machine.axes.begin(), machine.axes.end(),
                                        [&](const AxisSpec& a) { return a.name == (*s)[0]; });
      if (!known) {
        std::string names;
        for (const AxisSpec& a : machine.axes) {
          names += (names.empty() ? "" : ", ") + std::string(1, a.name);
        }
        r_.error(f->value, "no axis " + yaml_util::quote(*s) +
                               " in machine.axes (its soft limits and v_max come from there; "
                               "axes: " +
                               (names.empty() ? std::string("none") : names) + ")");
      } else {
        out.name = (*s)[0];
      }
    }
  }
  if (const Field* f = r_.require(*m, "velocity")) {
    if (auto n = io_pin_name(f->value)) out.velocity = *n;
  }
  if (const Field* f = r_.require(*m, "position")) {
    if (auto n = io_pin_name(f->value)) out.position = *n;
  }
  const Field* ferror = m->find("ferror_mm");
  if (ferror != nullptr) {
    if (auto x = r_.real(ferror->value)) {
      if (*x <= 0.0) {
        r_.error(ferror->value, "must be > 0 (got " + ferror->value.node.Scalar() + ")");
      } else {
        out.ferror_mm = *x;
      }
    }
  }
  if (const Field* f = m->find("min_ferror_mm")) {
    if (ferror == nullptr) {
      r_.error(f->value, "needs ferror_mm (the limit at v_max) beside it");
    } else if (auto x = r_.real(f->value)) {
      if (*x <= 0.0) {
        r_.error(f->value, "must be > 0 (got " + f->value.node.Scalar() + ")");
      } else if (out.ferror_mm && *x > *out.ferror_mm) {
        r_.error(f->value, "must be <= ferror_mm (got " + f->value.node.Scalar() + " > " +
                               ferror->value.node.Scalar() + ")");
      } else {
        out.min_ferror_mm = *x;
      }
    }
  }
  if (const Field* f = m->find("retract")) {
    if (auto s = r_.choice(f->value, {"positive", "negative", "none"})) {
      out.retract = *s == "positive"   ? RetractDirection::kPlus
                    : *s == "negative" ? RetractDirection::kMinus
                                       : RetractDirection::kNone;
    }
  }
}

void Parser::parse_short_stop(const Value& v, SafetySpec& out) {
  auto m = r_.map(v, {"shorts", "pulses", "limit"});
  if (!m) {
    return;
  }
  ShortStopSpec s;
  s.loc = v.loc;
  if (const Field* f = r_.require(*m, "shorts")) {
    if (auto n = io_pin_name(f->value)) s.shorts = *n;
  }
  if (const Field* f = r_.require(*m, "pulses")) {
    if (auto items = r_.list(f->value)) {
      if (items->empty()) {
        r_.error(f->value,
                 "needs at least one pin: the pulse counters that add up to all pulses "
                 "of a cycle");
      }
      for (const Value& item : *items) {
        if (auto n = io_pin_name(item)) s.pulses.push_back(*n);
      }
    }
  }
  if (const Field* f = m->find("limit")) {
    if (auto x = r_.real(f->value)) {
      if (!(*x > 0.0 && *x <= 1.0)) {
        r_.error(f->value,
                 "must be in (0, 1], the fraction of a cycle's pulses that are shorts "
                 "(got " +
                     f->value.node.Scalar() + ")");
      } else {
        s.limit = *x;
      }
    }
  }
  const bool any_retract = std::any_of(out.axes.begin(), out.axes.end(), [](const auto& a) {
    return a.retract != RetractDirection::kNone;
  });
  if (!any_retract) {
    r_.error(v,
             "no supervised axis has a retract direction (axes[].retract): the short stop "
             "cuts the motion against it, toward the work");
  }
  out.short_stop = std::move(s);
}

void Parser::parse_safety(const Value& v, MachineSpec& machine) {
  SafetySpec& out = machine.safety;
  out.present = true;
  out.loc = v.loc;
  auto m = r_.map(v, {"axes", "electrode", "wire_break", "generator", "short_stop"});
  if (!m) {
    return;
  }
  // io pins already claimed, with where: one pin is one axis's command or one alarm's input.
  UniqueNames pins;
  auto claim = [&](const NameRef& n, const Value& at) {
    if (const SourceLoc* first = pins.add(n.name, n.loc)) {
      r_.error(at, yaml_util::quote(n.name) + " is supervised twice (first at line " +
                       line_of(*first) + ")");
    }
  };
  if (const Field* f = m->find("axes")) {
    if (auto items = r_.list(f->value)) {
      UniqueNames names;
      for (const Value& item : *items) {
        SafetyAxisSpec a;
        parse_safety_axis(item, machine, a);
        if (!a.velocity.name.empty()) {
          claim(a.velocity, Value{item.node, a.velocity.loc, item.path + ".velocity"});
        }
        const std::string key(1, a.name);
        if (a.name == '\0') {
          // no (valid) name: reported above
        } else if (const SourceLoc* first = names.add(key, a.loc)) {
          r_.error(item, "axis '" + key + "' is supervised twice (first at line " +
                             line_of(*first) + ")");
        }
        out.axes.push_back(std::move(a));
      }
    }
  }
  if (const Field* f = m->find("electrode")) {
    if (auto e = r_.map(f->value, {"length", "margin_mm"})) {
      if (const Field* g = r_.require(*e, "length")) {
        out.electrode_length = io_pin_name(g->value);
      }
      if (const Field* g = r_.require(*e, "margin_mm")) {
        if (auto x = r_.real(g->value)) {
          if (*x < 0.0) {
            r_.error(g->value, "must be >= 0 (got " + g->value.node.Scalar() + ")");
          } else {
            out.electrode_margin_mm = *x;
          }
        }
      }
    }
  }
  if (const Field* f = m->find("wire_break")) {
    out.wire_break = io_pin_name(f->value);
  }
  if (const Field* f = m->find("generator")) {
    if (auto items = r_.list(f->value)) {
      for (const Value& item : *items) {
        if (auto n = io_pin_name(item)) {
          claim(*n, item);
          out.generator.push_back(*n);
        }
      }
    }
  }
  if (const Field* f = m->find("short_stop")) {
    parse_short_stop(f->value, out);  // after the axes: it needs one with a retract direction
  }
}

}  // namespace edm::rt::config_detail
