#pragma once
// The parts of SimParams::visit (params.cpp), one for each section of the struct (params.hpp),
// called in declaration order. `v` marks every field it is given load time only; `writable` is the
// caller's own visitor, for the fields the driver applies at run time (the electrode's length, the
// hole). Non-RT.

#include "edm/runtime/param.hpp"
#include "edm/sim/params.hpp"

namespace edm::sim {

/// The generator (§1): voltages, current, pulse times.
void visit_generator(SimParams& p, edm::rt::ParamVisitor& v);
/// The ignition delay (§1, §6.2 step 4).
void visit_ignition(SimParams& p, edm::rt::ParamVisitor& v);
/// Shorts (§6.2 steps 1-2), short events at the gap (§4a), the injected contact.
void visit_shorts(SimParams& p, edm::rt::ParamVisitor& v);
/// Arcs (§6.2 step 3).
void visit_arcs(SimParams& p, edm::rt::ParamVisitor& v);
/// Removal and wear (§2, §6.2 step 6).
void visit_removal(SimParams& p, edm::rt::ParamVisitor& v);
/// The tool and the work's thickness, where the tip starts.
void visit_electrode(SimParams& p, edm::rt::ParamVisitor& v, edm::rt::ParamVisitor& writable);
/// The work on the machine, the reference switches, encoders, touch mode, the hole (§3a).
void visit_work(SimParams& p, edm::rt::ParamVisitor& v, edm::rt::ParamVisitor& writable);
/// Debris and flushing (§6.2 step 7).
void visit_flushing(SimParams& p, edm::rt::ParamVisitor& v);
/// The axes (§3, §6.3).
void visit_axes(SimParams& p, edm::rt::ParamVisitor& v);
/// WEDM (§6.4).
void visit_wire(SimParams& p, edm::rt::ParamVisitor& v);
/// The sensors (§6.2 step 8) and the cost bound.
void visit_sensors(SimParams& p, edm::rt::ParamVisitor& v);

}  // namespace edm::sim
