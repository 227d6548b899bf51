// MDI: one line through the part-program interpreter (mdi.hpp).
#include "edm/hmi/mdi.hpp"

#include <string>

namespace edm::hmi {

GcodeResult interpret_mdi(std::string_view line, const machining::MachineTables& tables,
                          const WorkOffsets& offsets, const machining::Vec3& position_mm) {
  // A trailing line end (as a shell's $(cat) or an editor leaves it) is not a second line.
  while (!line.empty() && (line.back() == '\n' || line.back() == '\r')) line.remove_suffix(1);
  if (const std::size_t nl = line.find_first_of("\r\n"); nl != std::string_view::npos) {
    GcodeResult r;
    r.file = std::string(kMdiName);
    r.errors.push_back({1, static_cast<int>(nl) + 1, "MDI takes one line; this has several"});
    return r;
  }
  GcodeOptions o;
  o.start_mm = position_mm;
  o.offsets = offsets;
  o.implicit_end = true;
  GcodeResult r = interpret_gcode(line, kMdiName, tables, o);
  if (r.ok() && r.blocks.size() == 1) {  // the appended end alone: nothing was asked
    r.blocks.clear();
    r.frames.clear();
    r.errors.push_back({1, 1, "nothing to do: the line has no words"});
  }
  return r;
}

}  // namespace edm::hmi
