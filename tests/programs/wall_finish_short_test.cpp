// WallFinish and short circuits (issue 19): while the Td window reads short the orbit's phase and
// radius wait (no advance toward the wall), the retract backs the electrode along the contour it
// has travelled and walks it forward again, then the orbit goes on; too many retracts without
// progress are a fault (alarm 150 with a machine).

#include <gtest/gtest.h>

#include <cmath>

#include "edm/programs/wall_finish.hpp"
#include "finish_rig.hpp"
#include "support/param_access.hpp"

namespace edm::test {
namespace {

using namespace std::chrono_literals;
using programs::WallFinish;

// The electrode at (0, 0) follows its commands; sparks at Td 10 µs while the generator is on,
// all shorts while `shorting`, or, with a contact (a chip on the wall met at the electrode's
// position), while the electrode is within kContactUm of it until it has once backed off by
// twice that (transient), or for good (persistent).
constexpr double kContactMm = 0.03;

struct OrbitRig : FinishInputsRig {
  bool shorting{false};
  bool contact{false}, persistent{false}, cleared{false};
  double cx{0.0}, cy{0.0};
  std::int64_t short_cycles{0};

  OrbitRig() : FinishInputsRig(WallFinishParams()) {
    configure_and_activate();
    short_cycles = block.read_param(param_index(block, "retract.short_cycles")).i;
    start_offset.set(0.2);
    final_offset.set(0.21);
  }
  static programs::WallFinishParams WallFinishParams() {
    programs::WallFinishParams p;
    p.feed_default_mm_min = 79.2;  // 1.3 mm/s along the 0.21 mm final orbit: ≈ 1 s a revolution
    p.spark_out_revs = 2;
    return p;
  }
  double r() const { return std::hypot(x_mm.get(), y_mm.get()); }
  void place_contact() {
    contact = true;
    cx = x_mm.get();
    cy = y_mm.get();
  }
  bool in_contact() {
    if (!contact) return false;
    const double d = std::hypot(x_mm.get() - cx, y_mm.get() - cy);
    if (d >= 2.0 * kContactMm) cleared = true;
    return d < kContactMm && (persistent || !cleared);
  }
  rt::BlockStatus step() {
    if ((shorting || in_contact()) && gen()) {
      sparks(0, 0.0);
      n_short.set(10);
    } else {
      sparks(gen() ? 10 : 0, 10.0);
      n_short.set(0);
    }
    const rt::BlockStatus s = block.update(ctx);
    x_mm.set(x_mm.get() + out<double>("vx_cmd_mm_s") * ctx.dt_s);
    y_mm.set(y_mm.get() + out<double>("vy_cmd_mm_s") * ctx.dt_s);
    ++ctx.cycle;
    ctx.release += 1ms;
    return s;
  }
};

TEST(WallFinishShort, AShortStopsTheOrbitRetractsAlongTheContourThenTheOrbitGoesOn) {
  OrbitRig rig;
  rig.start.set(true);
  for (int k = 0; k < 20000 && rig.out<std::int64_t>("revolutions") < 2; ++k) rig.step();
  ASSERT_EQ(rig.state(), 2) << "orbiting";
  rig.place_contact();
  std::int64_t run = 0, detected = -1, retract_at = -1;
  double rho0 = -1.0;  // the reference radius when the window first reads short
  double rho_max = 0.0;
  for (std::int64_t k = 0; k < 150; ++k) {
    rig.step();
    const bool reads_short = rig.out<bool>("short_now");  // the window or the cycle
    if (reads_short) {
      if (rho0 < 0.0) rho0 = rig.out<double>("rho_mm");
      rho_max = std::max(rho_max, rig.out<double>("rho_mm"));
      if (++run == rig.short_cycles && detected < 0) detected = k;
    } else {
      run = 0;
    }
    if (retract_at < 0 && rig.out<bool>("retract.active")) retract_at = k;
  }
  ASSERT_GE(detected, 0);
  ASSERT_GE(retract_at, 0);
  EXPECT_LE(retract_at - detected, 2) << "the retract starts within 2 cycles of the detection";
  EXPECT_LE(rho_max, rho0 + 1e-12) << "no radial advance toward the wall while reading short";
  EXPECT_TRUE(rig.cleared) << "backed off along the contour";
  for (int k = 0; k < 60000 && rig.state() != 4; ++k) {
    ASSERT_NE(rig.step(), rt::BlockStatus::kFault);
  }
  EXPECT_EQ(rig.state(), 4) << "the orbit went on and finished";
  EXPECT_EQ(rig.out<std::int64_t>("short_retracts"), 1);
}

TEST(WallFinishShort, APersistentShortIsAFaultAfterNRetracts) {
  OrbitRig rig;
  rig.start.set(true);
  for (int k = 0; k < 20000 && rig.out<std::int64_t>("revolutions") < 2; ++k) rig.step();
  ASSERT_EQ(rig.state(), 2);
  rig.shorting = true;
  bool faulted = false;
  for (int k = 0; k < 60000 && !faulted; ++k) faulted = rig.step() == rt::BlockStatus::kFault;
  EXPECT_TRUE(faulted);
  EXPECT_EQ(rig.out<std::int64_t>("short_retracts"), rig.block.params().shorts.short_retracts_max);
}

}  // namespace
}  // namespace edm::test
