#include "planner/tracking/event_sink.hpp"

#include <cerrno>

namespace skylane::planner {

void JsonLinesSink::write(const TrackEvent& /*event*/, const std::string& json_line) {
  if (closed_) return;
  errno = 0;
  out_ << json_line << '\n';
  check();
}

void JsonLinesSink::flush() {
  if (closed_) return;
  errno = 0;
  out_.flush();
  check();
}

void JsonLinesSink::check() {
  if (out_) return;
  closed_ = true;
  error_ = errno;  // the failed write(2)'s, read before anything else can set it
}

}  // namespace skylane::planner
