// Builds a Runtime from a parsed Config: driver, blocks, parameters, wires, tasks, variables and
// trace channels; the safety supervisor (supervisor_builder.cpp) and the retain store
// (retain_builder.cpp) have files of their own. Every problem is reported as file:line:col.

#include <spdlog/spdlog.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <map>

#include "edm/runtime/composite_driver.hpp"
#include "edm/runtime/runtime.hpp"
#include "param_reader.hpp"
#include "pin_table.hpp"
#include "retain_builder.hpp"
#include "supervisor_builder.hpp"

namespace edm::rt {

namespace {

class ParamLister final : public ParamVisitor {
 public:
  struct Field {
    std::string name;
    ParamType type;
    ParamSpec spec;  // its strings point into the block type's visit(): static text
  };
  std::vector<Field> fields;

 protected:
  void on_param(std::string_view name, ParamRef ref, ParamSpec spec) override {
    fields.push_back({std::string(name), ref.type, spec});
  }
};

std::vector<std::string> split(const std::string& s) {
  std::vector<std::string> parts;
  std::size_t start = 0;
  for (;;) {
    std::size_t dot = s.find('.', start);
    parts.push_back(s.substr(start, dot - start));
    if (dot == std::string::npos) {
      return parts;
    }
    start = dot + 1;
  }
}

}  // namespace

class RuntimeBuilder {
 public:
  RuntimeBuilder(const Config& cfg, const BlockRegistry& blocks, const DriverRegistry& drivers,
                 const BuildOptions& options)
      : cfg_(cfg), block_types_(blocks), driver_types_(drivers), options_(options) {}

  std::unique_ptr<Runtime> build() {
    rt_.reset(new Runtime());
    rt_->config_ = cfg_;
    rt_->tables_ = to_machine_tables(cfg_);
    rt_->electrode_.set_length_mm(cfg_.machine.electrode.length_mm);  // retain may override
    make_tasks();
    make_driver();
    make_programs();
    wire();
    make_supervisor();
    register_variables();
    make_trace();
    check_bridge_vars();
    diag_.throw_if_any();
    rt_->variables_.set_machine(&rt_->machine_);
    for (auto& t : rt_->tasks_) {
      t->attach_forces(rt_->variables_);
    }
    finish();
    build_retain(cfg_, options_, *rt_, diag_);
    diag_.throw_if_any();
    return std::move(rt_);
  }

 private:
  void make_tasks() {
    for (const TaskSpec& ts : cfg_.tasks) {
      auto t = std::make_unique<Task>(ts, rt_->machine_);
      for (const NameRef& p : ts.programs) {
        program_task_[p.name] = t.get();
      }
      tasks_by_name_[ts.name] = t.get();
      rt_->tasks_.push_back(std::move(t));
    }
    const IoSpec& io = cfg_.machine.io;
    if (io.task) {
      auto it = tasks_by_name_.find(io.task->name);
      if (it == tasks_by_name_.end()) {
        diag_.error(io.task->loc, "machine.io.task: unknown task '" + io.task->name + "'");
      } else {
        io_task_ = it->second;
      }
    } else {
      for (auto& t : rt_->tasks_) {
        if (io_task_ == nullptr || t->spec().priority < io_task_->spec().priority) {
          io_task_ = t.get();
        }
      }
    }
  }

  void make_driver() {
    const IoSpec& io = cfg_.machine.io;
    const Duration period = io_task_ != nullptr ? io_task_->spec().interval : Duration{};
    bool configured = false;
    if (io.driver == "composite") {
      auto composite = std::make_unique<CompositeDriver>();
      bool seeded = false;
      configured = true;
      for (const IoSpec& child : io.drivers) {
        std::unique_ptr<IoDriver> d;
        const std::string what =
            "I/O driver '" + (child.name.empty() ? child.driver : child.name) + "'";
        configured = make_one_driver(child, what, period, seeded, d) && configured;
        if (!d) {
          return;  // unknown type (reported): io.* names would only add noise
        }
        composite->add(child.name, std::move(d));
      }
      ParamLister params;
      composite->visit_params(params);
      std::map<std::string, int> seen;
      for (const ParamLister::Field& f : params.fields) {
        if (++seen[f.name] == 2) {
          diag_.error(io.loc, "machine.io: parameter 'io." + f.name +
                                  "' is declared by two drivers (give one a `name:`)");
        }
      }
      rt_->driver_ = std::move(composite);
      if (options_.seed && !seeded) {
        diag_.error(SourceLoc{cfg_.path, 0, 0}, "--seed: no driver of the composite has a seed");
      }
    } else {
      bool seeded = false;
      configured =
          make_one_driver(io, "I/O driver '" + io.driver + "'", period, seeded, rt_->driver_);
    }
    if (!configured) {
      return;
    }
    std::vector<std::string> names;
    PinCollector pc("io", io_task_, pins_, names);
    rt_->driver_->visit_pins(pc);
    for (const auto& d : pc.duplicates) {
      diag_.error(io.loc, "machine.io: pin '" + d + "' is declared by two drivers (rename one)");
    }
    if (io_task_ != nullptr) {
      io_task_->attach_driver(*rt_->driver_);
    }
    block_pin_names_["io"] = names;
  }

  // Creates one driver (`out`, null for an unknown type) from its spec: parameters, pin map,
  // seed and configure(), every problem located. True when it was configured (its pins can be
  // collected); `seeded` is set when it took --seed.
  bool make_one_driver(const IoSpec& io, const std::string& what, Duration period, bool& seeded,
                       std::unique_ptr<IoDriver>& out) {
    out = driver_types_.create(io.driver);
    if (!out) {
      std::vector<std::string> known = driver_types_.names();
      known.emplace_back("composite");
      diag_.error(io.driver_loc, "machine.io.driver: unknown I/O driver '" + io.driver +
                                     "' (known: " + join_names(known) + ")");
      return false;
    }
    IoDriver& d = *out;
    read_params(d, io.params, what, diag_);
    report_validation(d, io.params, what, io.loc, diag_);
    if (!io.pins.empty() && !d.has_pin_map()) {
      diag_.error(io.pins.front().loc, what + ": this driver has no pin map (`pins:`)");
    } else if (d.has_pin_map()) {
      report_pin_map(io, what, d);
    }
    if (options_.seed) {
      if (d.set_seed(*options_.seed)) {
        seeded = true;
      } else if (cfg_.machine.io.driver != "composite") {  // a child of one may have none
        diag_.error(SourceLoc{cfg_.path, 0, 0},
                    "--seed: the '" + io.driver + "' driver has no random seed");
      }
    }
    if (!diag_.empty()) {
      return false;
    }
    report_param_errors(d.configure(setup("io", period)), io.params, what, io.loc, diag_);
    return true;
  }

  void report_pin_map(const IoSpec& io, const std::string& what, IoDriver& d) {
    std::vector<PinMapEntry> entries;
    for (const PinMapSpec& e : io.pins) {
      PinMapEntry entry;
      for (const ParamSetting& f : e.fields) {
        entry.push_back({f.key, f.value, f.quoted});
      }
      entries.push_back(std::move(entry));
    }
    for (const PinMapError& e : d.set_pin_map(entries)) {
      SourceLoc loc = e.entry < io.pins.size() ? io.pins[e.entry].loc : io.loc;
      if (e.entry < io.pins.size()) {
        for (const ParamSetting& f : io.pins[e.entry].fields) {
          if (f.key == e.key) {
            loc = f.value_loc;
          }
        }
      }
      diag_.error(loc, what + ": pins[" + std::to_string(e.entry) + "]" +
                           (e.key.empty() ? "" : "." + e.key) + ": " + e.message);
    }
  }

  // The safety supervisor watches and drives the driver's pins on the I/O task.
  void make_supervisor() {
    const SafetySpec& spec = cfg_.machine.safety;
    if (!spec.present || !rt_->driver_) {
      return;  // an unknown driver was reported; its pins would only add noise
    }
    if (io_task_ == nullptr) {
      diag_.error(spec.loc, "machine.safety: there is no I/O task to supervise (no tasks)");
      return;
    }
    auto pin_of = [this](const NameRef& n) {
      const PinEntry* e = resolve("", n.name, n.loc, false);
      return e != nullptr ? e->ref : PinRef{};
    };
    rt_->supervisor_ = build_supervisor(spec, rt_->tables_, rt_->machine_, &rt_->manual_,
                                        io_task_->spec().interval, pin_of, diag_);
    if (rt_->supervisor_) {
      io_task_->attach_supervisor(*rt_->supervisor_);
    }
  }

  BlockSetup setup(std::string_view instance, Duration period) {
    return {instance,      period,        &rt_->machine_,  &rt_->job_,
            &rt_->tables_, &rt_->manual_, &rt_->electrode_};
  }

  void make_programs() {
    for (const ProgramSpec& ps : cfg_.programs) {
      auto prog = std::make_unique<Program>(ps.name, rt_->machine_);
      Task* task = nullptr;
      if (auto it = program_task_.find(ps.name); it != program_task_.end()) {
        task = it->second;
      }
      const Duration period = task != nullptr ? task->spec().interval : Duration{};
      for (const BlockSpec& bs : ps.blocks) {
        std::unique_ptr<Block> block = block_types_.create(bs.type);
        if (!block) {
          diag_.error(bs.type_loc, "block '" + bs.name + "': unknown block type '" + bs.type +
                                       "' (known: " + join_names(block_types_.names()) + ")");
          continue;
        }
        const std::string what = "block '" + bs.name + "' (" + bs.type + ")";
        const std::size_t before = diag_.diagnostics().size();
        read_params(*block, bs.params, what, diag_);
        if (diag_.diagnostics().size() == before) {
          report_validation(*block, bs.params, what, bs.loc, diag_);
        }
        if (diag_.diagnostics().size() == before) {
          const std::string full = ps.name + "." + bs.name;
          report_param_errors(block->configure(setup(full, period)), bs.params, what, bs.loc,
                              diag_);
        }
        std::vector<std::string> names;
        PinCollector pc(ps.name + "." + bs.name, task, pins_, names);
        block->visit_pins(pc);
        for (const auto& d : pc.duplicates) {
          diag_.error(bs.loc, what + ": pin '" + d + "' declared twice (block type bug)");
        }
        block_pin_names_[ps.name + "." + bs.name] = names;
        block_types_by_name_[ps.name + "." + bs.name] = bs.type;
        prog->add(bs.name, std::move(block));
      }
      if (task != nullptr) {
        task->add_program(*prog);
      }
      rt_->programs_.push_back(std::move(prog));
    }
  }

  [[nodiscard]] bool is_program(const std::string& name) const {
    return std::any_of(cfg_.programs.begin(), cfg_.programs.end(),
                       [&](const ProgramSpec& p) { return p.name == name; });
  }

  // Resolves a wire endpoint to a pin entry, reporting what is wrong at loc. Names: io.pin;
  // block.pin[.…] in this program (block.child.pin for a C++ PROGRAM's child); and, for sources,
  // program.block.pin[.…] — a first part that names a program is read as a program.
  const PinEntry* resolve(const std::string& program, const std::string& name, const SourceLoc& loc,
                          bool allow_other_program) {
    std::vector<std::string> parts = split(name);
    std::string key;
    std::string block_key;
    if (parts[0] == "io") {
      if (parts.size() != 2) {
        diag_.error(loc, "'" + name + "': I/O pins are named io.pin");
        return nullptr;
      }
      block_key = "io";
      key = name;
    } else if (allow_other_program && parts.size() >= 3 && is_program(parts[0])) {
      block_key = parts[0] + "." + parts[1];
      key = name;
    } else {
      block_key = program + "." + parts[0];
      key = program + "." + name;
    }
    if (auto it = pins_.find(key); it != pins_.end()) {
      return &it->second;
    }
    if (block_key == "io" && !rt_->driver_) {
      return nullptr;  // the unknown driver was reported; its pins would only add noise
    }
    auto bit = block_pin_names_.find(block_key);
    if (bit == block_pin_names_.end()) {
      if (allow_other_program && parts.size() >= 3 && !is_program(parts[0])) {
        diag_.error(loc, "'" + name + "': no block '" + parts[0] + "' in program '" + program +
                             "' and no program '" + parts[0] + "'");
      } else {
        diag_.error(loc, "'" + name + "': unknown block '" + block_key + "'");
      }
      return nullptr;
    }
    std::string type = block_key == "io" ? "I/O driver" : block_types_by_name_[block_key];
    const std::string pin = key.substr(block_key.size() + 1);
    diag_.error(loc, "'" + name + "': " + type + " '" + block_key + "' has no pin '" + pin +
                         "' (pins: " + join_names(bit->second) + ")");
    return nullptr;
  }

  void connect_constant(const WireSpec& w, const PinEntry& dest) {
    const std::string& t = w.source;
    const char* b = t.data();
    const char* e = t.data() + t.size();
    auto bad = [&](std::string_view hint) {
      diag_.error(w.source_loc, "constant '" + t + "' does not fit " +
                                    std::string(to_string(dest.ref.type)) + " input '" + w.dest +
                                    "'" + std::string(hint));
    };
    switch (dest.ref.type) {
      case PinType::kBool:
        if (t == "true" || t == "false") {
          dest.ref.as_input<bool>()->set_constant(t == "true");
        } else {
          bad(" (use true or false)");
        }
        return;
      case PinType::kInt: {
        std::int64_t v = 0;
        auto [p, ec] = std::from_chars(b, e, v);
        if (ec != std::errc{} || p != e) {
          bad(" (a whole number)");
        } else {
          dest.ref.as_input<std::int64_t>()->set_constant(v);
        }
        return;
      }
      case PinType::kReal: {
        double v = 0.0;
        auto [p, ec] = std::from_chars(b, e, v);
        if (ec != std::errc{} || p != e || !std::isfinite(v)) {
          bad(" (a finite number)");
        } else {
          dest.ref.as_input<double>()->set_constant(v);
        }
        return;
      }
    }
  }

  void wire() {
    for (const ProgramSpec& ps : cfg_.programs) {
      for (const WireSpec& w : ps.wires) {
        const PinEntry* dest = resolve(ps.name, w.dest, w.dest_loc, false);
        if (dest == nullptr) {
          continue;
        }
        if (dest->ref.dir != PinDir::kInput) {
          diag_.error(w.dest_loc,
                      "'" + w.dest + "' is an output: a wire goes into an input (dest: source)");
          continue;
        }
        wired_.push_back({dest->ref, &w});
        if (!w.source_is_name) {
          connect_constant(w, *dest);
          continue;
        }
        const PinEntry* src = resolve(ps.name, w.source, w.source_loc, true);
        if (src == nullptr) {
          continue;
        }
        if (src->ref.dir != PinDir::kOutput) {
          diag_.error(w.source_loc, "'" + w.source +
                                        "' is an input: a wire's source must be "
                                        "an output");
          continue;
        }
        if (src->ref.type != dest->ref.type) {
          diag_.error(w.source_loc, "type mismatch: '" + w.dest + "' is " +
                                        std::string(to_string(dest->ref.type)) + " but '" +
                                        w.source + "' is " + std::string(to_string(src->ref.type)));
          continue;
        }
        switch (src->ref.type) {
          case PinType::kBool:
            dest->ref.as_input<bool>()->connect(*src->ref.as_output<bool>());
            break;
          case PinType::kInt:
            dest->ref.as_input<std::int64_t>()->connect(*src->ref.as_output<std::int64_t>());
            break;
          case PinType::kReal:
            dest->ref.as_input<double>()->connect(*src->ref.as_output<double>());
            break;
        }
      }
    }
  }

  void register_params(const std::string& prefix, Block& block, Task* owner) {
    ParamLister pl;
    block.visit_params(pl);
    for (std::uint32_t i = 0; i < pl.fields.size(); ++i) {
      Variable v;
      v.name = prefix + "." + pl.fields[i].name;
      v.kind = VarKind::kParam;
      v.block = &block;
      v.param_index = i;
      v.param_type = pl.fields[i].type;
      v.unit = pl.fields[i].spec.unit;
      v.description = pl.fields[i].spec.description;
      v.range = pl.fields[i].spec.range.text();
      v.param_range = pl.fields[i].spec.range;
      v.param_finite = pl.fields[i].spec.finite;
      v.load_time_only = pl.fields[i].spec.load_time_only;
      v.owner = owner;
      if (!rt_->variables_.add(std::move(v))) {
        diag_.error(SourceLoc{cfg_.path, 0, 0},
                    "variable '" + prefix + "." + pl.fields[i].name +
                        "' is both a pin and a parameter (block type bug)");
      }
    }
  }

  void register_variables() {
    for (const auto& [name, pin] : pins_) {
      Variable v;
      v.name = name;
      v.kind = pin.ref.dir == PinDir::kInput ? VarKind::kInput : VarKind::kOutput;
      v.pin = pin.ref;
      v.unit = pin.unit;
      v.owner = pin.owner;
      rt_->variables_.add(std::move(v));
    }
    if (rt_->driver_) {
      register_params("io", *rt_->driver_, io_task_);
    }
    for (auto& prog : rt_->programs_) {
      Task* owner = program_task_.count(prog->name()) ? program_task_[prog->name()] : nullptr;
      for (const Program::Entry& e : prog->blocks()) {
        register_params(e.full_name, *e.block, owner);
      }
    }
  }

  // The pin a config section names, or nullptr after reporting why not (`section`: the message
  // prefix; `pins_only`: how the message ends for a parameter). A name under "io." is skipped
  // silently when the driver is unknown (that was reported already).
  const Variable* find_pin(const NameRef& n, const std::string& section, const char* pins_only) {
    const Variable* v = rt_->variables_.find(n.name);
    if (v == nullptr && !rt_->driver_ && n.name.rfind("io.", 0) == 0) {
      return nullptr;
    }
    if (v == nullptr) {
      diag_.error(n.loc, section + ": unknown variable '" + n.name + "'");
      return nullptr;
    }
    if (!v->is_pin()) {
      diag_.error(n.loc, section + ": '" + n.name + "' is a parameter; " + pins_only);
      return nullptr;
    }
    return v;
  }

  // The bridge resolves its status variables when it starts; checking them here gives their
  // file:line:col (and makes `edmplc --check` catch them). The parser limits their number.
  void check_bridge_vars() {
    for (const NameRef& n : cfg_.bridge.status_vars) {
      find_pin(n, "bridge.status_vars", "only pins");
    }
  }

  void make_trace() {
    std::map<Task*, std::vector<std::pair<std::string, PinRef>>> per_task;
    std::vector<Task*> order;
    for (const NameRef& n : cfg_.trace.variables) {
      const Variable* v = find_pin(n, "trace", "only pins are traced");
      if (v == nullptr) {
        continue;
      }
      if (v->owner == nullptr) {
        continue;
      }
      if (per_task.count(v->owner) == 0) {
        order.push_back(v->owner);
      }
      auto& vars = per_task[v->owner];
      if (vars.size() == kMaxTraceVarsPerTask) {
        diag_.error(n.loc, "trace: more than " + std::to_string(kMaxTraceVarsPerTask) +
                               " variables on task '" + v->owner->name() + "'");
        continue;
      }
      vars.emplace_back(n.name, v->pin);
    }
    if (!diag_.empty()) {
      return;
    }
    // Channels in task order so the CSV columns follow the config's task list.
    for (auto& t : rt_->tasks_) {
      auto it = per_task.find(t.get());
      if (it == per_task.end()) {
        continue;
      }
      const std::uint32_t ch = rt_->trace_.add_channel(t->name(), it->second, cfg_.trace.capacity);
      t->attach_trace(rt_->trace_, ch);
      rt_->has_trace_ = true;
    }
  }

  // A composite drives some of its children's inputs itself (Input::claim, bind time): a YAML
  // wire into one would be silently replaced, so it is an error at the wire.
  void refuse_driven_wires() {
    for (const auto& [ref, w] : wired_) {
      const bool claimed = ref.type == PinType::kBool  ? ref.as_input<bool>()->claimed()
                           : ref.type == PinType::kInt ? ref.as_input<std::int64_t>()->claimed()
                                                       : ref.as_input<double>()->claimed();
      if (claimed) {
        diag_.error(w->dest_loc, "'" + w->dest +
                                     "' is driven by the program block that owns it; it cannot "
                                     "be wired (wire that block's own inputs instead)");
      }
    }
  }

  void finish() {
    // bind() after the wiring: a C++ PROGRAM connects its children seeing its final inputs.
    if (rt_->driver_) {
      rt_->driver_->bind();
    }
    for (auto& prog : rt_->programs_) {
      for (const Program::Entry& e : prog->blocks()) {
        e.block->bind();
      }
    }
    refuse_driven_wires();
    if (rt_->driver_) {
      rt_->driver_->commit_params();
      rt_->driver_->activate();
    }
    for (auto& prog : rt_->programs_) {
      for (const Program::Entry& e : prog->blocks()) {
        e.block->commit_params();
      }
      prog->activate();
    }
  }

  const Config& cfg_;
  const BlockRegistry& block_types_;
  const DriverRegistry& driver_types_;
  const BuildOptions& options_;
  DiagnosticSink diag_;
  std::unique_ptr<Runtime> rt_;
  std::map<std::string, Task*> program_task_;
  std::map<std::string, Task*> tasks_by_name_;
  Task* io_task_{nullptr};
  std::map<std::string, PinEntry> pins_;
  std::map<std::string, std::vector<std::string>> block_pin_names_;
  std::vector<std::pair<PinRef, const WireSpec*>> wired_;  // every YAML wire's destination
  std::map<std::string, std::string> block_types_by_name_;
};

std::unique_ptr<Runtime> Runtime::build(const Config& cfg, const BlockRegistry& blocks,
                                        const DriverRegistry& drivers,
                                        const BuildOptions& options) {
  try {
    return RuntimeBuilder(cfg, blocks, drivers, options).build();
  } catch (const ConfigError& e) {  // a wire of a fragment names its include (config_include)
    throw ConfigError(with_include_notes(cfg, e.diagnostics()));
  }
}

}  // namespace edm::rt
