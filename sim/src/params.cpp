#include "edm/sim/params.hpp"

// The simulator's parameter schema (visit, whose parts are params_schema.cpp) and its validation.
// The presets are presets.cpp, the thickness-profile parser thickness_profile.cpp.

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

namespace edm::sim {

namespace rt = edm::rt;

namespace {

// The plant resolves every field once, at construction: none can change at run time.
class LoadTimeOnly final : public rt::ParamVisitor {
 public:
  explicit LoadTimeOnly(rt::ParamVisitor& inner) : inner_(inner) {}

 protected:
  void on_param(std::string_view name, rt::ParamRef ref, rt::ParamSpec spec) override {
    spec.load_time_only = true;
    inner_.forward(name, ref, spec);
  }

 private:
  rt::ParamVisitor& inner_;
};

}  // namespace

void SimParams::visit(rt::ParamVisitor& outer) {
  LoadTimeOnly v(outer);
  visit_generator(v);
  visit_ignition(v);
  visit_shorts(v);
  visit_arcs(v);
  visit_removal(v);
  visit_electrode(v, outer);
  visit_work(v, outer);
  visit_flushing(v);
  visit_axes(v);
  visit_wire(v);
  visit_sensors(v);
}

std::vector<rt::ParamError> SimParams::validate() const {
  SimParams copy = *this;  // visit() takes non-const references
  rt::SpecChecker specs;
  copy.visit(specs);
  if (!specs.errors.empty()) {
    return std::move(specs.errors);
  }
  return cross_field_errors();
}

std::vector<rt::ParamError> SimParams::cross_field_errors() const {
  std::vector<rt::ParamError> e;
  using rt::require_non_negative;
  using rt::require_positive;
  if (wire_break_rab_shape != std::floor(wire_break_rab_shape)) {
    e.push_back({"wire_break_rab_shape",
                 "must be a whole number (got " + std::to_string(wire_break_rab_shape) + ")"});
  }
  if (wire_plane) {
    if (tool_kind != "wire") e.push_back({"wire_plane", "needs tool_kind wire"});
    const double w = wire_plate_x_max_mm - wire_plate_x_min_mm;
    const double hgt = wire_plate_y_max_mm - wire_plate_y_min_mm;
    // The field is a float per cell: at most 64 M cells (256 MB) for one plate.
    if (!(w > 0.0 && hgt > 0.0)) {
      e.push_back({"wire_plate_x_max_mm", "the plate must have a positive extent in X and Y"});
    } else if ((w + 1.0) * (hgt + 1.0) / (wire_grid_um * wire_grid_um * 1e-6) > 64e6) {
      e.push_back({"wire_grid_um",
                   "the plate's field would exceed 64 M cells: a coarser grid "
                   "or a smaller plate"});
    }
    if (wire_void_d_mm > 0.0 && !(wire_void_height_mm < wire_plate_mm)) {
      e.push_back({"wire_void_height_mm", "must be < wire_plate_mm"});
    }
  }
  if (!(work_x_min_mm < work_x_max_mm)) {
    e.push_back({"work_x_max_mm", "must be > work_x_min_mm (got " + std::to_string(work_x_max_mm) +
                                      " <= " + std::to_string(work_x_min_mm) + ")"});
  }
  if (!(work_y_min_mm < work_y_max_mm)) {
    e.push_back({"work_y_max_mm", "must be > work_y_min_mm (got " + std::to_string(work_y_max_mm) +
                                      " <= " + std::to_string(work_y_min_mm) + ")"});
  }
  if (work_bore_d_mm > 0.0) {  // the bore must leave a wall on every side
    const double r = work_bore_d_mm / 2.0;
    if (!(work_bore_x_mm - r > work_x_min_mm && work_bore_x_mm + r < work_x_max_mm &&
          work_bore_y_mm - r > work_y_min_mm && work_bore_y_mm + r < work_y_max_mm)) {
      e.push_back({"work_bore_d_mm", "the bore (centre " + std::to_string(work_bore_x_mm) + ", " +
                                         std::to_string(work_bore_y_mm) + ", diameter " +
                                         std::to_string(work_bore_d_mm) +
                                         ") must lie inside the work block"});
    }
  }
  if (removal_mm3_per_j == 0.0 && crater_ref_um3 == 0.0) {
    e.push_back({"removal_mm3_per_j", "removal_mm3_per_j or crater_ref_um3 must be > 0"});
  }
  if (td_law != "exp" && td_law != "quadratic") {
    e.push_back({"td_law", "must be 'exp' or 'quadratic' (got '" + td_law + "')"});
  }
  if (tool_kind == "tube") {
    require_positive(e, "tool_od_mm", tool_od_mm);
    require_non_negative(e, "tool_id_mm", tool_id_mm);
    rt::require_ordered(e, "tool_id_mm", tool_id_mm, "tool_od_mm", tool_od_mm);
    if (!(hole_d_mm > tool_od_mm)) {
      e.push_back({"hole_d_mm", "must be > tool_od_mm (got " + std::to_string(hole_d_mm) +
                                    " <= " + std::to_string(tool_od_mm) + ")"});
    }
  } else if (tool_kind == "block") {
    require_positive(e, "tool_width_mm", tool_width_mm);
    require_positive(e, "tool_length_mm", tool_length_mm);
    require_positive(e, "side_gap_mm", side_gap_mm);
  } else if (tool_kind == "wire") {
    require_positive(e, "wire_d_mm", wire_d_mm);
    std::string why;
    const auto steps = parse_thickness_profile(wire_thickness_profile, &why);
    if (!steps) {
      e.push_back({"wire_thickness_profile", why});
    }
    rt::require_ordered(e, "wire_hole_from_mm", wire_hole_from_mm, "wire_hole_to_mm",
                        wire_hole_to_mm);
    rt::require_ordered(e, "wire_cavity_from_mm", wire_cavity_from_mm, "wire_cavity_to_mm",
                        wire_cavity_to_mm);
    if (steps && wire_cavity_to_mm > wire_cavity_from_mm && wire_cavity_height_mm > 0.0) {
      // The slabs above and below the cavity must keep some material: h_c < H(s) over it.
      double h_min = std::numeric_limits<double>::infinity();
      for (std::size_t i = 0; i < steps->size(); ++i) {
        const double next = i + 1 < steps->size() ? (*steps)[i + 1].from_mm
                                                  : std::numeric_limits<double>::infinity();
        if ((*steps)[i].from_mm < wire_cavity_to_mm && next > wire_cavity_from_mm) {
          h_min = std::min(h_min, (*steps)[i].thickness_mm);
        }
      }
      if (!(wire_cavity_height_mm < h_min)) {
        e.push_back({"wire_cavity_height_mm", "must be < the part thickness over the cavity (" +
                                                  std::to_string(h_min) + " mm; got " +
                                                  std::to_string(wire_cavity_height_mm) + ")"});
      }
    }
  } else {
    e.push_back({"tool_kind", "must be 'tube', 'block' or 'wire' (got '" + tool_kind + "')"});
  }
  return e;
}

}  // namespace edm::sim
