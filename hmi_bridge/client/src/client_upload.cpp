// Program upload: program.begin, the blocks in program.chunk lines well under the server's line
// limit, program.commit with the CRC-32 of the whole program; program.abort after a refusal.
#include <algorithm>

#include "edm/bridge/client.hpp"

namespace edm::bridge {

namespace {

constexpr std::size_t kChunkBytes = 512 * 1024;  // well under the server's 1 MiB line limit

}  // namespace

Reply Client::upload_program(std::span<const machining::MotionBlock> blocks,
                             std::size_t chunk_blocks) {
  UploadOptions o;
  o.chunk_blocks = chunk_blocks;
  return upload_program(blocks, o);
}

Reply Client::upload_program(std::span<const machining::MotionBlock> blocks,
                             const UploadOptions& options) {
  const std::size_t chunk_blocks = options.chunk_blocks;
  Json begin = {{"blocks", blocks.size()}};
  if (!options.slot.empty()) begin["slot"] = options.slot;
  if (options.offsets_generation) begin["offsets_generation"] = *options.offsets_generation;
  Reply r = request("program.begin", begin);
  if (!r) {
    return r;
  }
  std::size_t first = 0;
  while (first < blocks.size()) {
    Json chunk = Json::array();
    std::size_t bytes = 0;
    std::size_t i = first;
    for (; i < blocks.size() && i - first < std::max<std::size_t>(chunk_blocks, 1); ++i) {
      Json b = to_json(blocks[i]);
      bytes += b.dump().size() + 1;
      chunk.push_back(std::move(b));
      if (bytes > kChunkBytes) {
        ++i;
        break;
      }
    }
    r = request("program.chunk", {{"first", first}, {"blocks", std::move(chunk)}});
    if (!r) {
      request("program.abort");
      return r;
    }
    first = i;
  }
  r = request("program.commit", {{"checksum", format_checksum(program_checksum(blocks))}});
  return r;
}

}  // namespace edm::bridge
