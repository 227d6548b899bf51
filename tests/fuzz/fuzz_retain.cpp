// fuzz_retain: any bytes as a retain file for the runtime's reader (runtime/retain.hpp). A damaged
// file is normal: the reader must never throw or crash, and must apply all values or none. What
// it accepts must be writable again and read back to the same values.

#include <string>
#include <string_view>

#include "edm/runtime/retain.hpp"
#include "fuzz/fuzz_entry.hpp"

namespace edm::fuzz {

int retain_one_input(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  const rt::RetainLoadResult r = rt::parse_retain_file(text);
  if (!r.warning.empty()) {
    EDM_FUZZ_CHECK(r.values.empty());  // nothing half-applied
    return 0;
  }
  for (const auto& [name, value] : r.values) {
    EDM_FUZZ_CHECK(rt::is_valid_retain_name(name));
  }
  // format_retain_file throws only for invalid names, which the reader must not have accepted.
  const std::string again = rt::format_retain_file(r.values);
  const rt::RetainLoadResult back = rt::parse_retain_file(again);
  EDM_FUZZ_CHECK(back.warning.empty());
  EDM_FUZZ_CHECK(back.values == r.values);
  return 0;
}

}  // namespace edm::fuzz

EDM_FUZZ_MAIN(edm::fuzz::retain_one_input)
