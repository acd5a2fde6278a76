#include "service/event_hub.hpp"

#include <algorithm>

namespace skylane::service {

std::string sseMessage(const HubEvent& e) {
  // A JSON line holds no line break, so one `data:` line carries it.
  return "id: " + std::to_string(e.seq) + "\nevent: " + e.type + "\ndata: " + e.line + "\n\n";
}

void EventHub::write(const planner::TrackEvent& event, const std::string& json_line) {
  pending_.push_back({store_.lastEventSeq(), event.flight, event.type, json_line});
}

void EventHub::deliver(std::vector<Subscriber>& list, const HubEvent& e, const std::string& text) {
  list.erase(std::remove_if(list.begin(), list.end(),
                            [&](Subscriber& s) {
                              if (s.stream->closed()) return true;
                              const bool had = e.seq > 0 && e.seq <= s.after;  // in the stream's backlog already
                              return !had && (!s.wants || s.wants(e.flight)) && !s.stream->push(text);
                            }),
             list.end());
}

void EventHub::flush() {
  std::vector<HubEvent> batch = std::move(pending_);
  pending_.clear();
  for (const HubEvent& e : batch) publish(e);
}

void EventHub::publish(const HubEvent& e) {
  for (const auto& observe : observers) observe(e);
  const auto it = by_flight_.find(e.flight);
  if (it == by_flight_.end() && filtered_.empty()) return;
  const std::string text = sseMessage(e);
  if (it != by_flight_.end()) {
    deliver(it->second, e, text);
    if (it->second.empty()) by_flight_.erase(it);
  }
  deliver(filtered_, e, text);
}

void EventHub::subscribe(std::shared_ptr<EventStream> stream, const std::string& flight, Filter wants, std::int64_t after) {
  // A closed stream is dropped at the next event or keep-alive (not from its close callback, which
  // may run inside the loops here).
  if (flight.empty()) {
    filtered_.push_back({std::move(stream), std::move(wants), after});
  } else {
    by_flight_[flight].push_back({std::move(stream), nullptr, after});
  }
}

void EventHub::keepAlive() {
  const HubEvent none;
  for (auto it = by_flight_.begin(); it != by_flight_.end();) {
    deliver(it->second, none, ": keep-alive\n\n");
    it = it->second.empty() ? by_flight_.erase(it) : std::next(it);
  }
  filtered_.erase(std::remove_if(filtered_.begin(), filtered_.end(),
                                 [](Subscriber& s) { return s.stream->closed() || !s.stream->push(": keep-alive\n\n"); }),
                  filtered_.end());
}

std::size_t EventHub::streams() const {
  std::size_t n = filtered_.size();
  for (const auto& [flight, list] : by_flight_) n += list.size();
  return n;
}

}  // namespace skylane::service
