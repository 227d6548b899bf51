#include "supervisor_builder.hpp"

#include <string>

namespace edm::rt {

namespace {

std::string describe(const PinRef& p) {
  return std::string(to_string(p.type)) + (p.dir == PinDir::kInput ? " input" : " output");
}

// The pin `n` as a T pin of direction `dir`, or nullptr after reporting what it is instead.
template <PinValue T>
void* typed_pin(const PinRef& p, PinDir dir, const NameRef& n, const char* role,
                DiagnosticSink& diag) {
  if (p.pin == nullptr) {
    return nullptr;
  }
  if (p.dir == dir && p.type == PinTypeOf<T>::value) {
    return p.pin;
  }
  const std::string want = std::string(to_string(PinTypeOf<T>::value)) +
                           (dir == PinDir::kInput ? " input (a command to the machine)"
                                                  : " output (a reading from the machine)");
  diag.error(n.loc, "machine.safety: '" + n.name + "' (" + role + ") must be a " + want +
                        " of the I/O driver; it is a " + describe(p));
  return nullptr;
}

}  // namespace

std::unique_ptr<Supervisor> build_supervisor(const SafetySpec& spec,
                                             const machining::MachineTables& tables,
                                             Machine& machine, const ManualControl* manual,
                                             Duration io_period, const IoPinResolver& resolve,
                                             DiagnosticSink& diag) {
  if (!spec.present) {
    return nullptr;
  }
  const std::size_t errors_before = diag.diagnostics().size();
  SupervisorSetup setup;
  for (const SafetyAxisSpec& a : spec.axes) {
    const machining::AxisLimits* lim = tables.axis(a.name);
    if (lim == nullptr) {
      continue;  // reported by the parser
    }
    SupervisedAxis s;
    s.limits = *lim;
    s.velocity = static_cast<Input<double>*>(
        typed_pin<double>(resolve(a.velocity), PinDir::kInput, a.velocity, "velocity", diag));
    s.position = static_cast<const Output<double>*>(
        typed_pin<double>(resolve(a.position), PinDir::kOutput, a.position, "position", diag));
    s.ferror_mm = a.ferror_mm.value_or(0.0);
    s.min_ferror_mm = a.min_ferror_mm.value_or(s.ferror_mm);
    s.retract = a.retract;
    setup.axes.push_back(s);
  }
  if (spec.electrode_length) {
    const NameRef& n = *spec.electrode_length;
    setup.electrode_mm = static_cast<const Output<double>*>(
        typed_pin<double>(resolve(n), PinDir::kOutput, n, "electrode.length", diag));
    setup.electrode_margin_mm = spec.electrode_margin_mm;
  }
  if (spec.wire_break) {
    const NameRef& n = *spec.wire_break;
    setup.wire_broken = static_cast<const Output<bool>*>(
        typed_pin<bool>(resolve(n), PinDir::kOutput, n, "wire_break", diag));
  }
  for (const NameRef& n : spec.generator) {
    setup.generator.push_back(static_cast<Input<bool>*>(
        typed_pin<bool>(resolve(n), PinDir::kInput, n, "generator", diag)));
  }
  if (spec.short_stop) {
    const ShortStopSpec& ss = *spec.short_stop;
    setup.short_count = static_cast<const Output<std::int64_t>*>(typed_pin<std::int64_t>(
        resolve(ss.shorts), PinDir::kOutput, ss.shorts, "short_stop.shorts", diag));
    for (const NameRef& n : ss.pulses) {
      setup.pulse_counts.push_back(static_cast<const Output<std::int64_t>*>(
          typed_pin<std::int64_t>(resolve(n), PinDir::kOutput, n, "short_stop.pulses", diag)));
    }
    setup.short_limit = ss.limit;
  }
  if (diag.diagnostics().size() != errors_before) {
    return nullptr;
  }
  setup.manual = manual;
  return std::make_unique<Supervisor>(machine, std::move(setup), io_period);
}

}  // namespace edm::rt
