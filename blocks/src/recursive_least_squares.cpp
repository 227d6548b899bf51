#include "edm/blocks/recursive_least_squares.hpp"

#include <cmath>

namespace edm::blocks {

std::vector<rt::ParamError> RecursiveLeastSquaresParams::validate() const {
  std::vector<rt::ParamError> errs;
  rt::require_ordered(errs, "p0", p0, "trace_max", trace_max);
  return errs;
}

void RecursiveLeastSquares::visit_pins(rt::PinVisitor& v) {
  static constexpr const char* kPhi[] = {"phi0", "phi1", "phi2", "phi3"};
  static constexpr const char* kTheta[] = {"theta0", "theta1", "theta2", "theta3"};
  v.input("y", y_);
  for (std::size_t i = 0; i < RlsCore::kMaxParams; ++i) {
    v.input(kPhi[i], phi_[i]);
  }
  v.input("enable", enable_);
  for (std::size_t i = 0; i < RlsCore::kMaxParams; ++i) {
    v.output(kTheta[i], theta_[i]);
  }
  v.output("error", error_);
  v.output("y_hat", y_hat_);
  v.output("trace_p", trace_p_, "1");
  v.output("bounded", bounded_);
}

void RecursiveLeastSquares::activate() noexcept {
  const auto& p = params_;
  const double init[RlsCore::kMaxParams] = {p.theta0_init, p.theta1_init, p.theta2_init,
                                            p.theta3_init};
  rls_.reset(static_cast<std::size_t>(p.n_params), p.p0, init);
  for (std::size_t i = 0; i < RlsCore::kMaxParams; ++i) {
    theta_[i].set(i < rls_.n() ? rls_.theta(i) : 0.0);
  }
  error_.set(0.0);
  y_hat_.set(0.0);
  trace_p_.set(rls_.trace());
  bounded_.set(false);
}

rt::BlockStatus RecursiveLeastSquares::update(const rt::CycleContext& /*ctx*/) noexcept {
  const double y = y_.get();
  double phi[RlsCore::kMaxParams] = {};
  bool finite = std::isfinite(y);
  for (std::size_t i = 0; i < rls_.n(); ++i) {
    phi[i] = phi_[i].get();
    finite = finite && std::isfinite(phi[i]);
  }
  if (!finite) {
    return fault("a non-finite regressor or measurement");
  }
  const double y_hat = rls_.predict(phi);
  y_hat_.set(y_hat);
  error_.set(y - y_hat);
  if (!enable_.get()) {
    bounded_.set(false);
    return rt::BlockStatus::kOk;
  }
  const RlsCore::Result r = rls_.update(phi, y, params_.lambda, params_.trace_max);
  if (!r.ok) {
    return fault("the RLS update diverged (covariance not positive or not finite)");
  }
  for (std::size_t i = 0; i < rls_.n(); ++i) {
    theta_[i].set(rls_.theta(i));
  }
  trace_p_.set(rls_.trace());
  bounded_.set(r.bounded);
  return r.bounded ? rt::BlockStatus::kSaturated : rt::BlockStatus::kOk;
}

}  // namespace edm::blocks
