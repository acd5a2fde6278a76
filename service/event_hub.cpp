#include "service/event_hub.hpp"

namespace skylane::service {

std::string sseMessage(const HubEvent& e) {
  // A JSON line holds no line break, so one `data:` line carries it.
  return "id: " + std::to_string(e.seq) + "\nevent: " + e.type + "\ndata: " + e.line + "\n\n";
}

void EventHub::write(const planner::TrackEvent& event, const std::string& json_line) {
  pending_.push_back({store_.lastEventSeq(), event.flight, event.type, json_line});
}

void EventHub::flush() {
  std::vector<HubEvent> batch = std::move(pending_);
  pending_.clear();
  for (const HubEvent& e : batch) {
    for (const auto& observe : observers) observe(e);
    for (auto it = subscribers_.begin(); it != subscribers_.end();) {
      Subscriber& s = it->second;
      const bool open = !s.stream->closed() && (!s.wants(e.flight) || s.stream->push(sseMessage(e)));
      it = open ? std::next(it) : subscribers_.erase(it);
    }
  }
}

void EventHub::subscribe(std::shared_ptr<EventStream> stream, Filter wants) {
  // A closed stream is dropped at the next event or keep-alive (not from its close callback, which
  // may run inside the loops below).
  subscribers_[next_id_++] = {std::move(stream), std::move(wants)};
}

void EventHub::keepAlive() {
  for (auto it = subscribers_.begin(); it != subscribers_.end();) {
    const bool open = !it->second.stream->closed() && it->second.stream->push(": keep-alive\n\n");
    it = open ? std::next(it) : subscribers_.erase(it);
  }
}

}  // namespace skylane::service
