#pragma once
// What every edmhmi command shares: exit codes, the connection to edmplc, the interrupt flag.
// (DESIGN §4: exit 0 ok, 1 runtime failure or alarm, 2 bad input.)

#include <atomic>
#include <string>
#include <string_view>
#include <vector>

#include "edm/bridge/client.hpp"
#include "edm/hmi/connection.hpp"

namespace edmhmi {

inline constexpr int kExitOk = 0;
inline constexpr int kExitFailure = 1;
inline constexpr int kExitBadInput = 2;
inline constexpr int kExitInterrupted = 130;

using Args = std::vector<std::string_view>;

/// Set by SIGINT / SIGTERM; loops poll it.
std::atomic<bool>& interrupted();
void install_signal_handlers();

/// "edmhmi: message" + usage on stderr; returns kExitBadInput.
int usage(const std::string& message);

/// Connects and says hello; prints why on failure and returns false.
bool connect(edm::bridge::Client& client, const edm::hmi::ConnectionSettings& settings,
             bool auto_reconnect = false);

/// Prints a refused reply ("edmhmi: op: code: message") and returns the exit code for it.
int report_error(std::string_view op, const edm::bridge::Reply& reply);

/// Reads a whole text file (at most 64 MiB); prints why on failure and returns false.
bool read_text_file(const std::string& path, std::string& out);

int cmd_check(const Args& args);
int cmd_run(const Args& args, const edm::hmi::ConnectionSettings& settings);
int cmd_status(const Args& args, const edm::hmi::ConnectionSettings& settings);
int cmd_stats(const Args& args, const edm::hmi::ConnectionSettings& settings);
int cmd_machine(std::string_view command, const Args& args,
                const edm::hmi::ConnectionSettings& settings);
int cmd_watch(const Args& args, const edm::hmi::ConnectionSettings& settings);
int cmd_trace(const Args& args, const edm::hmi::ConnectionSettings& settings);
int cmd_serve(const Args& args, const edm::hmi::ConnectionSettings& settings);

}  // namespace edmhmi
