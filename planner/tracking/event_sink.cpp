#include "planner/tracking/event_sink.hpp"

namespace skylane::planner {

void JsonLinesSink::write(const TrackEvent& /*event*/, const std::string& json_line) {
  out_ << json_line << '\n';
  if (!out_) closed_ = true;
}

void JsonLinesSink::flush() {
  out_.flush();
  if (!out_) closed_ = true;
}

}  // namespace skylane::planner
