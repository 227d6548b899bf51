#include "retain_builder.hpp"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "retain_job.hpp"
#include "retain_offsets.hpp"

namespace edm::rt {

class RetainBuilder {
 public:
  RetainBuilder(const Config& cfg, const BuildOptions& options, Runtime& rt, DiagnosticSink& diag)
      : cfg_(cfg), options_(options), rt_(rt), diag_(diag) {}

  void make_retain() {
    const RetainSpec& rs = cfg_.retain;
    if (rs.file.empty()) {
      return;
    }
    std::vector<RetainStore::Variable> vars;
    VariableRegistry& reg = rt_.variables_;
    for (const NameRef& n : rs.variables) {
      if (auto t = retainable(n)) {
        vars.push_back({n.name, t->second, [&reg, var = t->first, type = t->second]() {
                          return read_retained(reg, *var, type);
                        }});
      }
    }
    // The job record's measured quantities: each an LREAL variable of the config.
    auto reader = [&](const std::optional<NameRef>& n, const char* key) {
      std::function<double()> read;
      if (!n) return read;
      if (auto t = retainable(*n)) {
        if (t->second != RetainType::kReal) {
          diag_.error(n->loc, std::string("retain.") + key + ": '" + n->name +
                                  "' is not LREAL (a length in mm)");
        } else {
          read = [&reg, var = t->first] { return read_retained(reg, *var, RetainType::kReal).r; };
        }
      }
      return read;
    };
    retain_job::Readers readers{reader(rs.job_depth, "job_depth"),
                                reader(rs.job_touch_z, "job_touch_z"),
                                reader(rs.job_wear, "job_wear")};
    if (!diag_.empty()) {
      return;
    }
    const SourceLoc& file_loc = rs.file_loc.line != 0 ? rs.file_loc : rs.loc;
    namespace fs = std::filesystem;
    std::string path = rs.file;
    if (fs::path(path).is_relative()) {
      if (options_.state_dir.empty()) {
        // The application decides where state lives (edmplc: --state-dir, EDM_STATE_DIR).
        if (options_.load_retain) {
          spdlog::info(
              "retain: '{}' is relative and no state directory is set (--state-dir or "
              "EDM_STATE_DIR): nothing is retained in this run",
              rs.file);
        }
        return;
      }
      path = (fs::path(options_.state_dir) / path).lexically_normal().string();
    }
    // Judged also by --check: a device, FIFO, directory or link is never read nor replaced.
    if (const std::string problem = retain_target_problem(path); !problem.empty()) {
      diag_.error(file_loc, "retain.file: " + problem);
      return;
    }
    // --check and --list-vars: no store is constructed, so nothing can write the file.
    if (!options_.load_retain) {
      return;
    }
    if (const fs::path dir = fs::path(path).parent_path(); !dir.empty()) {
      std::error_code ec;
      fs::create_directories(dir, ec);  // a first start with a new state directory
      if (ec) {
        diag_.error(file_loc, "retain.file: cannot create the directory '" + dir.string() +
                                  "': " + ec.message());
        return;
      }
    }
    // While a part-program runner exists, the job record is retained beside the variables.
    const bool job_record = rt_.job_.has_runner();
    if (job_record) {
      auto job_vars = retain_job::variables(rt_.job_, rt_.interrupted_job_, std::move(readers));
      vars.insert(vars.end(), std::make_move_iterator(job_vars.begin()),
                  std::make_move_iterator(job_vars.end()));
    }
    {  // the work offsets G54…G59 and the electrode length whenever there is a retain file
      auto offset_vars = retain_offsets::variables(rt_.work_offsets_, rt_.electrode_);
      vars.insert(vars.end(), std::make_move_iterator(offset_vars.begin()),
                  std::make_move_iterator(offset_vars.end()));
    }
    RetainLoadResult loaded = load_retain_file(path);
    switch (loaded.status) {
      case RetainLoadStatus::kLoaded:
        retain_offsets::take(loaded.values, rt_.work_offsets_, rt_.electrode_);
        if (job_record) {
          rt_.interrupted_job_ = retain_job::take(loaded.values);
          if (rt_.interrupted_job_) {
            rt_.job_alarm_text_ = retain_job::alarm_text(*rt_.interrupted_job_);
          }
        }
        for (const auto& [name, value] : loaded.values) {
          restore(name, value);
        }
        break;
      case RetainLoadStatus::kMissing:
        spdlog::info("retain: {} (first start); retained variables start from their defaults",
                     loaded.warning);
        break;
      case RetainLoadStatus::kNotRegular:  // replaced between the check above and the open
        diag_.error(file_loc, "retain.file: " + loaded.warning);
        return;
      case RetainLoadStatus::kCorrupt:
      case RetainLoadStatus::kUnreadable:
        // Never overwrite what could not be read: move it aside (evidence, manual recovery) and
        // raise an alarm at power-on so the operator knows the retained values are defaults.
        try {
          const std::string aside = set_aside_retain_file(path);
          rt_.retain_warning_ = loaded.warning + "; kept as '" + aside +
                                "'; retained variables start from their defaults";
          rt_.startup_alarm_ = AlarmCode::kRetainCorrupt;
        } catch (const std::exception& e) {
          diag_.error(file_loc,
                      "retain.file: " + loaded.warning +
                          "; it cannot be moved aside either, so the runtime will not overwrite "
                          "it: " +
                          e.what());
          return;
        }
        break;
    }
    rt_.retain_path_ = path;
    rt_.retain_ = std::make_unique<RetainStore>(path, rs.min_interval, std::move(vars));
    // A write that fails (full disk, read-only directory, the file replaced by a directory) is
    // alarm 183 until a write succeeds: retained data the runtime could not keep is never quiet.
    rt_.retain_->set_write_listener([&machine = rt_.machine_, store = rt_.retain_.get()](bool ok) {
      if (ok) {
        machine.clear_alarm(AlarmCode::kRetainWriteFailed, "retain");
        return;
      }
      Alarm a;
      a.code = AlarmCode::kRetainWriteFailed;
      a.severity = AlarmSeverity::kWarning;
      a.source = "retain";
      a.text = "the retain file could not be written: retained values are not kept";
      a.value = static_cast<double>(store->write_failures());
      machine.raise(a);
    });
  }

  // The variable `n` names and its type in the retain file, or nullopt (reported).
  std::optional<std::pair<const Variable*, RetainType>> retainable(const NameRef& n) {
    const Variable* v = rt_.variables_.find(n.name);
    if (v == nullptr) {
      diag_.error(n.loc, "retain: unknown variable '" + n.name + "'");
      return std::nullopt;
    }
    if (v->kind == VarKind::kInput) {
      diag_.error(n.loc,
                  "retain: '" + n.name + "' is an input (wired); retain outputs or parameters");
      return std::nullopt;
    }
    RetainType type = RetainType::kReal;
    if (v->is_pin()) {
      type = v->pin.type == PinType::kBool  ? RetainType::kBool
             : v->pin.type == PinType::kInt ? RetainType::kInt
                                            : RetainType::kReal;
    } else if (v->param_type == ParamType::kBool) {
      type = RetainType::kBool;
    } else if (v->param_type == ParamType::kInt) {
      type = RetainType::kInt;
    } else if (v->param_type == ParamType::kString || v->param_type == ParamType::kDuration) {
      diag_.error(n.loc, "retain: parameter '" + n.name + "' is " + std::string(v->type_name()) +
                             "; retain BOOL, LINT or LREAL");
      return std::nullopt;
    }
    return std::pair{v, type};
  }

  // Reads a retained variable with its exact type (LINT stays exact beyond 2^53).
  static RetainValue read_retained(const VariableRegistry& reg, const Variable& v,
                                   RetainType type) {
    if (v.is_pin()) {
      switch (v.pin.type) {
        case PinType::kBool: return RetainValue::make_bool(v.pin.as_output<bool>()->get());
        case PinType::kInt: return RetainValue::make_int(v.pin.as_output<std::int64_t>()->get());
        case PinType::kReal: return RetainValue::make_real(v.pin.as_output<double>()->get());
      }
    }
    const ParamValue p = reg.read_param(v.name).value_or(ParamValue{});
    switch (type) {
      case RetainType::kBool: return RetainValue::make_bool(p.b);
      case RetainType::kInt: return RetainValue::make_int(p.i);
      case RetainType::kReal: return RetainValue::make_real(p.r);
    }
    return {};
  }

  void restore(const std::string& name, const RetainValue& value) {
    const Variable* v = rt_.variables_.find(name);
    bool listed = std::any_of(cfg_.retain.variables.begin(), cfg_.retain.variables.end(),
                              [&](const NameRef& n) { return n.name == name; });
    if (v == nullptr || !listed) {
      spdlog::warn("retain: '{}' in {} is not a retained variable of this config; ignored", name,
                   cfg_.retain.file);
      return;
    }
    // The config may have changed since the file was written: only restore a value of the same
    // type, and never a non-finite real into a controller.
    const std::string_view want = v->type_name();
    const std::string_view have = to_string(value.type);
    if (want != have) {
      spdlog::warn("retain: '{}' is {} in the file but {} in the config; not restored", name, have,
                   want);
      return;
    }
    if (value.type == RetainType::kReal && !std::isfinite(value.r)) {
      spdlog::warn("retain: '{}' holds a non-finite value; not restored", name);
      return;
    }
    if (!v->is_pin()) {
      const ParamValue pv = value.type == RetainType::kBool  ? ParamValue::of_bool(value.b)
                            : value.type == RetainType::kInt ? ParamValue::of_int(value.i)
                                                             : ParamValue::of_real(value.r);
      VarStatus st = rt_.variables_.write(name, pv, /*apply_now=*/true);
      if (!st) {
        spdlog::warn("retain: '{}' not restored: {}", name, st.message);
      }
      return;
    }
    switch (v->pin.type) {
      case PinType::kBool: v->pin.as_output<bool>()->set(value.b); break;
      case PinType::kInt: v->pin.as_output<std::int64_t>()->set(value.i); break;
      case PinType::kReal: v->pin.as_output<double>()->set(value.r); break;
    }
  }

 private:
  const Config& cfg_;
  const BuildOptions& options_;
  Runtime& rt_;
  DiagnosticSink& diag_;
};

void build_retain(const Config& cfg, const BuildOptions& options, Runtime& rt,
                  DiagnosticSink& diag) {
  RetainBuilder(cfg, options, rt, diag).make_retain();
}

}  // namespace edm::rt
