#include "edm/blocks/fuzzy_servo_lut.hpp"

#include <algorithm>
#include <cmath>
#include <utility>

namespace edm::blocks {
namespace {

constexpr int kWindow = 32;  // pulses in the seed-003 shift registers

}  // namespace

std::vector<rt::ParamError> FuzzyServoLUT::configure(const rt::BlockSetup& /*setup*/) {
  std::vector<rt::ParamError> errs = rt::validate_params(params_);
  if (!errs.empty()) {
    return errs;
  }
  fuzzy::SyntaxError se;
  const auto terms = [&](const char* field, const std::string& text, bool optional,
                         fuzzy::Variable& var) {
    if (optional && std::all_of(text.begin(), text.end(), [](char c) {
          return c == ' ' || c == '\t' || c == '\n' || c == '\r';
        })) {
      return;  // an empty optional variable: rules that use it get "unknown term"
    }
    if (auto t = fuzzy::parse_terms(text, se)) {
      var.terms = std::move(*t);
    } else {
      errs.push_back({field, se.message});
    }
  };
  std::vector<fuzzy::Variable> inputs(3);
  inputs[0].name = "open";
  inputs[1].name = "short";
  inputs[2].name = "normal";
  fuzzy::Variable out;
  out.name = "v";
  terms("open_terms", params_.open_terms, false, inputs[0]);
  terms("short_terms", params_.short_terms, false, inputs[1]);
  terms("normal_terms", params_.normal_terms, true, inputs[2]);
  terms("velocity_terms", params_.velocity_terms, false, out);
  if (!errs.empty()) {
    return errs;
  }
  auto rules = fuzzy::parse_rules(params_.rules, inputs, out, se);
  if (!rules) {
    return {{"rules", se.message}};
  }
  // The paper's coding: y = round(quant_num · v / quant_den), v in paper units (±quant_v_full).
  const double code_per_unit = static_cast<double>(params_.quant_num) /
                               static_cast<double>(params_.quant_den) * params_.quant_v_full;
  const double full_code = std::round(code_per_unit);
  if (!(full_code >= 1.0 && full_code <= 32767.0)) {
    return {{"quant_num", "the full-scale code round(quant_num * quant_v_full / quant_den) = " +
                              std::to_string(full_code) +
                              " does not fit the int16 table (1 ... 32767)"}};
  }
  engine_ =
      std::make_unique<fuzzy::MamdaniEngine>(std::move(inputs), std::move(out), std::move(*rules),
                                             static_cast<std::size_t>(params_.samples));
  table_.fill(0);  // addresses with a count above 32 are never read
  for (int o = 0; o < kCounts; ++o) {
    for (int s = 0; s < kCounts; ++s) {
      const double x[3] = {static_cast<double>(o), static_cast<double>(s),
                           static_cast<double>(std::max(0, kWindow - o - s))};
      const double y = engine_->infer(x);
      const bool reachable = o + s <= kWindow;
      if (std::isnan(y) && reachable) {
        return {{"rules", "no rule fires at open = " + std::to_string(o) + ", short = " +
                              std::to_string(s) + " (every reachable cell needs one)"}};
      }
      const double v = std::isnan(y) ? 0.0 : std::clamp(y, -1.0, 1.0);
      const double v_paper = params_.quant_v_full * v;
      table_[static_cast<std::size_t>(address(o, s))] =
          static_cast<std::int16_t>(std::lround(static_cast<double>(params_.quant_num) * v_paper /
                                                static_cast<double>(params_.quant_den)));
    }
  }
  lsb_ = 1.0 / code_per_unit;
  return errs;
}

void FuzzyServoLUT::activate() noexcept { v_mm_s_.set(params_.v_max_mm_s * table(0, 0)); }

rt::BlockStatus FuzzyServoLUT::update(const rt::CycleContext& /*ctx*/) noexcept {
  const std::int64_t o = open_count_.get();
  const std::int64_t s = short_count_.get();
  if (o < 0 || o > kWindow || s < 0 || s > kWindow) {
    return fault("an open or short count outside the window", static_cast<double>(o));
  }
  v_mm_s_.set(params_.v_max_mm_s * table(static_cast<int>(o), static_cast<int>(s)));
  return rt::BlockStatus::kOk;
}

}  // namespace edm::blocks
