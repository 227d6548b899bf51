#pragma once
// Sparkplug B payloads for the MQTT unit tests, built with the generated protobuf classes (so a
// test can send what edmplc's own encode() never would: a wrong wire field, no name, an alias).

#include <cstdint>
#include <string>

#include "sparkplug_b.pb.h"

namespace edm::sparkplug::test {

namespace pb = edm::sparkplug::pb;

inline pb::Payload::Metric* add_metric(pb::Payload& p, const std::string& name,
                                       std::uint32_t datatype) {
  pb::Payload::Metric* m = p.add_metrics();
  if (!name.empty()) m->set_name(name);
  m->set_datatype(datatype);
  return m;
}

/// One metric `name` of `datatype` whose value `set` fills (e.g. set_long_value).
template <class Set>
std::string one_metric(const std::string& name, std::uint32_t datatype, Set set) {
  pb::Payload p;
  p.set_timestamp(1);
  set(*add_metric(p, name, datatype));
  return p.SerializeAsString();
}

inline std::string double_metric(const std::string& name, double v) {
  return one_metric(name, pb::Double, [v](pb::Payload::Metric& m) { m.set_double_value(v); });
}

inline std::string int64_metric(const std::string& name, std::int64_t v) {
  return one_metric(name, pb::Int64, [v](pb::Payload::Metric& m) {
    m.set_long_value(static_cast<std::uint64_t>(v));
  });
}

/// `n` metrics called `name` (each a Double), as one payload.
inline std::string many_metrics(std::size_t n, const std::string& name = "m") {
  pb::Payload p;
  for (std::size_t i = 0; i < n; ++i) add_metric(p, name, pb::Double)->set_double_value(1.0);
  return p.SerializeAsString();
}

}  // namespace edm::sparkplug::test
