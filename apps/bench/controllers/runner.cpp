// One simulated run of the controller benchmark: build, step on the virtual clock, measure.

#include <algorithm>
#include <chrono>
#include <cmath>
#include <memory>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "bench.hpp"
#include "edm/apps/offline_runtime.hpp"
#include "edm/apps/text_file.hpp"
#include "edm/runtime/clock.hpp"
#include "edm/runtime/config.hpp"
#include "edm/runtime/runtime.hpp"
#include "edm/runtime/scheduler.hpp"
#include "edm/sim/plant.hpp"
#include "edm/sim/sim_driver.hpp"

namespace edm::bench {
namespace {

using namespace std::chrono_literals;

void replace_once(std::string& s, const std::string& from, const std::string& to,
                  const std::string& where) {
  const auto at = s.find(from);
  if (at == std::string::npos) {
    throw std::runtime_error(where + ": edit target '" + from + "' not found");
  }
  s.replace(at, from.size(), to);
}

// Least-squares line through (t, z); the RMS residual is the jitter of one cycle.
struct LineFit {
  double n{0}, st{0}, stt{0}, sz{0}, stz{0}, szz{0};
  void add(double t, double z) {
    n += 1;
    st += t;
    stt += t * t;
    sz += z;
    stz += t * z;
    szz += z * z;
  }
  [[nodiscard]] double rms_residual() const {
    if (n < 3) {
      return 0.0;
    }
    const double vtt = stt - st * st / n;
    const double vtz = stz - st * sz / n;
    const double vzz = szz - sz * sz / n;
    const double ss = vtt > 0 ? vzz - vtz * vtz / vtt : vzz;
    return std::sqrt(std::max(0.0, ss) / n);
  }
};

double mean_of(const std::vector<double>& v, std::size_t from, std::size_t to) {
  if (to <= from) {
    return 0.0;
  }
  double s = 0;
  for (std::size_t i = from; i < to; ++i) {
    s += v[i];
  }
  return s / static_cast<double>(to - from);
}

}  // namespace

std::vector<std::pair<const char*, double>> Outcome::fields() const {
  return {{"time_s", time_s},
          {"reached", reached},
          {"time_to_depth_s", time_to_depth_s},
          {"depth_mm", depth_mm},
          {"depth_error_um", depth_error_um},
          {"speed_mm_min", speed_mm_min},
          {"mrr_mm3_min", mrr_mm3_min},
          {"short_pct", short_pct},
          {"arc_pct", arc_pct},
          {"open_pct", open_pct},
          {"retracts", retracts},
          {"electrode_used_mm", electrode_used_mm},
          {"td_rms_us", td_rms_us},
          {"wire_broken", wire_broken},
          {"break_time_s", break_time_s},
          {"rab_mean", rab_mean},
          {"rab_err_rms", rab_err_rms},
          {"rab_above_max", rab_above_max},
          {"rab_below_max", rab_below_max},
          {"rab_in_band_s", rab_in_band_s},
          {"overload_s", overload_s},
          {"ratio_normal_pct", ratio_normal_pct},
          {"ratio_tarc_pct", ratio_tarc_pct},
          {"ratio_sarc_pct", ratio_sarc_pct},
          {"ratio_short_pct", ratio_short_pct},
          {"ratio_open_pct", ratio_open_pct},
          {"jitter_um", jitter_um},
          {"jitter_first_um", jitter_first_um},
          {"jitter_last_um", jitter_last_um},
          {"loop_y_mean", loop_y_mean},
          {"loop_ref_mean", loop_ref_mean},
          {"loop_err_rms", loop_err_rms},
          {"wall_err_um", wall_err_um},
          {"circularity_um", circularity_um},
          {"wall_worst_um", wall_worst_um},
          {"recovery_s", recovery_s},
          {"peak_short_pct", peak_short_pct},
          {"peak_arc_pct", peak_arc_pct},
          {"stalls", stalls}};
}

std::pair<double, double> mean_sd(const std::vector<double>& v) {
  if (v.empty()) {
    return {0.0, 0.0};
  }
  double m = 0;
  for (double x : v) {
    m += x;
  }
  m /= static_cast<double>(v.size());
  if (v.size() < 2) {
    return {m, 0.0};
  }
  double ss = 0;
  for (double x : v) {
    ss += (x - m) * (x - m);
  }
  return {m, std::sqrt(ss / static_cast<double>(v.size() - 1))};
}

Outcome run(const std::string& source_root, const RunSpec& spec) {
  std::string text = apps::read_text_file(source_root + "/" + spec.config);
  for (const Edit& e : spec.edits) {
    replace_once(text, e.from, e.to, spec.config);
  }
  std::string seed = "seed: " + std::to_string(spec.seed);
  if (!spec.io_extra.empty()) {
    seed += ", " + spec.io_extra;
  }
  replace_once(text, "seed: 1}", seed + "}", spec.config);
  auto r = apps::build_offline(rt::parse_config_text(text, spec.config));
  std::vector<rt::Task*> tasks;
  for (const auto& t : r->tasks()) {
    t->detach_trace();  // nobody drains the trace rings here
    tasks.push_back(t.get());
  }
  r->machine().command(rt::MachineCommand::kPowerOn);
  auto& vars = r->variables();
  auto pin = [&](const std::string& name) {
    const rt::Variable* v = vars.find(name);
    if (v == nullptr || !v->is_pin()) {
      throw std::runtime_error(spec.config + ": no pin '" + name + "'");
    }
    return v->pin;
  };
  const rt::PinRef n_open = pin("io.n_open"), n_normal = pin("io.n_normal"),
                   n_tarc = pin("io.n_transient_arc"), n_sarc = pin("io.n_stable_arc"),
                   n_short = pin("io.n_short");
  const rt::PinRef r_normal = pin("io.ratio_normal"), r_tarc = pin("io.ratio_transient_arc"),
                   r_sarc = pin("io.ratio_stable_arc"), r_short = pin("io.ratio_short"),
                   r_open = pin("io.ratio_open");
  const rt::PinRef td_sum = pin("io.td_sum_ns"), td_count = pin("io.td_count");
  const rt::PinRef depth = pin("io.depth_mm"), z = pin("io.z_mm"), vz = pin("io.vz_cmd");
  const rt::PinRef electrode = pin("io.electrode_mm"), broken = pin("io.wire_broken");
  const rt::PinRef rab = pin("io.rab"), wire_load = pin("io.wire_load");
  const bool has_done = !spec.done_var.empty();
  const bool has_loop = !spec.loop_y_var.empty();
  const rt::PinRef loop_y = has_loop ? pin(spec.loop_y_var) : rt::PinRef{};
  const rt::PinRef loop_ref = has_loop ? pin(spec.loop_ref_var) : rt::PinRef{};
  double loop_y_sum = 0, loop_ref_sum = 0, loop_err_ss = 0, loop_n = 0;
  const rt::PinRef done = has_done ? pin(spec.done_var) : rt::PinRef{};

  const sim::Plant* plant = nullptr;
  double wall_target_mm = 0.0;
  if (spec.wall_growth_mm > 0) {
    auto* drv = dynamic_cast<sim::SimDriver*>(&r->driver());
    if (drv == nullptr) {
      throw std::runtime_error(spec.config + ": B4 needs the sim driver");
    }
    plant = &drv->plant();
    double s0 = 0;
    for (std::size_t j = 0; j < sim::Plant::kWallBins; ++j) {
      s0 += plant->wall_bin_radius_mm(j);
    }
    wall_target_mm = s0 / static_cast<double>(sim::Plant::kWallBins) + spec.wall_growth_mm;
  }
  // B3: 100 ms windows from the drop on: short %, arc %, true depth gained [mm].
  struct Window {
    double short_pct, arc_pct, gained_mm;
  };
  std::vector<Window> windows;
  bool dropped = false;
  double win_pulses[3] = {0, 0, 0};  // all, shorts, arcs
  int win_n = 0;
  double win_d0 = 0;

  rt::VirtualClock clock;
  rt::VirtualScheduler sched(tasks, clock);
  Outcome o;
  const auto limit_ms = static_cast<std::int64_t>(std::llround(spec.limit_s * 1000.0));
  const auto period_ms = static_cast<std::int64_t>(std::llround(spec.jump_period_s * 1000.0));
  constexpr std::int64_t kJumpUpMs = 40, kJumpDownMs = 50, kSettleMs = 200;
  double pulses[5] = {0, 0, 0, 0, 0};  // open, normal, transient arc, stable arc, short
  double ratios[5] = {0, 0, 0, 0, 0};  // normal, transient arc, stable arc, short, open
  double td_ss = 0, td_n = 0;
  double electrode0 = -1.0;
  bool vz_high = false, reached = false;
  // Wire: io.rab after the transient (per ms, for rab_mean) and per whole second of the run.
  const auto transient_ms = static_cast<std::int64_t>(std::llround(spec.transient_s * 1000.0));
  double rab_sum = 0, rab_n = 0, rab_err_ss = 0, rab_err_n = 0;
  double rab_sec = 0, sec_open = 0, sec_pulses = 0;  // this second's sums
  double last_out_of_band_s = 0;                     // end of the last second out of the band
  LineFit fit;
  std::int64_t k = 0;
  std::int64_t end_ms = limit_ms;
  for (k = 1; k <= limit_ms; ++k) {
    // Jumps: forced up, forced back down short of the start, then the servo closes the gap.
    if (period_ms > 0 && k > period_ms) {
      const std::int64_t phase = (k - 1) % period_ms;
      auto force = [&](const std::string& name, double value) {
        if (name.empty()) {
          return;
        }
        if (const rt::VarStatus st = vars.force(name, value); !st) {
          throw std::runtime_error(spec.config + ": cannot force '" + name + "': " + st.message);
        }
      };
      if (phase == 0) {
        o.jitter_per_cycle_um.push_back(fit.rms_residual() * 1000.0);
        fit = LineFit{};
        vars.force("io.vz_cmd", 30.0);
        force(spec.jump_cycle_var, 1.0);
        force(spec.jump_hold_var, spec.jump_hold_value);
        force(spec.jump_track_var, rt::read_pin_as_double(z));
      } else if (phase == 1) {
        force(spec.jump_cycle_var, 0.0);
      } else if (phase == kJumpUpMs) {
        vars.force("io.vz_cmd", -30.0);
      }
      if (phase == kJumpUpMs + kJumpDownMs) {
        vars.unforce("io.vz_cmd");
        if (!spec.jump_track_var.empty()) {
          vars.unforce(spec.jump_track_var);
        }
      }
      if (phase == kJumpUpMs + kJumpDownMs +
                       static_cast<std::int64_t>(std::llround(spec.jump_hold_extra_ms)) &&
          !spec.jump_hold_var.empty()) {
        vars.unforce(spec.jump_hold_var);
      }
    }
    sched.run_until(rt::TimePoint{1ms * k});
    const double t_s = static_cast<double>(k) * 1e-3;
    if (electrode0 < 0) {
      electrode0 = rt::read_pin_as_double(electrode);
    }
    const double c[5] = {rt::read_pin_as_double(n_open), rt::read_pin_as_double(n_normal),
                         rt::read_pin_as_double(n_tarc), rt::read_pin_as_double(n_sarc),
                         rt::read_pin_as_double(n_short)};
    for (int i = 0; i < 5; ++i) {
      pulses[i] += c[i];
    }
    const double rr[5] = {rt::read_pin_as_double(r_normal), rt::read_pin_as_double(r_tarc),
                          rt::read_pin_as_double(r_sarc), rt::read_pin_as_double(r_short),
                          rt::read_pin_as_double(r_open)};
    for (int i = 0; i < 5; ++i) {
      ratios[i] += rr[i];
    }
    const double d = rt::read_pin_as_double(depth);
    if (spec.td_ref_us > 0 && d > 0.05) {
      const double cnt = rt::read_pin_as_double(td_count);
      if (cnt > 0) {
        const double e = rt::read_pin_as_double(td_sum) / cnt * 1e-3 - spec.td_ref_us;
        td_ss += e * e;
        td_n += 1;
      }
    }
    const bool in_jump =
        period_ms > 0 && k > period_ms && (k - 1) % period_ms < kJumpUpMs + kJumpDownMs;
    const bool high = rt::read_pin_as_double(vz) > 0.2;
    if (high && !vz_high && !in_jump) {
      o.retracts += 1;
    }
    vz_high = high;
    const bool servo_part =
        period_ms == 0 || (k - 1) % period_ms >= kJumpUpMs + kJumpDownMs + kSettleMs;
    if (period_ms > 0 && servo_part) {
      fit.add(t_s, rt::read_pin_as_double(z));
    }
    if (has_loop && servo_part) {
      const double y = rt::read_pin_as_double(loop_y), yr = rt::read_pin_as_double(loop_ref);
      loop_y_sum += y;
      loop_ref_sum += yr;
      loop_err_ss += (y - yr) * (y - yr);
      loop_n += 1;
    }
    if (rt::read_pin_as_double(wire_load) > 0.9) {
      o.overload_s += 1e-3;
    }
    if (spec.rab_ref > 0 && o.wire_broken == 0.0) {
      const double x = rt::read_pin_as_double(rab);
      if (k > transient_ms) {
        rab_sum += x;
        rab_n += 1;
      }
      rab_sec += x;
      sec_open += c[0];
      sec_pulses += c[0] + c[1] + c[2] + c[3] + c[4];
      if (k % 1000 == 0) {  // a whole second: its mean Rab
        const double mean = rab_sec / 1000.0;
        o.rab_per_s.push_back(mean);
        // Scored only while the wire cuts: a second with most pulses open (crossing a
        // through-hole, or backed off the work) has no sparks for Rab to measure.
        if (sec_open <= 0.5 * sec_pulses) {
          const double e = mean - spec.rab_ref;
          if (std::fabs(e) > kRabBand) {
            last_out_of_band_s = t_s;
          }
          if (k - 1000 >= transient_ms) {  // the whole second after the transient
            rab_err_ss += e * e;
            rab_err_n += 1;
            o.rab_above_max = std::max(o.rab_above_max, e);
            o.rab_below_max = std::max(o.rab_below_max, -e);
          }
        }
        rab_sec = sec_open = sec_pulses = 0.0;
      }
    }
    const bool cutting = !has_done || spec.window_end_state <= 0 ||
                         rt::read_pin_as_double(done) < spec.window_end_state;
    if (spec.flush_drop_mm > 0 && !reached && cutting) {
      if (!dropped && d >= spec.flush_drop_mm) {
        dropped = true;
        win_d0 = d;
      }
      if (dropped) {
        win_pulses[0] += c[0] + c[1] + c[2] + c[3] + c[4];
        win_pulses[1] += c[4];
        win_pulses[2] += c[2] + c[3];
        if (++win_n == 100) {
          const double all = std::max(1.0, win_pulses[0]);
          windows.push_back({100.0 * win_pulses[1] / all, 100.0 * win_pulses[2] / all, d - win_d0});
          win_pulses[0] = win_pulses[1] = win_pulses[2] = 0;
          win_n = 0;
          win_d0 = d;
        }
      }
    }
    if (spec.target_depth_mm > 0 && !reached && d >= spec.target_depth_mm - 0.05) {
      reached = true;
      o.time_to_depth_s = t_s;
    }
    if (o.wire_broken == 0.0 && rt::read_pin_as_double(broken) != 0.0) {
      o.wire_broken = 1.0;
      o.break_time_s = t_s;
    }
    if ((spec.stop_at_depth && reached) ||
        (has_done && rt::read_pin_as_double(done) == spec.done_value) || o.wire_broken != 0.0) {
      end_ms = k;
      break;
    }
  }
  o.time_s = static_cast<double>(std::min(end_ms, limit_ms)) * 1e-3;
  o.depth_mm = rt::read_pin_as_double(depth);
  o.reached = (has_done ? rt::read_pin_as_double(done) == spec.done_value : reached) ? 1.0 : 0.0;
  if (!reached) {
    o.time_to_depth_s = spec.limit_s;
  }
  o.depth_error_um = spec.target_depth_mm > 0 ? (o.depth_mm - spec.target_depth_mm) * 1000.0 : 0.0;
  const double t_cut = reached && spec.stop_at_depth ? o.time_to_depth_s : o.time_s;
  o.speed_mm_min = t_cut > 0 ? o.depth_mm / t_cut * 60.0 : 0.0;
  o.mrr_mm3_min = o.speed_mm_min * 100.0;  // sink: 10 × 10 mm electrode
  const double all = pulses[0] + pulses[1] + pulses[2] + pulses[3] + pulses[4];
  if (all > 0) {
    o.open_pct = 100.0 * pulses[0] / all;
    o.arc_pct = 100.0 * (pulses[2] + pulses[3]) / all;
    o.short_pct = 100.0 * pulses[4] / all;
  }
  const double cycles = static_cast<double>(std::min(end_ms, limit_ms));
  o.ratio_normal_pct = 100.0 * ratios[0] / cycles;
  o.ratio_tarc_pct = 100.0 * ratios[1] / cycles;
  o.ratio_sarc_pct = 100.0 * ratios[2] / cycles;
  o.ratio_short_pct = 100.0 * ratios[3] / cycles;
  o.ratio_open_pct = 100.0 * ratios[4] / cycles;
  o.electrode_used_mm = electrode0 - rt::read_pin_as_double(electrode);
  o.td_rms_us = td_n > 0 ? std::sqrt(td_ss / td_n) : 0.0;
  if (o.wire_broken == 0.0) {
    o.break_time_s = spec.limit_s;
  }
  o.rab_in_band_s = o.wire_broken != 0.0 || last_out_of_band_s > spec.limit_s - 0.5
                        ? spec.limit_s
                        : last_out_of_band_s;
  o.rab_mean = rab_n > 0 ? rab_sum / rab_n : 0.0;
  if (loop_n > 0) {
    o.loop_y_mean = loop_y_sum / loop_n;
    o.loop_ref_mean = loop_ref_sum / loop_n;
    o.loop_err_rms = std::sqrt(loop_err_ss / loop_n);
  }
  o.rab_err_rms = rab_err_n > 0 ? std::sqrt(rab_err_ss / rab_err_n) : 0.0;
  if (plant != nullptr) {
    double sum = 0, lo = 1e9, hi = -1e9;
    for (std::size_t j = 0; j < sim::Plant::kWallBins; ++j) {
      const double x = plant->wall_bin_radius_mm(j);
      sum += x;
      lo = std::min(lo, x);
      hi = std::max(hi, x);
    }
    o.wall_err_um = (sum / static_cast<double>(sim::Plant::kWallBins) - wall_target_mm) * 1000.0;
    o.circularity_um = (hi - lo) * 1000.0;
    const double e_lo = (lo - wall_target_mm) * 1000.0, e_hi = (hi - wall_target_mm) * 1000.0;
    o.wall_worst_um = std::abs(e_lo) > std::abs(e_hi) ? e_lo : e_hi;
  }
  if (spec.flush_drop_mm > 0) {
    constexpr std::size_t kSettled = 10;  // 1 s of 100 ms windows
    std::size_t ok_run = 0;
    o.recovery_s = -1.0;
    for (std::size_t i = 0; i < windows.size(); ++i) {
      const Window& w = windows[i];
      o.peak_short_pct = std::max(o.peak_short_pct, w.short_pct);
      o.peak_arc_pct = std::max(o.peak_arc_pct, w.arc_pct);
      ok_run = w.short_pct <= 1.0 && w.gained_mm > 0 ? ok_run + 1 : 0;
      if (ok_run == kSettled && o.recovery_s < 0) {
        o.recovery_s = static_cast<double>(i + 1 - kSettled) * 0.1;
      }
    }
    if (o.recovery_s < 0) {  // never settled: the whole time after the drop
      o.recovery_s = static_cast<double>(windows.size()) * 0.1;
    }
    for (std::size_t i = 0; i + kSettled <= windows.size(); i += kSettled) {
      double gained = 0;
      for (std::size_t m = i; m < i + kSettled; ++m) {
        gained += windows[m].gained_mm;
      }
      o.stalls += gained < 0.005 ? 1.0 : 0.0;
    }
  }
  const auto& j = o.jitter_per_cycle_um;
  o.jitter_um = mean_of(j, 0, j.size());
  o.jitter_first_um = mean_of(j, 0, std::min<std::size_t>(3, j.size()));
  o.jitter_last_um = mean_of(j, j.size() >= 3 ? j.size() - 3 : 0, j.size());
  return o;
}

}  // namespace edm::bench
