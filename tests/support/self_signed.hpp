#pragma once
// A self-signed certificate for the TLS tests, made with the openssl CLI (edm::apps::run, no
// shell): EC P-256, valid two days, subjectAltName IP:127.0.0.1.

#include <chrono>
#include <filesystem>
#include <string>

#include "edm/apps/subprocess.hpp"

namespace edm::test {

/// Writes `key` (mode 600) and `cert`; returns the certificate's SHA-256 fingerprint
/// ("AB:CD:..."), empty when openssl failed.
inline std::string make_self_signed(const std::string& key, const std::string& cert,
                                    const std::string& common_name) {
  edm::apps::SpawnOptions quiet;
  quiet.err = edm::apps::Stream::kNull;
  const auto made = edm::apps::run(
      {"openssl", "req", "-x509", "-newkey", "ec", "-pkeyopt", "ec_paramgen_curve:prime256v1",
       "-nodes", "-days", "2", "-subj", "/CN=" + common_name, "-addext",
       "subjectAltName=IP:127.0.0.1", "-keyout", key, "-out", cert},
      quiet, std::chrono::seconds(60));
  if (!made.failure("openssl").empty()) return {};
  namespace fs = std::filesystem;
  fs::permissions(key, fs::perms::owner_read | fs::perms::owner_write, fs::perm_options::replace);
  const auto fp =
      edm::apps::run({"openssl", "x509", "-in", cert, "-noout", "-fingerprint", "-sha256"}, quiet,
                     std::chrono::seconds(60));
  const auto eq = fp.out.find('=');
  if (!fp.failure("openssl").empty() || eq == std::string::npos) return {};
  std::string fingerprint = fp.out.substr(eq + 1);
  fingerprint.erase(fingerprint.find_last_not_of('\n') + 1);
  return fingerprint;
}

}  // namespace edm::test
