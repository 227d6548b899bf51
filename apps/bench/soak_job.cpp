#include "soak_job.hpp"

#include <fmt/core.h>

#include <cmath>
#include <cstdlib>
#include <sstream>

namespace edm::bench::soak {

namespace {

/// Replaces the one occurrence of `from`; false if it is not there exactly once.
bool replace_once(std::string& text, const std::string& from, const std::string& to) {
  const auto at = text.find(from);
  if (at == std::string::npos || text.find(from, at + 1) != std::string::npos) {
    return false;
  }
  text.replace(at, from.size(), to);
  return true;
}

/// The value of a report row ("  label   value"), or empty.
std::string row(const std::string& report, const std::string& label) {
  std::istringstream in(report);
  for (std::string line; std::getline(in, line);) {
    if (line.starts_with("  " + label + " ")) {
      const auto v = line.find_first_not_of(' ', label.size() + 2);
      return v == std::string::npos ? std::string() : line.substr(v);
    }
  }
  return {};
}

std::optional<double> number_after(const std::string& text, const std::string& key) {
  const auto at = text.find(key);
  if (at == std::string::npos) {
    return std::nullopt;
  }
  const char* begin = text.c_str() + at + key.size();
  char* end = nullptr;
  const double v = std::strtod(begin, &end);
  return end == begin ? std::nullopt : std::optional<double>(v);
}

}  // namespace

std::string soak_config(const std::string& shipped_yaml, std::string& error) {
  std::string y = shipped_yaml;
  if (!replace_once(y, "{name: Z, min_mm: -60,", "{name: Z, min_mm: -1000,") ||
      !replace_once(
          y, "wall_sparks: true}",
          fmt::format("wall_sparks: true, electrode_length_mm: {:.0f}}}", kSoakElectrodeMm)) ||
      !replace_once(y, "electrode: {length_mm: 300}",
                    fmt::format("electrode: {{length_mm: {:.0f}}}", kSoakElectrodeMm))) {
    error =
        "drill-sim.yaml changed: the Z axis, the io params line or machine.electrode is not "
        "where it was";
    return {};
  }
  return "# edm-bench-soak: config/machines/drill-sim.yaml with Z min -1000 mm (not -60) and a "
         "1200 mm electrode (not 300),\n# so one edmplc drills hole after hole.\n" +
         y;
}

std::string job_program(const std::string& demo_nc, int k, double worn_mm, std::string& error) {
  std::string p = demo_nc;
  const bool ok = replace_once(p, "G00 X5 Y5 ",
                               fmt::format("G00 X{} Y{} ", 5 + 3 * (k % 30), 5 + 3 * (k / 30))) &&
                  replace_once(p, "G00 Z-11.8 ", fmt::format("G00 Z{:.3f} ", -11.8 - worn_mm));
  if (!ok) {
    error = "examples/parts/demo.nc changed: 'G00 X5 Y5' or 'G00 Z-11.8' is not there once";
    return {};
  }
  return p;
}

bool JobFigures::at_depth() const {
  return outcome == "finished" && reached_mm && program_mm && measured_mm &&
         std::abs(*reached_mm - *program_mm) <= kDepthToleranceMm &&
         *measured_mm >= *program_mm - kMeasuredShortMm;
}

JobFigures parse_report(const std::string& report) {
  JobFigures f;
  if (report.find("job report:") == std::string::npos) {
    return f;
  }
  f.outcome = row(report, "outcome");
  const std::string depth = row(report, "depth reached");
  f.reached_mm = number_after(depth, "");
  f.program_mm = number_after(depth, "(program ");
  f.measured_mm = number_after(row(report, "hole depth (measured)"), "");
  f.machining_s = number_after(row(report, "machining time"), "(");
  f.electrode_left_mm = number_after(row(report, "electrode left"), "");
  f.alarms = row(report, "alarms");
  return f;
}

}  // namespace edm::bench::soak
