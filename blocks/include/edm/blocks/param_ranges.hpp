#pragma once
// The physical ranges the block and program parameters share (issue 31). Every runtime-writable
// number declares a bounded range (rt::ParamSpec), so that no writer — the bridge, Modbus, MQTT,
// a config — can set a value a machine cannot mean: generous enough for the largest real EDM
// machines and generators, tight enough to refuse nonsense (gap.kg took 9.2e18). Where a range
// comes from is said here; ranges of one parameter alone are at its declaration.
// Sources: ../shared/PLANT-MODEL.md (PM), ../shared/SEEDS.md (seed NNN).

#include "edm/runtime/param.hpp"

namespace edm::blocks::ranges {

// Lengths. The largest die-sinking machines travel ~3 m on one axis; the simulated ones ±100 mm.
/// A position on a machine axis [mm]: ±5 m, beyond the travel of any EDM machine.
inline constexpr rt::Range kPositionMm = rt::closed(-5000.0, 5000.0);
/// A length along one axis or the path [mm] (depth, clearance, retract, back-off): one travel.
inline constexpr rt::Range kLengthMm = rt::closed(0.0, 5000.0);
inline constexpr rt::Range kPositiveLengthMm = rt::open_closed(0.0, 5000.0);
/// A tolerance or window on a position [mm]: 10 mm (the defaults are 0.001-0.002 mm).
inline constexpr rt::Range kToleranceMm = rt::closed(0.0, 10.0);
inline constexpr rt::Range kPositiveToleranceMm = rt::open_closed(0.0, 10.0);

// Motion. PM §3 and §6.5: servo v_max 30 mm/s, jump and retract "several m/min" (v_jump 150
// mm/s), a_max 0.3-2 m/s².
/// An axis or path speed [mm/s]: 1 m/s (60 m/min), above any EDM axis's rapid.
inline constexpr rt::Range kSpeedMmS = rt::open_closed(0.0, 1000.0);
/// An acceleration [mm/s²]: 10 g, five times a fast linear-motor axis.
inline constexpr rt::Range kAccelMmS2 = rt::open_closed(0.0, 1.0e5);
/// A position-loop gain [1/s]: kv·dt < 2 for a stable discrete loop, so 1e4 at a 100 µs task
/// (the 10 kHz bench); the configs use 20-50 (PM §3: ω_n 200 rad/s).
inline constexpr rt::Range kLoopGainPerS = rt::closed(0.0, 1.0e4);

// Pulses. PM §1 and §6.5: Td medians 7.6-222 µs, T_wait 100-300 µs, sinking t_on 1-1000 µs,
// adaptive control starting at t_off 500 µs; seed 000 Table 1: arc-off time 9-50 µs.
/// An ignition delay or its reference [µs]: 10 ms, longer than any generator waits to ignite.
inline constexpr rt::Range kTdUs = rt::closed(0.0, 10000.0);
/// A pulse on- or off-time [µs]: 10 ms.
inline constexpr rt::Range kPulseUs = rt::closed(0.0, 10000.0);
/// A gap or servo reference voltage [V]: at most the open voltage, under 400 V on EDM
/// generators (PM §1: 80-120 V; seed 000 Table 1: servo reference 30-70 V).
inline constexpr rt::Range kVoltageV = rt::closed(0.0, 400.0);

// Time [s] (TIME parameters are ranged in seconds).
/// A process time — a filter's time constant, a ramp, a timeout, a counting window: one hour.
inline constexpr rt::Range kProcessTimeS = rt::closed(0.0, 3600.0);
inline constexpr rt::Range kPositiveProcessTimeS = rt::open_closed(0.0, 3600.0);
/// A settle time of the generator or the electrode [s]: 10 s (the defaults are 20 ms).
inline constexpr rt::Range kSettleS = rt::closed(0.0, 10.0);
inline constexpr rt::Range kPositiveSettleS = rt::open_closed(0.0, 10.0);

// Generic signal blocks (Gain, Limiter, Integrator, filters) carry any signal of the machine:
// mm, mm/s, µs, V, ratios — all far inside ±1e12. The bound refuses only what no sensor or
// set point can be and keeps the arithmetic finite; the "no limit" defaults (±1e9, ±1e12) stay.
/// A value in the signal's unit.
inline constexpr rt::Range kSignal = rt::closed(-1.0e12, 1.0e12);
/// A rate in signal units per second (0: unlimited).
inline constexpr rt::Range kSignalRate = rt::closed(0.0, 1.0e12);
/// A gain between two signals: ±1e6 (unit conversions and servo gains are 1e-3..1e3).
inline constexpr rt::Range kGain = rt::closed(-1.0e6, 1.0e6);
/// An estimator's start value or model coefficient (RLS θ, STR β, ILC p0 and kδ): ±1e6; the
/// shipped configs use up to 1290 (kδ of the sinking ILC).
inline constexpr rt::Range kCoefficient = rt::closed(-1.0e6, 1.0e6);

// Counts at the task rate. 1e6 cycles is 1000 s at 1 kHz.
inline constexpr rt::Range kCycles = rt::closed(1.0, 1.0e6);

}  // namespace edm::blocks::ranges
