// edm-ilcdesign — seed 002's controller design procedure (Furlan & Balemi, §5) on the die-sinking
// simulator (issue 20):
//   1) identify the machining process parameters p0 and kδ,
//   2) choose the bandwidth of the low-pass Q → q0,
//   3) the learning gains l1, l2, l3 from eq. 1.
// The plant is config/bench/controllers/sink-ilc.yaml (the ILC's machine: sink preset, 5 ms mean
// gap voltage y, PositionLoop kv 50/s after the ILC's u); the tool forces the PositionLoop's
// reference gap.pz.x_ref_mm, which is what the ILC's u drives, so the responses are the ones the
// block sees (its sampling convention: u output at one 1 ms update, y and z read at the next).
//
// Identification (default seeds 1000 … 1003: a tuning set, disjoint from the benchmark's 1-20):
//   approach  the reference follows the voltage servo's integral law, r' = 0.02·(45 − y) mm/s
//             (−0.5 … 5 mm/s, as sink-sim.yaml), for `--settle-s` seconds of machining;
//   steps     then a square wave r = c(t) ± A/2, half period H (`--half-ms`), about a centre
//             c(t) that advances at the feed rate of the approach's last second (corrected once
//             a period towards mean y = 45 V, so the gap stays at its working point);
//   p0        step response s(i) = (z(k0 + i) − z(k0))/Δr at every edge k0, z(k0) read by the
//             cycle that applies the new reference (before it acts; up and down edges
//             averaged, so the slow advance of c cancels); the impulse response p_i =
//             s(i + 1) − s(i), p0 = s(1) (the first sample after the command, s(0) = 0);
//   kδ        y = kδ·δ + b with δ = z − z_p: per half period the means Y, Z of y and z over its
//             last `--window-ms`; dY_i = Y_i − (Y_i−1 + Y_i+1)/2, dZ_i likewise (the surface
//             z_p recedes about linearly over three halves, so it cancels), kδ = Σ|dY| / Σ|dZ|
//             with signs kept (Σ dY·s_i / Σ dZ·s_i, s_i = ±1 the half's side).
// (The estimators are in ilc_identify.hpp, tested on synthetic records in
// tests/controllers/ilc_identify_test.cpp.)
// Gains: eq. 1 with the identified p0, kδ and the poles (--q-pole, --lambda1..3).
// --learn: the cold-start learning of sink-ilc.yaml (as shipped, or with text edits --edit
// 'FROM=>TO', e.g. other poles) on seeds --seed … (the benchmark's: 1-20), the jump forced as the
// benchmark does (B5): per cycle the RMS of e = 45 V − y over the servo part (from 200 ms after
// the jump's start to the next jump), the mean e over that part, and the z-jitter; means over
// the seeds.
// Exit codes: 0 ok, 1 a run failed, 2 bad arguments.

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <exception>
#include <memory>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "edm/apps/cli.hpp"
#include "edm/apps/offline_runtime.hpp"
#include "edm/apps/text_file.hpp"
#include "edm/blocks/iterative_learning_control.hpp"
#include "edm/runtime/clock.hpp"
#include "edm/runtime/config.hpp"
#include "edm/runtime/runtime.hpp"
#include "edm/runtime/scheduler.hpp"
#include "ilc_identify.hpp"

namespace {

using namespace std::chrono_literals;
namespace rt = edm::rt;
using edm::blocks::IterativeLearningControl;
using edm::blocks::IterativeLearningControlParams;

constexpr const char* kUsage =
    "edm-ilcdesign [--seed S] [--seeds N] [--amplitude-um A]... [--half-ms H] [--window-ms W]\n"
    "                     [--settle-s T] [--periods P] [--q-pole a] [--lambda1 l] [--lambda2 l]\n"
    "                     [--lambda3 l] [--learn [--edit F=>T]...\n"
    "                     [--cycles C]]";

constexpr double kYRef = 45.0;            // V, the ILC's y_ref and the voltage servo's reference
constexpr double kServoGain = 0.02;       // mm/s/V, sink-sim.yaml's voltage servo
constexpr double kServoMin = -0.5;        // mm/s
constexpr double kServoMax = 5.0;         // mm/s
constexpr std::size_t kResponseLen = 40;  // samples of the step response kept

// One simulated machine from a config text, stepped in 1 ms slices.
class Machine {
 public:
  Machine(std::string text, const std::string& name, std::int64_t seed) {
    replace_once(text, "seed: 1}", "seed: " + std::to_string(seed) + "}", name);
    r_ = edm::apps::build_offline(rt::parse_config_text(text, name));
    for (const auto& t : r_->tasks()) {
      t->detach_trace();
      tasks_.push_back(t.get());
    }
    r_->machine().command(rt::MachineCommand::kPowerOn);
    sched_ = std::make_unique<rt::VirtualScheduler>(tasks_, clock_);
  }
  static void replace_once(std::string& text, const std::string& from, const std::string& to,
                           const std::string& name) {
    const auto at = text.find(from);
    if (at == std::string::npos) {
      throw std::runtime_error(name + ": no '" + from + "' to replace");
    }
    text.replace(at, from.size(), to);
  }
  rt::PinRef pin(const std::string& name) {
    const rt::Variable* v = r_->variables().find(name);
    if (v == nullptr || !v->is_pin()) {
      throw std::runtime_error("no pin '" + name + "'");
    }
    return v->pin;
  }
  void force(const std::string& name, double value) {
    if (const rt::VarStatus st = r_->variables().force(name, value); !st) {
      throw std::runtime_error("cannot force '" + name + "': " + st.message);
    }
  }
  void unforce(const std::string& name) { (void)r_->variables().unforce(name); }
  void step() {
    ++k_;
    sched_->run_until(rt::TimePoint{1ms * k_});
    if (rt::is_safe_state(r_->machine().state())) {
      throw std::runtime_error("the machine left RUN at " + std::to_string(k_) + " ms");
    }
  }
  [[nodiscard]] std::int64_t ms() const { return k_; }

 private:
  std::unique_ptr<rt::Runtime> r_;
  std::vector<rt::Task*> tasks_;
  rt::VirtualClock clock_;
  std::unique_ptr<rt::VirtualScheduler> sched_;
  std::int64_t k_{0};
};

struct IdentOptions {
  double amplitude_mm{0.004};
  std::int64_t half_ms{200};
  std::int64_t window_ms{100};
  std::int64_t settle_ms{4000};
  std::int64_t periods{40};
};

struct IdentResult {
  std::vector<double> s;  // mean step response s(0 … kResponseLen−1)
  double sum_dy{0.0}, sum_dz{0.0};
  double y_mean{0.0};  // mean y over the step windows
  std::int64_t edges{0}, halves{0};
};

IdentResult identify(const std::string& text, const std::string& name, std::int64_t seed,
                     const IdentOptions& o) {
  Machine m(text, name, seed);
  const rt::PinRef y = m.pin("gap.uav.out"), z = m.pin("io.z_mm");
  const std::string ref = "gap.pz.x_ref_mm";
  // Approach and machining under the integral law.
  double r = rt::read_pin_as_double(z);
  std::vector<double> r_hist;
  for (std::int64_t k = 0; k < o.settle_ms; ++k) {
    m.force(ref, r);
    m.step();
    const double v =
        std::clamp(kServoGain * (kYRef - rt::read_pin_as_double(y)), kServoMin, kServoMax);
    r += v * 1e-3;
    r_hist.push_back(r);
  }
  // Feed rate of the last second [mm/ms].
  double feed = (r_hist.back() - r_hist[r_hist.size() - 1001]) / 1000.0;
  double c = r;
  std::vector<double> zs, ys;  // the square-wave record (ilc_identify.hpp's convention)
  const std::int64_t halves = 2 * o.periods;
  double period_y = 0, period_n = 0;
  for (std::int64_t h = 0; h < halves; ++h) {
    const double side = h % 2 == 0 ? 1.0 : -1.0;
    for (std::int64_t i = 0; i < o.half_ms; ++i) {
      c += feed;
      m.force(ref, c + side * 0.5 * o.amplitude_mm);
      m.step();
      zs.push_back(rt::read_pin_as_double(z));
      ys.push_back(rt::read_pin_as_double(y));
      period_y += ys.back(), period_n += 1;
    }
    if (h % 2 == 1) {  // once a period: steer the mean y back to y_ref (≈ 0.5 µm/s per V)
      feed -= 0.5e-6 * (period_y / period_n - kYRef);
      period_y = period_n = 0;
    }
  }
  IdentResult out;
  const auto half = static_cast<std::size_t>(o.half_ms);
  out.s = edm::ilcdesign::step_response(zs, half, o.amplitude_mm, kResponseLen);
  const auto k = edm::ilcdesign::k_delta_sums(zs, ys, half, static_cast<std::size_t>(o.window_ms));
  out.sum_dy = k.dy;
  out.sum_dz = k.dz;
  out.halves = static_cast<std::int64_t>(k.halves);
  out.edges = halves - 1;
  double ysum_all = 0;
  for (double v : ys) {
    ysum_all += v;
  }
  const double yn_all = static_cast<double>(ys.size());
  out.y_mean = ysum_all / yn_all;
  return out;
}

// Cold-start learning with the benchmark's forced jump (B5): per cycle RMS and mean of e over the
// servo part, and z-jitter (RMS about a line) over it.
struct CycleFigures {
  std::vector<double> e_rms, e_mean, jitter_um;
  double mrr_mm3_min{0.0};
};

CycleFigures learn(const std::string& text, const std::string& name, std::int64_t seed,
                   std::int64_t cycles) {
  Machine m(text, name, seed);
  const rt::PinRef y = m.pin("gap.uav.out"), z = m.pin("io.z_mm"), depth = m.pin("io.depth_mm");
  constexpr std::int64_t kPeriod = 1500, kUp = 40, kDown = 50, kSettle = 200;
  CycleFigures f;
  double ss = 0, se = 0, n = 0;
  double st = 0, sz = 0, stt = 0, stz = 0, szz = 0;
  auto close_cycle = [&] {
    f.e_rms.push_back(n > 0 ? std::sqrt(ss / n) : 0.0);
    f.e_mean.push_back(n > 0 ? se / n : 0.0);
    double jit = 0.0;
    if (n > 2) {
      const double vt = stt - st * st / n, vz = szz - sz * sz / n, ctz = stz - st * sz / n;
      jit = std::sqrt(std::max(0.0, (vz - (vt > 0 ? ctz * ctz / vt : 0.0)) / n)) * 1000.0;
    }
    f.jitter_um.push_back(jit);
    ss = se = n = st = sz = stt = stz = szz = 0;
  };
  const std::int64_t end = cycles * kPeriod;
  for (std::int64_t k = 1; k <= end; ++k) {
    if (k > kPeriod) {
      const std::int64_t phase = (k - 1) % kPeriod;
      if (phase == 0) {
        close_cycle();
        m.force("io.vz_cmd", 30.0);
        m.force("gap.ilc.cycle_start", 1.0);
        m.force("gap.ilc.y", kYRef);
      } else if (phase == 1) {
        m.force("gap.ilc.cycle_start", 0.0);
      } else if (phase == kUp) {
        m.force("io.vz_cmd", -30.0);
      } else if (phase == kUp + kDown) {
        m.unforce("io.vz_cmd");
        m.unforce("gap.ilc.y");
      }
    }
    m.step();
    const bool servo_part = k <= kPeriod || (k - 1) % kPeriod >= kUp + kDown + kSettle;
    if (servo_part) {
      const double e = kYRef - rt::read_pin_as_double(y);
      const double t = static_cast<double>(k) * 1e-3, zz = rt::read_pin_as_double(z);
      ss += e * e, se += e, n += 1;
      st += t, sz += zz, stt += t * t, stz += t * zz, szz += zz * zz;
    }
  }
  close_cycle();
  f.mrr_mm3_min = rt::read_pin_as_double(depth) * 100.0 / (static_cast<double>(end) / 60000.0);
  return f;
}

}  // namespace

int main(int argc, char** argv) {
  std::int64_t seed = 1000;
  std::int64_t seeds = 4;
  std::vector<double> amplitudes_um;
  IdentOptions io;
  double settle_s = 4.0;
  IterativeLearningControlParams gp;  // the poles: as shipped in sink-ilc.yaml
  gp.q_pole = 0.9;
  gp.lambda1 = 0.5;
  gp.lambda2 = 0.5;
  gp.lambda3 = 0.0999;
  bool do_learn = false;
  std::vector<std::string> edits;
  std::int64_t cycles = 30;
  std::string config = std::string(EDM_SOURCE_DIR) + "/config/bench/controllers/sink-ilc.yaml";
  CLI::App app(
      "edm-ilcdesign: seed 002's design procedure (identify p0 and k_delta on the sink "
      "simulator, eq. 1 gains), or the cold-start learning per cycle (--learn)",
      "edm-ilcdesign");
  app.add_option("--seed", seed, "first simulator seed (identification: tuning set >= 1000)")
      ->check(CLI::Range(std::int64_t{0}, INT64_MAX))
      ->capture_default_str();
  app.add_option("--seeds", seeds, "seeds S … S + N − 1")
      ->check(CLI::Range(std::int64_t{1}, std::int64_t{1000}))
      ->capture_default_str();
  app.add_option("--amplitude-um", amplitudes_um,
                 "peak-to-peak step of the reference (repeatable; default 2, 4, 8)")
      ->check(edm::apps::kPositive);
  app.add_option("--half-ms", io.half_ms, "half period of the square wave")
      ->check(CLI::Range(std::int64_t{50}, std::int64_t{10000}))
      ->capture_default_str();
  app.add_option("--window-ms", io.window_ms, "end of each half averaged for kδ")
      ->check(CLI::Range(std::int64_t{1}, std::int64_t{10000}))
      ->capture_default_str();
  app.add_option("--settle-s", settle_s, "seconds of machining under the integral law first")
      ->check(edm::apps::kPositive)
      ->capture_default_str();
  app.add_option("--periods", io.periods, "square-wave periods per seed")
      ->check(CLI::Range(std::int64_t{3}, std::int64_t{100000}))
      ->capture_default_str();
  app.add_option("--q-pole", gp.q_pole, "pole a of Q (q0 = 1 − a)")->capture_default_str();
  app.add_option("--lambda1", gp.lambda1, "forward-motion pole 1")->capture_default_str();
  app.add_option("--lambda2", gp.lambda2, "forward-motion pole 2")->capture_default_str();
  app.add_option("--lambda3", gp.lambda3, "within-cycle pole")->capture_default_str();
  app.add_flag("--learn", do_learn, "measure the cold-start learning per cycle instead");
  app.add_option("--edit", edits,
                 "--learn: a text edit of the config, 'FROM=>TO' (repeatable; FROM must occur)");
  app.add_option("--cycles", cycles, "--learn: jump cycles per run")
      ->check(CLI::Range(std::int64_t{2}, std::int64_t{10000}))
      ->capture_default_str();
  app.add_option("--config", config, "the ILC machine config")->capture_default_str();
  if (const auto code = edm::apps::parse(app, argc, argv, kUsage)) return *code;
  io.settle_ms = static_cast<std::int64_t>(std::llround(settle_s * 1000.0));

  try {
    std::string text = edm::apps::read_text_file(config);
    if (do_learn) {
      for (const std::string& e : edits) {
        const auto at = e.find("=>");
        if (at == std::string::npos) {
          std::fprintf(stderr, "edm-ilcdesign: --edit '%s' is not FROM=>TO\nusage: %s\n", e.c_str(),
                       kUsage);
          return edm::apps::kExitBadInput;
        }
        Machine::replace_once(text, e.substr(0, at), e.substr(at + 2), config);
      }
      std::vector<double> rms(static_cast<std::size_t>(cycles), 0.0), mean = rms, jit = rms;
      double mrr = 0;
      for (std::int64_t s = seed; s < seed + seeds; ++s) {
        const CycleFigures f = learn(text, config, s, cycles);
        for (std::size_t c = 0; c < rms.size() && c < f.e_rms.size(); ++c) {
          rms[c] += f.e_rms[c] / static_cast<double>(seeds);
          mean[c] += f.e_mean[c] / static_cast<double>(seeds);
          jit[c] += f.jitter_um[c] / static_cast<double>(seeds);
        }
        mrr += f.mrr_mm3_min / static_cast<double>(seeds);
      }
      std::printf("cold-start learning, %s, seeds %lld … %lld, %lld cycles\n", config.c_str(),
                  static_cast<long long>(seed), static_cast<long long>(seed + seeds - 1),
                  static_cast<long long>(cycles));
      for (const std::string& e : edits) {
        std::printf("edit: %s\n", e.c_str());
      }
      double late = 0;
      for (std::size_t c = rms.size() / 3; c < rms.size(); ++c) {
        late += rms[c] / static_cast<double>(rms.size() - rms.size() / 3);
      }
      std::printf("MRR %.1f mm3/min; RMS e over cycles %zu-%zu %.2f V (means over the seeds)\n\n",
                  mrr, rms.size() / 3, rms.size() - 1, late);
      std::printf("| cycle | RMS e V | mean e V | z-jitter um |\n|---|---|---|---|\n");
      for (std::size_t c = 0; c < rms.size(); ++c) {
        std::printf("| %zu | %.2f | %.2f | %.2f |\n", c, rms[c], mean[c], jit[c]);
      }
      return edm::apps::kExitOk;
    }
    if (amplitudes_um.empty()) {
      amplitudes_um = {2.0, 4.0, 8.0};
    }
    std::printf(
        "identification on %s, seeds %lld … %lld: %lld s under the integral law, then %lld "
        "square-wave periods of 2 × %lld ms, kδ from the last %lld ms of each half\n\n",
        config.c_str(), static_cast<long long>(seed), static_cast<long long>(seed + seeds - 1),
        static_cast<long long>(io.settle_ms / 1000), static_cast<long long>(io.periods),
        static_cast<long long>(io.half_ms), static_cast<long long>(io.window_ms));
    double p0_all = 0, kd_ref = 0;
    std::vector<double> s_ref;
    std::printf(
        "| step A um | p0 = s(1) | s(2) | s(5) | s(20) | kδ V/mm | kδ per seed | mean y V |\n");
    std::printf("|---|---|---|---|---|---|---|---|\n");
    for (const double a_um : amplitudes_um) {
      io.amplitude_mm = a_um * 1e-3;
      std::vector<double> s(kResponseLen, 0.0);
      double dy = 0, dz = 0, ym = 0;
      std::string per_seed;
      for (std::int64_t sd = seed; sd < seed + seeds; ++sd) {
        const IdentResult r = identify(text, config, sd, io);
        for (std::size_t i = 0; i < s.size(); ++i) {
          s[i] += r.s[i] / static_cast<double>(seeds);
        }
        dy += r.sum_dy, dz += r.sum_dz, ym += r.y_mean / static_cast<double>(seeds);
        char buf[32];
        std::snprintf(buf, sizeof buf, "%s%.0f", per_seed.empty() ? "" : ", ", r.sum_dy / r.sum_dz);
        per_seed += buf;
      }
      const double kd = dy / dz;
      std::printf("| %.1f | %.4f | %.4f | %.4f | %.4f | %.0f | %s | %.1f |\n", a_um, s[1], s[2],
                  s[5], s[20], kd, per_seed.c_str(), ym);
      if (s_ref.empty() || std::fabs(a_um - 4.0) < 1e-9) {
        s_ref = s;
        kd_ref = kd;
      }
      p0_all += s[1] / static_cast<double>(amplitudes_um.size());
    }
    std::printf("\nstep response s(i) (mean over seeds, the 4 um step or the first):");
    for (std::size_t i = 0; i < 12; ++i) {
      std::printf(" %.4f", s_ref[i]);
    }
    std::printf("\nimpulse response p_i = s(i+1) − s(i):");
    for (std::size_t i = 0; i + 1 < 12; ++i) {
      std::printf(" %.4f", s_ref[i + 1] - s_ref[i]);
    }
    std::printf("\n\n");
    IterativeLearningControlParams id = gp;
    id.p0 = p0_all;
    id.k_delta = kd_ref;
    IterativeLearningControlParams id_warm = id;  // sink-ilc-warm.yaml, sink-ilc-sim.yaml
    id_warm.lambda3 = 0.0997;
    IterativeLearningControlParams id_old = id;  // the poles shipped before issue 20
    id_old.lambda1 = 0.7;
    id_old.lambda2 = 0.7;
    id_old.lambda3 = 0.09;
    IterativeLearningControlParams before = id_old;  // and its trial p0, kδ
    before.p0 = 0.05;
    before.k_delta = 3000.0;
    std::printf("eq. 1, q0 = 1 − q_pole; kδ·l1·p0 = 1 − λ3/q0 is the first sample's correction:\n");
    std::printf("| | p0 | kδ V/mm | q0 | λ1 | λ2 | λ3 | l1 mm/V | l2 mm/V | l3 mm/V | kδ·l1 |\n");
    std::printf("|---|---|---|---|---|---|---|---|---|---|---|\n");
    const std::pair<const char*, IterativeLearningControlParams> rows[] = {
        {"identified, these poles", id},
        {"identified, λ3 of the warm start", id_warm},
        {"identified, poles before issue 20", id_old},
        {"before issue 20 (trial)", before}};
    for (const auto& [label, p] : rows) {
      const auto g = IterativeLearningControl::gains(p);
      std::printf("| %s | %.4f | %.0f | %.3g | %.3g | %.3g | %.4g | %.4g | %.4g | %.4g | %.3g |\n",
                  label, p.p0, p.k_delta, 1.0 - p.q_pole, p.lambda1, p.lambda2, p.lambda3, g.l1,
                  g.l2, g.l3, p.k_delta * g.l1);
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "edm-ilcdesign: %s\n", e.what());
    return edm::apps::kExitFailure;
  }
  return edm::apps::kExitOk;
}
