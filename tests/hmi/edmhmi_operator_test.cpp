// edmhmi's operator commands against a real edmplc on the simulator (issue 21): the work is where
// the program does not know it (the simulator's work_surface_z_mm / work_origin_*), the axes are
// not referenced at power-on and programs need the reference. home, mdi, touch --set, offset, run
// in work coordinates with the report's two coordinate systems, --dry-run, --from; and the
// dead man: a continuous jog whose edmhmi is killed stops the axis.
#include <gtest/gtest.h>

#include <cmath>
#include <optional>
#include <string>
#include <vector>

#include "process_fixture.hpp"
#include "support/files.hpp"

namespace edm::hmi::test {
namespace {

constexpr double kSurfaceZ = -7.25;  // machine Z of the work's top (unknown to the program)
constexpr double kDatumX = 12.5;     // the work block spans datum ± 50 mm in X and Y
constexpr double kDatumY = -8.0;

class EdmhmiOperatorTest : public EdmhmiProcessTest {
 protected:
  /// drill-sim.yaml with the work moved and incremental encoders that need homing.
  std::string operator_config() {
    std::string text = edm::test::read_file(kDrillSim);
    const auto replace = [&text](const std::string& from, const std::string& to) {
      const auto at = text.find(from);
      EXPECT_NE(at, std::string::npos) << from;
      if (at != std::string::npos) text.replace(at, from.size(), to);
    };
    replace("params: {preset: drill, seed: 1, wall_sparks: true}",
            "params: {preset: drill, seed: 1, wall_sparks: true, work_surface_z_mm: " +
                std::to_string(kSurfaceZ) + ", work_origin_x_mm: " + std::to_string(kDatumX) +
                ", work_origin_y_mm: " + std::to_string(kDatumY) + "}");
    replace("manual: {}", "manual: {referenced_at_start: false, reference_required: true}");
    const std::string path = dir_.file("operator.yaml");
    edm::test::write_file(path, text);
    return path;
  }

  /// start_plc() at another pace: `speed`× wall time (the dead man needs real time).
  void start_plc_at_speed(const std::string& config, const std::string& speed) {
    port_ = free_port();
    plc_ = std::make_unique<Proc>(
        std::vector<std::string>{EDM_EDMPLC_PATH, "--config", config, "--clock", "virtual",
                                 "--speed", speed, "--bridge-port", std::to_string(port_)},
        dir_.file("edmplc.out"), dir_.file("edmplc.err"));
    ASSERT_TRUE(poll_until([&] { return edmhmi({"status"}).code == 0; }, 20s, 50ms))
        << plc_->out() << plc_->err();
  }

  std::string part(const std::string& name, const std::string& text) {
    const std::string path = dir_.file(name);
    edm::test::write_file(path, text);
    return path;
  }
};

TEST_F(EdmhmiOperatorTest, HomeTouchOffSetG54AndDrillInWorkCoordinates) {
  start_plc(operator_config());
  // G54 X0 is the block's left edge (touched), Y0 the datum's Y (typed), Z0 its top (touched).
  const std::string hole = part("hole.nc",
                                "G54\nG00 Z2\nG00 X50 Y0\nG00 Z0.5\nM03 M08\nE1\nG01 Z-2 F60\n"
                                "E0\nG00 Z2\nM05 M09\nM30\n");

  // Programs need the reference first.
  const Outcome early = edmhmi({"run", "--quiet", hole});
  EXPECT_EQ(early.code, 1) << early.err;
  EXPECT_NE(early.err.find("not referenced"), std::string::npos) << early.err;

  const Outcome home = edmhmi({"home"});
  ASSERT_EQ(home.code, 0) << home.out << home.err;
  EXPECT_NE(home.out.find("home ok"), std::string::npos) << home.out;

  // Over the datum, above the surface (all frames are zero: MDI in machine coordinates).
  const Outcome over = edmhmi({"mdi", "G00 X12.5 Y-8 Z-3"});
  ASSERT_EQ(over.code, 0) << over.out << over.err;
  EXPECT_NE(over.out.find("mdi: finished"), std::string::npos) << over.out;

  const Outcome tz = edmhmi({"touch", "z", "--set", "G54"}, {}, true, 60s);
  ASSERT_EQ(tz.code, 0) << tz.out << tz.err;
  const auto z0 = number_after(tz.out, " Z");
  ASSERT_TRUE(z0.has_value()) << tz.out;
  EXPECT_NEAR(*z0, kSurfaceZ, 0.02) << tz.out;
  EXPECT_NE(tz.out.find("offset.set: G54"), std::string::npos) << tz.out;

  // Beside the block's left face (datum X − 50), below the surface, then touch +X.
  ASSERT_EQ(edmhmi({"mdi", "G00 X-42 Y-8"}).code, 0);
  ASSERT_EQ(edmhmi({"mdi", "G00 Z-1"}).code, 0);  // G54 Z now: 1 mm below the surface
  const Outcome tx = edmhmi({"touch", "x+", "--set", "G54"}, {}, true, 60s);
  ASSERT_EQ(tx.code, 0) << tx.out << tx.err;
  const auto x0 = number_after(tx.out, "touch x+ ok X");
  ASSERT_TRUE(x0.has_value()) << tx.out;
  EXPECT_NEAR(*x0, kDatumX - 50.0, 0.02) << tx.out;
  ASSERT_EQ(edmhmi({"mdi", "G00 Z2"}).code, 0);
  const Outcome setY = edmhmi({"offset", "G54", "Y" + std::to_string(kDatumY)});
  ASSERT_EQ(setY.code, 0) << setY.err;
  const Outcome frames = edmhmi({"offset", "G54"});
  EXPECT_EQ(frames.code, 0);
  EXPECT_EQ(frames.out.rfind("G54  X", 0), 0u) << frames.out;

  const Outcome run = edmhmi({"run", "--quiet", hole}, {}, true, 120s);
  ASSERT_EQ(run.code, 0) << run.out << run.err;
  EXPECT_NE(row_value(run.out, "work frame").rfind("G54, origin at X", 0), std::string::npos)
      << run.out;
  const std::string h = row_value(run.out, "hole (line 7)");
  EXPECT_EQ(h.rfind("X 50.0000 Y 0.0000 G54 = X ", 0), 0u) << run.out;
  EXPECT_NE(h.find("2.0000 mm deep"), std::string::npos) << run.out;
  // The machine X of the hole is the touched edge + 50: the datum's X.
  const auto hx = number_after(h, "G54 = X");
  ASSERT_TRUE(hx.has_value()) << h;
  EXPECT_NEAR(*hx, kDatumX, 0.02);
  const std::string end = row_value(run.out, "end position");
  const auto ex = number_after(end, "X"), ez = number_after(end, "Z");
  ASSERT_TRUE(ex && ez) << run.out;
  EXPECT_NEAR(*ex, 50.0, 0.01) << end;  // work coordinates first
  EXPECT_NEAR(*ez, 2.0, 0.01) << end;
  // The hole's depth from the real surface (the simulator's truth) is the program's.
  const auto measured = number_after(run.out, "hole depth (measured)");
  ASSERT_TRUE(measured.has_value()) << run.out;
  EXPECT_NEAR(*measured, 2.0, 0.05) << run.out;

  // A dry run of the same program at another place: no sparks.
  const std::string dry = part("dry.nc",
                               "G54\nG00 Z2\nG00 X60 Y0\nG00 Z0.5\nE1\nG01 Z-2 F60\n"
                               "E0\nG00 Z2\nM30\n");
  const Outcome d = edmhmi({"run", "--dry-run", dry}, {}, true, 120s);
  ASSERT_EQ(d.code, 0) << d.out << d.err;
  EXPECT_NE(d.err.find("dry run"), std::string::npos) << d.err;
  EXPECT_EQ(row_value(d.out, "pulses"), "0") << d.out;

  // Resume a two-hole program at the second hole's drilling line: the prologue and a depth of 0
  // (the last job finished: no record).
  const std::string two = part("two.nc",
                               "G54\nG00 Z2\nG00 X70 Y0\nM03 M08\nG00 Z0.5\nE1\nG01 Z-1 F60\n"
                               "G00 Z2\nG00 X75\nG00 Z0.5\nG01 Z-1\nE0\nG00 Z2\nM05 M09\nM30\n");
  const Outcome r = edmhmi({"run", "--from", "11", two}, {}, true, 120s);
  ASSERT_EQ(r.code, 0) << "OUT\n" << r.out << "ERR\n" << r.err;
  EXPECT_NE(r.err.find("line 11 drills on from 0.0000 mm deep"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("resuming at line 11"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("then rotation on, flushing on, E1"), std::string::npos) << r.err;
  EXPECT_EQ(row_value(r.out, "hole (line 7)"), "") << r.out;  // the first hole is not redone
  EXPECT_NE(row_value(r.out, "hole (line 11)").find("X 75.0000 Y 0.0000 G54"), std::string::npos)
      << r.out;
  // A line that cannot be resumed: exit 2, nothing sent.
  const Outcome past = edmhmi({"run", "--from", "99", two});
  EXPECT_EQ(past.code, 2);
  EXPECT_NE(past.err.find("past the program's last block"), std::string::npos) << past.err;
}

TEST_F(EdmhmiOperatorTest, BadOperatorInputExitsTwoWithoutAMachine) {
  // Checked before connecting: nobody listens on the port (a connection attempt would exit 1).
  port_ = free_port();
  for (const std::vector<std::string>& args : {std::vector<std::string>{"jog", "X", "20"},
                                               {"jog", "A", "1"},
                                               {"jog", "X"},
                                               {"jog", "X", "1", "--velocity", "2"},
                                               {"home", "XQ"},
                                               {"touch", "x"},
                                               {"touch", "z", "--set", "G53"},
                                               {"offset", "G59.1"},
                                               {"offset", "X1"},
                                               {"offset", "G54", "Z"}}) {
    const Outcome o = edmhmi(args);
    EXPECT_EQ(o.code, 2) << args[0] << " " << args[1] << ": " << o.err;
  }
}

TEST_F(EdmhmiOperatorTest, AJogWhoseEdmhmiIsKilledStopsWithinTheDeadman) {
  // Real-time pace: the runtime's 500 ms dead man in wall time (the shipped machine: referenced
  // at power-on, the work at machine zero).
  start_plc_at_speed(kDrillSim, "1");
  ASSERT_EQ(edmhmi({"mdi", "G00 Z5"}).code, 0);
  Proc& jog = spawn({"jog", "X", "--velocity", "4"});
  // Jogging: the axis moves.
  std::optional<double> x_before;
  ASSERT_TRUE(poll_until(
      [&] {
        const Outcome s = edmhmi({"status"});
        x_before = number_after(s.out, "io.x_mm");
        return x_before && *x_before > 0.5;
      },
      10s, 50ms));
  jog.kill();  // SIGKILL: no jog.stop is sent
  const auto killed = Clock::now();
  // Within the dead man (500 ms) and the deceleration (4 mm/s at 200 mm/s²: 20 ms) the axis
  // stands; allow the status polls' own latency.
  std::optional<double> last, now;
  ASSERT_TRUE(poll_until(
      [&] {
        last = now;
        now = number_after(edmhmi({"status"}).out, "io.x_mm");
        return last && now && std::abs(*now - *last) < 1e-4;
      },
      5s, 100ms));
  EXPECT_LT(Clock::now() - killed, 2s);
  // The axis went at most 4 mm/s × (0.5 s + the stop) past the kill.
  EXPECT_LT(*now - *x_before, 4.0 * 1.2 + 0.5);
}

}  // namespace
}  // namespace edm::hmi::test
