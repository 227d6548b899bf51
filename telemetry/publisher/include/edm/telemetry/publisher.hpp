#pragma once
// edmplc's MQTT telemetry (docs/mqtt.md): the machine as a Sparkplug B edge node with one device.
// The device's metrics are the machine state, the alarms, the job's progress and the configured
// variables; commands (NCMD/DCMD) may write the listed parameters when mqtt.commands.enabled.
//
// RT side: a CycleObserver on the I/O task copies the state, the job progress and the metric
// pins into a Seqlock at the end of each cycle (RT-safe: no allocation, lock, syscall or log).
// Everything else — sampling the seqlock, parameters, alarms, report by exception, MQTT — runs on
// the publisher's own thread (and libmosquitto's network thread), never on a task's thread.
// Thread-safety: construct before Runtime::run() (it attaches the observer); start()/stop() from
// the controlling thread; stats() from any thread.

#include <atomic>
#include <condition_variable>
#include <memory>
#include <mutex>
#include <thread>

#include "edm/runtime/runtime.hpp"
#include "edm/sparkplug/edge_node.hpp"
#include "edm/telemetry/mqtt_config.hpp"

namespace edm::telemetry {

class Publisher {
 public:
  Publisher(rt::Runtime& runtime, MqttConfig config);
  ~Publisher();
  Publisher(const Publisher&) = delete;
  Publisher& operator=(const Publisher&) = delete;

  /// Starts the edge node (connecting in the background) and the publishing thread. A setup
  /// libmosquitto refuses is logged and leaves telemetry off: the machine runs on without it.
  void start();
  /// A clean stop: DDEATH and NDEATH, disconnect, threads joined. Idempotent.
  void stop();
  [[nodiscard]] sparkplug::EdgeNodeStats stats() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace edm::telemetry
