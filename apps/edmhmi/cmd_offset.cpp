// edmhmi offset [G54..G59] [X.. Y.. Z..] [--json] — the work frames the runtime retains
// (offset.get / offset.set, docs/hmi.md).
#include <cctype>
#include <cstdio>

#include "cli.hpp"
#include "edm/hmi/job_runner.hpp"
#include "edm/hmi/work_offsets.hpp"

namespace edmhmi {

namespace {

using edm::bridge::Json;
using edm::bridge::Reply;

/// "X12.5" (or "X" "12.5") words into offset.set's fields; false with a message when malformed.
bool parse_axis_words(const std::vector<std::string>& words, std::size_t from, Json& params,
                      std::string& error) {
  for (std::size_t i = from; i < words.size(); ++i) {
    const std::string& w = words[i];
    const char letter = static_cast<char>(std::tolower(static_cast<unsigned char>(w.front())));
    if (letter != 'x' && letter != 'y' && letter != 'z') {
      error = "'" + w + "': expected X<mm>, Y<mm> or Z<mm>";
      return false;
    }
    std::string number = w.substr(1);
    if (number.empty() && i + 1 < words.size()) number = words[++i];
    const std::optional<double> v = edm::apps::finite_number(number);
    if (!v) {
      error = "'" + w + "': " + (number.empty() ? "no number" : "'" + number + "' is not a number");
      return false;
    }
    const std::string key(1, letter);
    if (params.contains(key)) {
      error = "'" + w + "': " + std::string(1, static_cast<char>(std::toupper(letter))) +
              " given twice";
      return false;
    }
    params[key] = *v;
  }
  return true;
}

}  // namespace

int cmd_offset(const OffsetArgs& args, const edm::hmi::ConnectionSettings& settings) {
  std::optional<int> frame;
  std::size_t first_axis = 0;
  if (!args.words.empty() && !args.words.front().empty() &&
      std::toupper(static_cast<unsigned char>(args.words.front().front())) == 'G') {
    frame = edm::hmi::frame_index(args.words.front());
    if (!frame) return usage("offset: '" + args.words.front() + "': work frames are G54..G59");
    first_axis = 1;
  }
  Json params = Json::object();
  std::string error;
  for (const std::string& w : args.words) {
    if (w.empty()) return usage("offset: an empty word");
  }
  if (!parse_axis_words(args.words, first_axis, params, error)) return usage("offset: " + error);
  if (!params.empty() && !frame)
    return usage("offset: name the frame to set, e.g. offset G54 Z-41.25");

  edm::bridge::Client client;
  if (!connect(client, settings)) return kExitFailure;
  if (!params.empty()) {
    params["frame"] = edm::hmi::frame_name(*frame);
    const Reply r = client.request("offset.set", params);
    if (!r) return report_error("offset.set", r);
    const edm::machining::Vec3 v{r.body.value("x", 0.0), r.body.value("y", 0.0),
                                 r.body.value("z", 0.0)};
    std::printf("%s  (generation %llu)\n", edm::hmi::format_frame(*frame, v).c_str(),
                static_cast<unsigned long long>(r.body.value("generation", std::uint64_t{0})));
    return kExitOk;
  }
  const std::optional<edm::hmi::WorkOffsets> fetched =
      fetch([&] { return edm::hmi::fetch_offsets(client); });
  if (!fetched) return kExitFailure;
  const edm::hmi::WorkOffsets& offsets = *fetched;
  if (args.json) {
    std::printf("%s\n", edm::hmi::to_json(offsets).dump(2).c_str());
    return kExitOk;
  }
  for (int i = 0; i < edm::hmi::kWorkFrames; ++i) {
    if (frame && *frame != i) continue;
    const double length = offsets.z_electrode_mm[static_cast<std::size_t>(i)];
    std::printf("%s",
                edm::hmi::format_frame(i, offsets.frame[static_cast<std::size_t>(i)]).c_str());
    if (length > 0.0) std::printf("  (Z with a %.4f mm electrode)", length);
    std::printf("\n");
  }
  if (offsets.electrode_mm > 0.0) std::printf("electrode now %.4f mm\n", offsets.electrode_mm);
  return kExitOk;
}

}  // namespace edmhmi
