// edm_paramdoc — the parameter tables of docs/blocks.md (and docs/controllers.md), generated from
// the ParamSpec every registered block, PROGRAM and I/O driver type declares (issue 18 item 3).
//
//   edm_paramdoc --write FILE...   rewrite the table between each <!-- params:T --> pair
//   edm_paramdoc --check FILE...   exit 1 and name the types whose table is out of date
//
// Every registered type must have exactly one marker pair across the files given. `./edm docs`
// runs --write; the ctest `docs.blocks` runs --check.
// Exit codes: 0 up to date (or rewritten), 1 out of date or a marker problem, 2 bad arguments or
// a file that cannot be read or written.

#include <array>
#include <cstddef>
#include <cstdio>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "doc_markers.hpp"
#include "edm/apps/cli.hpp"
#include "edm/blocks/register.hpp"
#include "edm/programs/register.hpp"
#include "edm/runtime/block.hpp"
#include "edm/runtime/io_driver.hpp"
#include "edm/runtime/loopback_driver.hpp"
#include "edm/runtime/type_registry.hpp"
#include "edm/sim/sim_driver.hpp"
#include "param_table.hpp"

namespace {

using edm::apps::kExitBadInput;
using edm::apps::kExitOk;
constexpr int kExitOutOfDate = edm::apps::kExitFailure;

// Every registrar whose types the docs describe: the block library and the C++ PROGRAMs, then
// the I/O drivers (the runtime's and the simulator).
constexpr std::array kBlockRegistrars{&edm::blocks::register_builtin_blocks,
                                      &edm::programs::register_builtin_programs};
constexpr std::array kDriverRegistrars{&edm::rt::register_runtime_drivers,
                                       &edm::sim::register_sim_driver};

// Adds the table of each type the registrars register, from a default instance of it. A
// runtime-writable number without a bounded range (or a default outside it) is an error: the
// table would document a parameter any writer could set to anything (issue 31).
template <class Base, std::size_t N>
void add_tables(const std::array<void (*)(edm::rt::TypeRegistry<Base>&), N>& registrars,
                std::map<std::string, std::string>& tables, std::vector<std::string>& errors) {
  edm::rt::TypeRegistry<Base> registry;
  for (auto* add_types : registrars) {
    add_types(registry);
  }
  for (const std::string& name : registry.names()) {
    if (tables.contains(name)) {
      errors.push_back("'" + name + "' is both a block and a driver type: one marker cannot tell");
    }
    const auto block = registry.create(name);
    tables[name] = edm::paramdoc::param_table(*block);
    edm::rt::SpecAudit audit;
    block->visit_params(audit);
    for (const edm::rt::ParamError& p : audit.problems) {
      errors.push_back("'" + name + "' parameter '" + p.field + "' " + p.message);
    }
  }
}

bool read_file(const std::string& path, std::string& text) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream ss;
  ss << in.rdbuf();
  text = ss.str();
  return static_cast<bool>(in);
}

// Through a temporary file and a rename, so an interrupted run never leaves half a document.
bool write_file(const std::string& path, const std::string& text) {
  const std::string tmp = path + ".tmp";
  {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    out << text;
    if (!out.flush()) {
      return false;
    }
  }
  return std::rename(tmp.c_str(), path.c_str()) == 0;
}

std::string joined(const std::vector<std::string>& names) {
  std::string out;
  for (const std::string& n : names) {
    out += (out.empty() ? "" : ", ") + n;
  }
  return out;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Generates the parameter tables of the block docs from the blocks' ParamSpecs.",
               "edm_paramdoc"};
  std::vector<std::string> write_files;
  std::vector<std::string> check_files;
  auto* write = app.add_option("--write", write_files, "rewrite the tables in these files");
  auto* check = app.add_option("--check", check_files, "exit 1 if a table is out of date");
  write->excludes(check);
  check->excludes(write);
  app.require_option(1);
  if (const auto code =
          edm::apps::parse(app, argc, argv, "edm_paramdoc --write FILE... | --check FILE...")) {
    return *code;
  }
  const bool writing = !write_files.empty();
  const std::vector<std::string>& files = writing ? write_files : check_files;

  std::vector<std::string> errors;
  std::map<std::string, std::string> tables;  // type → its table
  add_tables(kBlockRegistrars, tables, errors);
  add_tables(kDriverRegistrars, tables, errors);
  std::map<std::string, std::string> section_file;  // type → the file that documents it
  bool out_of_date = false;
  for (const std::string& path : files) {
    std::string text;
    if (!read_file(path, text)) {
      std::fprintf(stderr, "edm_paramdoc: cannot read %s\n", path.c_str());
      return kExitBadInput;
    }
    edm::paramdoc::SpliceResult r = edm::paramdoc::splice_tables(text, tables);
    for (const std::string& e : r.errors) {
      errors.push_back(path + ": " + e);
    }
    for (const std::string& type : r.found) {
      const auto [it, first] = section_file.emplace(type, path);
      if (!first && it->second != path) {
        errors.push_back("'" + type + "' has a section in both " + it->second + " and " + path);
      }
    }
    if (r.stale.empty()) {
      continue;
    }
    if (writing) {
      if (!write_file(path, r.text)) {
        std::fprintf(stderr, "edm_paramdoc: cannot write %s\n", path.c_str());
        return kExitBadInput;
      }
      std::printf("%s: rewrote %s\n", path.c_str(), joined(r.stale).c_str());
    } else {
      out_of_date = true;
      std::printf("%s: out of date: %s\n", path.c_str(), joined(r.stale).c_str());
    }
  }
  for (const auto& [type, table] : tables) {
    if (!section_file.contains(type)) {
      errors.push_back("no section for '" + type + "': put <!-- params:" + type +
                       " --> and <!-- /params:" + type + " --> in its section");
    }
  }
  for (const std::string& e : errors) {
    std::fprintf(stderr, "edm_paramdoc: %s\n", e.c_str());
  }
  if (out_of_date) {
    std::fprintf(stderr, "edm_paramdoc: regenerate with ./edm docs\n");
  }
  return out_of_date || !errors.empty() ? kExitOutOfDate : kExitOk;
}
