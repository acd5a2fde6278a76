#pragma once
/// \file
/// \brief The service's metrics in the Prometheus text exposition format (version 0.0.4):
/// counters, gauges read when scraped, and histograms with cumulative buckets.

#include <cstdint>
#include <functional>
#include <map>
#include <string>
#include <vector>

namespace skylane::service {

/// \brief A histogram of seconds.
class Histogram {
 public:
  explicit Histogram(std::vector<double> bounds_s) : bounds_(std::move(bounds_s)), counts_(bounds_.size(), 0) {}
  void observe(double s);
  /// \brief The `name_bucket`, `name_sum` and `name_count` lines.
  [[nodiscard]] std::string text(const std::string& name, const std::string& help) const;

 private:
  std::vector<double> bounds_;
  std::vector<std::uint64_t> counts_;  ///< per bucket (not cumulative)
  std::uint64_t count_ = 0;
  double sum_ = 0.0;
};

/// \brief What /metrics shows.
struct Metrics {
  std::uint64_t requests = 0;
  std::map<int, std::uint64_t> responses;  ///< by status code
  std::uint64_t fixes_accepted = 0, inputs_rejected = 0, events = 0;
  std::uint64_t datagrams_dropped = 0;  ///< by the kernel on the UDP inputs (input_dropped events)
  std::uint64_t approvals_submitted = 0, approvals_refused_queue_full = 0, rate_limited = 0;
  Histogram approval_seconds{{0.25, 0.5, 1, 2, 5, 10, 30, 60, 120, 300}};
  Histogram fix_request_seconds{{0.0005, 0.001, 0.002, 0.005, 0.01, 0.02, 0.05, 0.1, 0.25, 1}};
  /// \brief Gauges read at scrape time: name → (help, value).
  std::map<std::string, std::pair<std::string, std::function<double()>>> gauges;
  /// \brief The exposition text.
  [[nodiscard]] std::string text() const;
};

}  // namespace skylane::service
