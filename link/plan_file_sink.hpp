#pragma once
/// \file
/// \brief Every accepted replan written as a QGroundControl plan file, for a vehicle without a
/// link (the operator uploads it) and as the record of what a link sent:
/// `DIR/<flight>-route<N>.plan` (the flight id with characters other than letters, digits, '-',
/// '_' and '.' replaced by '_').

#include "link/qgc_plan.hpp"
#include "planner/tracking/event_sink.hpp"
#include "planner/tracking/tracker.hpp"

#include <functional>
#include <string>

namespace skylane::link {

class PlanFileSink final : public planner::EventSink {
 public:
  using Log = std::function<void(const std::string&)>;
  PlanFileSink(std::string dir, const planner::Tracker& tracker, Log log = {});
  void write(const planner::TrackEvent& event, const std::string& json_line) override;

 private:
  std::string dir_;
  const planner::Tracker& tracker_;
  Log log_;
};

}  // namespace skylane::link
