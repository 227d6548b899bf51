#pragma once
// Every op's handler, each run by run_op() from its row of the op table (op_table.cpp) once the
// role and state checks passed. Server thread only.

#include <chrono>
#include <functional>
#include <optional>
#include <string>

#include "edm/bridge/op_table.hpp"
#include "edm/runtime/machine.hpp"

namespace edm::bridge::ops {

// ops.cpp: the session, program transfer and machine commands.
Body op_hello(Session& s, const Json& msg);
Body op_ping(Session& s, const Json& msg);
Body op_status(Session& s, const Json& msg);
Body op_subscribe(Session& s, const Json& msg);
Body op_unsubscribe(Session& s, const Json& msg);
Body op_program_begin(Session& s, const Json& msg);
Body op_program_chunk(Session& s, const Json& msg);
Body op_program_commit(Session& s, const Json& msg);
Body op_program_abort(Session& s, const Json& msg);
Body op_cycle_start(Session& s, const Json& msg);
Body op_cycle_hold(Session& s, const Json& msg);
Body op_cycle_resume(Session& s, const Json& msg);
Body op_cycle_stop(Session& s, const Json& msg);
Body op_estop(Session& s, const Json& msg);
Body op_reset(Session& s, const Json& msg);
Body op_tasks_stats(Session& s, const Json& msg);
Body op_machine_info(Session& s, const Json& msg);
Body op_feed_override(Session& s, const Json& msg);

/// A hello that the failed-hello throttle does not let be evaluated yet: when it may be. Nullopt
/// when it may be evaluated now (or its "peer" is invalid: op_hello refuses it at once).
std::optional<std::chrono::steady_clock::time_point> hello_wait(Session& s, const Json& msg);

// ops_vars.cpp: variables and traces.
Body op_var_list(Session& s, const Json& msg);
Body op_var_read(Session& s, const Json& msg);
Body op_var_write(Session& s, const Json& msg);
Body op_var_force(Session& s, const Json& msg);
Body op_var_unforce(Session& s, const Json& msg);
Body op_trace_start(Session& s, const Json& msg);
Body op_trace_stop(Session& s, const Json& msg);

// ops_operator.cpp: the operator functions.
Body op_home(Session& s, const Json& msg);
Body op_jog(Session& s, const Json& msg);
Body op_jog_stop(Session& s, const Json& msg);
Body op_touch(Session& s, const Json& msg);
Body op_manual_status(Session& s, const Json& msg);

// ops_offsets.cpp: the work offsets (retained).
Body op_offset_get(Session& s, const Json& msg);
Body op_offset_set(Session& s, const Json& msg);
/// Syncs the retain file after a change; when the file cannot be written, undo() restores the
/// old value and the error names what stays unchanged. nullopt: kept (or nothing is retained).
std::optional<Body> retained_or_undone(Session& s, const std::string& what,
                                       const std::function<void()>& undo);

// ops_electrode.cpp: the electrode in the spindle, its length and the electrode table.
Body op_electrode_get(Session& s, const Json& msg);
Body op_electrode_set(Session& s, const Json& msg);
Body op_electrode_change(Session& s, const Json& msg);
Body op_electrode_measure(Session& s, const Json& msg);

// server_jobs.cpp: the job log.
Body op_jobs_get(Session& s, const Json& msg);
/// ops_conditions.cpp: an operator's edit of one field of a machining condition.
Body op_condition_set(Session& s, const Json& msg);

// ops_alarms.cpp: the active alarms and the history, each with its cause and remedy.
Body op_alarms_get(Session& s, const Json& msg);
/// One alarm as the `alarm` event and the history carry it (source, text, value, machine and
/// wall time, cause, remedy).
Json alarm_json(const rt::Alarm& a, std::chrono::system_clock::time_point wall);
/// UTC to the millisecond, as the alarms and the job log carry it: "2026-12-03T12:34:56.789Z".
std::string wall_time(std::chrono::system_clock::time_point t);

}  // namespace edm::bridge::ops
