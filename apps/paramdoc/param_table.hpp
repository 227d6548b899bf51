#pragma once
// The parameter table of one block or driver type, rendered in Markdown from the ParamSpec each
// field declares in its Params struct's visit() — the same declaration that validation, the
// refusal of a runtime write and `edmplc --list-vars` use, so docs/blocks.md cannot say otherwise.
// Non-RT; not thread-safe (reads a block that nothing else touches).

#include <string>

namespace edm::rt {
class Block;
}

namespace edm::paramdoc {

/// The header, the separator and one row per parameter of `block` (a default instance), in visit
/// order: | parameter | type | unit | range | default | run-time writable | description |.
/// A type without parameters gives one line saying so. Every line ends with '\n'.
std::string param_table(edm::rt::Block& block);

}  // namespace edm::paramdoc
