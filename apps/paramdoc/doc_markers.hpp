#pragma once
// Generated sections of a Markdown file, each between a pair of marker lines:
//
//   <!-- params:TypeName -->
//   (generated; rewritten by `./edm docs`)
//   <!-- /params:TypeName -->
//
// splice_tables() puts the wanted text between every pair and says which sections changed.
// Pure functions; thread-safe.

#include <map>
#include <string>
#include <vector>

namespace edm::paramdoc {

struct SpliceResult {
  std::string text;                 // the file with every known section replaced
  std::vector<std::string> found;   // the types with a marker pair, in file order
  std::vector<std::string> stale;   // the types whose section differed from the wanted text
  std::vector<std::string> errors;  // "line 12: ..." (unknown type, unclosed or repeated pair)
};

/// Replaces the body of each marker pair in `text` by wanted[type]. A pair naming a type that is
/// not in `wanted` is kept as it is and reported as an error, as are an opening marker without
/// its closing one (or with another opening before it) and a type with two pairs in one file.
SpliceResult splice_tables(const std::string& text,
                           const std::map<std::string, std::string>& wanted);

}  // namespace edm::paramdoc
