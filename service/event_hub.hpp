#pragma once
/// \file
/// \brief The tracking engine's events on their way to the service's readers. As an event sink
/// (after the database in the session's sinks) it takes each event with the sequence number the
/// database gave it, holds it until the batch is committed (flush), and then hands it to the open
/// event streams that may see it — so a reader never sees an event a crash could take back, and
/// a stream resumed with Last-Event-ID continues exactly after the last event it had.

#include "planner/tracking/event_sink.hpp"
#include "planner/tracking/track_store.hpp"
#include "service/http.hpp"

#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <vector>

namespace skylane::service {

/// \brief One committed event.
struct HubEvent {
  std::int64_t seq = 0;
  std::string flight, type, line;
};

/// \brief Text of one Server-Sent Events message (`id`, `event`, `data`).
[[nodiscard]] std::string sseMessage(const HubEvent& e);

/// \brief The sink and its subscribers.
class EventHub final : public planner::EventSink {
 public:
  /// \brief `store` gives each event's sequence number (it comes before this sink).
  explicit EventHub(const planner::TrackStore& store) : store_(store) {}
  void write(const planner::TrackEvent& event, const std::string& json_line) override;
  /// \brief The batch is committed: its events go to the subscribers and the observers.
  void flush() override;
  /// \brief An event committed elsewhere (the NATS event stream, its sequence the stream's) goes
  /// to the subscribers and the observers.
  void publish(const HubEvent& e);

  /// \brief A stream gets the events of one flight (`flight`), or, with `flight` empty, those
  /// whose flight `wants` accepts (all of an operator's flights).
  using Filter = std::function<bool(const std::string& flight)>;
  /// `after`: the last sequence the stream has had already (its backlog); events up to it are
  /// not sent again.
  void subscribe(std::shared_ptr<EventStream> stream, const std::string& flight, Filter wants, std::int64_t after = 0);
  /// \brief Sends a comment line to every stream (keeps proxies and readers from timing out, and
  /// finds streams whose reader has gone).
  void keepAlive();
  [[nodiscard]] std::size_t streams() const;
  /// \brief Called with every committed event (metrics, a request collecting its own events).
  std::vector<std::function<void(const HubEvent&)>> observers;

 private:
  struct Subscriber {
    std::shared_ptr<EventStream> stream;
    Filter wants;
    std::int64_t after = 0;
  };
  const planner::TrackStore& store_;
  std::vector<HubEvent> pending_;
  /// Sends `e` to the streams of `list`, dropping the closed ones.
  static void deliver(std::vector<Subscriber>& list, const HubEvent& e, const std::string& text);
  std::map<std::string, std::vector<Subscriber>> by_flight_;  ///< one flight's streams (no filter call per event)
  std::vector<Subscriber> filtered_;                          ///< streams of several flights
};

}  // namespace skylane::service
