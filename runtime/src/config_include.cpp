// Config parser, `include:` of a program (docs/config.md "Fragments"): a fragment is a YAML file
// holding a program's `blocks:` and `wires:` (and further `include:`s), found relative to the
// file that includes it. Its blocks and wires are appended to the program's own; a block name or
// wire destination defined twice is an error at the second place naming the first. Cycles,
// nesting deeper than kMaxIncludeDepth, more than kMaxIncludedFiles and more than the config size
// limit in all are refused at the include. Every message located in a fragment ends with where it
// was included from (with_include_notes).

#include <algorithm>
#include <filesystem>
#include <system_error>
#include <unordered_map>

#include "config_parser_impl.hpp"
#include "edm/machining/bounded_read.hpp"

namespace edm::rt {

namespace config_detail {

namespace {

namespace fs = std::filesystem;

constexpr std::size_t kMaxIncludeDepth = 8;                         // fragments within fragments
constexpr std::size_t kMaxIncludedFiles = 64;                       // fragments read by one config
constexpr std::size_t kMaxTotalBytes = machining::kMaxConfigBytes;  // the config and fragments

/// `name` relative to the directory of `including` (as given, normalised), or `name` if absolute.
std::string resolve(const std::string& including, const std::string& name) {
  const fs::path p(name);
  if (p.is_absolute()) {
    return p.lexically_normal().string();
  }
  return (fs::path(including).parent_path() / p).lexically_normal().string();
}

}  // namespace

std::string where(const SourceLoc& loc) {
  return loc.file + ":" + std::to_string(loc.line) + ":" + std::to_string(loc.col);
}

std::string canonical_path(const std::string& path) {
  std::error_code ec;
  fs::path p = fs::weakly_canonical(fs::path(path), ec);
  if (ec) {
    p = fs::absolute(fs::path(path), ec).lexically_normal();
  }
  return p.string();
}

void Parser::parse_include(const Value& v, ProgramSpec& out) {
  std::vector<Value> items;
  if (v.node.IsSequence()) {
    auto list = r_.list(v);
    if (!list) {
      return;
    }
    items = std::move(*list);
    if (items.empty()) {
      r_.error(v, "must name at least one fragment");
    }
  } else {
    items.push_back(v);  // one fragment: `include: fragments/x.yaml`
  }
  for (const Value& item : items) {
    include_one(item, out);
  }
}

void Parser::include_one(const Value& item, ProgramSpec& out) {
  const auto name = r_.string(item);
  if (!name) {
    return;
  }
  const std::string file = resolve(r_.file(), *name);
  const std::string canonical = canonical_path(file);
  const auto same = [&](const IncludeState::Frame& f) { return f.canonical == canonical; };
  if (const auto it = std::find_if(inc_.stack.begin(), inc_.stack.end(), same);
      it != inc_.stack.end()) {
    std::string chain;
    for (auto f = it; f != inc_.stack.end(); ++f) {
      chain += f->file + " -> ";
    }
    r_.error(item, "include cycle: " + chain + file);
    return;
  }
  if (inc_.stack.size() > kMaxIncludeDepth) {
    r_.error(item, "includes nest more than " + std::to_string(kMaxIncludeDepth) +
                       " deep (a fragment including a fragment ...)");
    return;
  }
  if (inc_.included->size() >= kMaxIncludedFiles) {
    r_.error(item, "more than " + std::to_string(kMaxIncludedFiles) + " fragments in one config");
    return;
  }
  const machining::BoundedRead read =
      machining::read_bounded_file(file, machining::kMaxConfigBytes, "config fragment");
  if (!read.ok()) {
    r_.error(item, "cannot include " + yaml_util::quote(file) + ": " + read.problem);
    return;
  }
  if (read.text.size() > kMaxTotalBytes - std::min(inc_.bytes, kMaxTotalBytes)) {
    r_.error(item, "the config and its fragments are larger than " +
                       std::to_string(kMaxTotalBytes >> 20) + " MiB together");
    return;
  }
  inc_.bytes += read.text.size();
  // The note of a fragment: where it was included, and where that file was included from.
  std::string note = "included from " + where(item.loc);
  for (const IncludedFile& f : *inc_.included) {
    if (f.file == r_.file()) {
      note += ", " + f.note;
      break;
    }
  }
  inc_.included->push_back({file, note});
  inc_.stack.push_back({canonical, file});
  Parser fragment(file, sink_, inc_);
  Reader reader(file, sink_);
  if (const auto root = load_document(read.text, reader, sink_)) {
    fragment.parse_fragment(*root, out);
  }
  inc_.stack.pop_back();
}

void Parser::parse_fragment(const YAML::Node& root, ProgramSpec& out) {
  const std::optional<Value> top =
      root_map(root, "the fragment is empty (expected a map with blocks, wires or include)",
               "a fragment must be a map (blocks, wires, include), got ");
  if (!top) {
    return;
  }
  auto m = r_.map(*top, {"blocks", "wires", "include"});
  if (!m) {
    return;
  }
  if (const Field* f = m->find("blocks")) {
    if (auto items = r_.list(f->value)) {
      std::vector<BlockSpec> blocks;
      parse_named(
          *items, blocks, [this](const Value& item, BlockSpec& b) { parse_block(item, b); },
          "block", " in program '" + out.name + "'");
      append_blocks(blocks, out);
    }
  }
  if (const Field* f = m->find("wires")) {
    std::vector<WireSpec> wires;
    parse_wires(f->value, wires);
    append_wires(wires, out);
  }
  if (const Field* f = m->find("include")) {
    parse_include(f->value, out);
  }
}

void Parser::append_blocks(std::vector<BlockSpec>& blocks, ProgramSpec& out) {
  for (BlockSpec& b : blocks) {
    const auto same = [&](const BlockSpec& o) { return o.name == b.name; };
    if (const auto it = std::find_if(out.blocks.begin(), out.blocks.end(), same);
        !b.name.empty() && it != out.blocks.end()) {
      r_.error(b.name_loc, "blocks",
               "duplicate block name '" + b.name + "' in program '" + out.name + "' (first at " +
                   where(it->name_loc) + ")");
      continue;
    }
    out.blocks.push_back(std::move(b));
  }
}

void Parser::append_wires(std::vector<WireSpec>& wires, ProgramSpec& out) {
  for (WireSpec& w : wires) {
    const auto same = [&](const WireSpec& o) { return o.dest == w.dest; };
    if (const auto it = std::find_if(out.wires.begin(), out.wires.end(), same);
        it != out.wires.end()) {
      r_.error(w.dest_loc, "wires",
               "input '" + w.dest + "' is wired twice (first at " + where(it->dest_loc) +
                   "); an input can be wired only once");
      continue;
    }
    out.wires.push_back(std::move(w));
  }
}

}  // namespace config_detail

std::vector<Diagnostic> with_include_notes(const Config& cfg, std::vector<Diagnostic> diags) {
  std::unordered_map<std::string, std::size_t> rank;  // 0: the config itself, then read order
  for (std::size_t i = 0; i < cfg.includes.size(); ++i) {
    rank.emplace(cfg.includes[i].file, i + 1);
  }
  const auto rank_of = [&](const Diagnostic& d) {
    const auto it = rank.find(d.loc.file);
    return it == rank.end() ? std::size_t{0} : it->second;
  };
  std::stable_sort(diags.begin(), diags.end(), [&](const Diagnostic& a, const Diagnostic& b) {
    const std::size_t ra = rank_of(a);
    const std::size_t rb = rank_of(b);
    if (ra != rb) {
      return ra < rb;
    }
    return a.loc.line != b.loc.line ? a.loc.line < b.loc.line : a.loc.col < b.loc.col;
  });
  for (Diagnostic& d : diags) {
    if (const std::size_t r = rank_of(d); r != 0) {
      d.message += " (" + cfg.includes[r - 1].note + ")";
    }
  }
  return diags;
}

}  // namespace edm::rt
