#pragma once
// What each alarm code means to an operator (issue 33, "alarms that say why"): the cause in
// words and the remedy, as the page, `edmhmi alarms` and `edmhmi status` show them beside the
// alarm's own source, text and value. The table of docs/safety.md "Alarm codes" is this one;
// tests/runtime/alarm_help_test.cpp checks that every code has both texts and is in the doc.
//
// RT-safety: static strings; the lookup is a switch (callable anywhere, never allocates).

#include <span>
#include <string_view>

#include "edm/runtime/machine.hpp"

namespace edm::rt {

struct AlarmHelp {
  std::string_view cause;   // what raised it, in words
  std::string_view remedy;  // what the operator does about it
};

/// The help text of `code`; empty views for kNone and for a code this build does not know.
[[nodiscard]] AlarmHelp alarm_help(AlarmCode code) noexcept;

/// Every alarm code the runtime raises, kNone excluded, in numeric order.
[[nodiscard]] std::span<const AlarmCode> all_alarm_codes() noexcept;

}  // namespace edm::rt
