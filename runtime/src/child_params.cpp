#include "edm/runtime/child_params.hpp"

namespace edm::rt {

namespace {

// Passes a child's parameters on as "<prefix>.<param>" (load time only).
class PrefixedParams final : public ParamVisitor {
 public:
  PrefixedParams(const std::string& prefix, ParamVisitor& inner) : prefix_(prefix), inner_(inner) {}

 protected:
  void on_param(std::string_view name, ParamRef ref, ParamSpec spec) override {
    inner_.forward(prefix_ + "." + std::string(name), ref, spec);
  }

 private:
  const std::string& prefix_;
  ParamVisitor& inner_;
};

}  // namespace

void append_prefixed(std::vector<ParamError>& errs, std::string_view prefix,
                     std::vector<ParamError> more) {
  for (ParamError& e : more) {
    std::string field = prefix.empty()    ? std::move(e.field)
                        : e.field.empty() ? std::string(prefix)
                                          : std::string(prefix) + "." + e.field;
    errs.push_back({std::move(field), std::move(e.message)});
  }
}

void ChildParams::add(std::string prefix, Block& child) {
  children_.push_back({std::move(prefix), &child});
}

void ChildParams::visit(ParamVisitor& v) {
  for (Child& c : children_) {
    if (c.prefix.empty()) {
      c.block->visit_params(v);
    } else {
      PrefixedParams p(c.prefix, v);
      c.block->visit_params(p);
    }
  }
}

std::vector<ParamError> ChildParams::validate() const {
  std::vector<ParamError> errs;
  for (const Child& c : children_) {
    append_prefixed(errs, c.prefix, c.block->validate());
  }
  return errs;
}

std::size_t ChildParams::count() const {
  std::size_t n = 0;
  for (const Child& c : children_) {
    n += c.block->param_count();
  }
  return n;
}

ChildParams::Owner ChildParams::owner(std::size_t index) const noexcept {
  for (const Child& c : children_) {
    const std::size_t n = c.block->param_count();
    if (index < n) {
      return {c.block, &c.prefix, index};
    }
    index -= n;
  }
  return {nullptr, nullptr, index};
}

void ChildParams::apply(std::size_t index, const ParamValue& v) const noexcept {
  if (const Owner o = owner(index); o.block != nullptr) {
    o.block->apply_param(o.index, v);
  }
}

ParamValue ChildParams::read(std::size_t index) const {
  const Owner o = owner(index);
  return o.block != nullptr ? o.block->read_param(o.index) : ParamValue{};
}

void ChildParams::commit() const {
  for (const Child& c : children_) {
    c.block->commit_params();
  }
}

}  // namespace edm::rt
