#pragma once
/// \file
/// \brief `skylane serve --nats URL`: the service as a front of the JetStream workers
/// (docs/nats.md). It keeps what is the service's own — tokens, zone sets, approvals and which
/// operator owns which flight, in its database — and hands the engine's work to NATS: approval
/// requests to the work queue (any approve worker takes them), a flight's start and its fixes to
/// the flight's fix subject (the track worker of its partition judges them). It reads back the
/// event stream (every event with its stream sequence, the Server-Sent Events id), the approvals'
/// outcomes and the flights' checkpoints. nats.c stays behind NatsClient.

#include "service/event_hub.hpp"
#include "service/nats_client.hpp"

#include <nlohmann/json_fwd.hpp>

#include <atomic>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <thread>
#include <vector>

namespace skylane::service {

/// \brief An event read from the event stream: its sequence, operator and flight (or approval) id.
struct StreamEvent {
  HubEvent event;   ///< seq: the stream sequence; flight: the subject's last token
  std::string op;   ///< the subject's operator
};

/// \brief An approval's outcome as the approve worker left it in the approvals bucket.
struct NatsApprovalOutcome {
  std::string status;   ///< approved, rejected, invalid, failed (queued/running: not final)
  std::string message;  ///< why, for invalid and failed
};

/// \brief The connection to the workers and the thread reading the event stream.
class NatsFront {
 public:
  using Log = std::function<void(const std::string&)>;
  using OnEvent = std::function<void(StreamEvent)>;
  /// \brief Connects (the streams must be set up: `skylane nats setup`) and reads every event
  /// published from now on, handing each to `on_event` on the reading thread.
  /// \throws NatsError when no server answers, std::invalid_argument when it is not set up.
  NatsFront(const std::string& url, Log log, OnEvent on_event);
  ~NatsFront();
  NatsFront(const NatsFront&) = delete;
  NatsFront& operator=(const NatsFront&) = delete;

  /// \brief Publishes the approval request of `op`/`id`: the mission file and the files it
  /// names, as one bundle (a repeat of the same request is dropped by its message id).
  void requestApproval(const std::string& op, const std::string& id, const std::string& mission_path);
  /// \brief The outcome, once final; then writes the outputs the worker kept (report.json,
  /// route.geojson, …) into `dir`.
  [[nodiscard]] std::optional<NatsApprovalOutcome> takeApprovalOutcome(const std::string& op, const std::string& id,
                                                                       const std::filesystem::path& dir);
  /// \brief Puts a zone set version under `key` unless the bucket has that text already; its
  /// revision (the version the workers name).
  std::uint64_t putZoneSet(const std::string& key, const std::string& text);
  /// \brief Publishes a flight's start (its approval) on its fix subject.
  void startFlight(const std::string& op, const std::string& flight, const std::string& approval);
  /// \brief Publishes fix lines on the flight's subject and waits until the stream has them all.
  void publishFixes(const std::string& op, const std::string& flight, const std::vector<std::string>& lines);
  /// \brief Publishes an event of the service's own (a fix line refused at the door).
  void publishEvent(const std::string& op, const std::string& flight, const std::string& json_line, const std::string& msg_id);
  /// \brief A flight's checkpoint (state and the fix sequence it covers), and its route as
  /// GeoJSON when the worker has replanned it.
  [[nodiscard]] std::optional<nlohmann::json> flightCheckpoint(const std::string& op, const std::string& flight);
  [[nodiscard]] std::optional<nlohmann::json> flightRouteGeoJson(const std::string& op, const std::string& flight);
  /// \brief The events on `filter` (a subject, wildcards allowed) after stream sequence `after`,
  /// up to the stream's last when called; at most `max_bytes` of event text.
  /// \throws NatsError; std::length_error when more than `max_bytes`.
  [[nodiscard]] std::vector<StreamEvent> eventsAfter(const std::string& filter, std::uint64_t after, std::size_t max_bytes);

 private:
  void readEvents(std::uint64_t from);
  Log log_;
  OnEvent on_event_;
  std::unique_ptr<NatsClient> nats_;    ///< the service thread's
  std::unique_ptr<NatsClient> reader_;  ///< the event reader's
  std::atomic<bool> stopping_{false};
  std::thread thread_;
};

/// \brief An event message of the stream as a StreamEvent (its type from the JSON's "event").
[[nodiscard]] StreamEvent streamEvent(const NatsMessage& m);

}  // namespace skylane::service
