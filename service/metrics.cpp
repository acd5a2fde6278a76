#include "service/metrics.hpp"

#include <algorithm>
#include <cstdio>
#include <sstream>

namespace skylane::service {

namespace {

std::string number(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.10g", v);
  return buf;
}

void counter(std::ostringstream& out, const std::string& name, const std::string& help, std::uint64_t v) {
  out << "# HELP " << name << " " << help << "\n# TYPE " << name << " counter\n" << name << " " << v << "\n";
}

}  // namespace

void Histogram::observe(double s) {
  const auto it = std::lower_bound(bounds_.begin(), bounds_.end(), s);
  if (it != bounds_.end()) ++counts_[static_cast<std::size_t>(it - bounds_.begin())];
  ++count_;
  sum_ += s;
}

std::string Histogram::text(const std::string& name, const std::string& help) const {
  std::ostringstream out;
  out << "# HELP " << name << " " << help << "\n# TYPE " << name << " histogram\n";
  std::uint64_t cumulative = 0;
  for (std::size_t i = 0; i < bounds_.size(); ++i) {
    cumulative += counts_[i];
    out << name << "_bucket{le=\"" << number(bounds_[i]) << "\"} " << cumulative << "\n";
  }
  out << name << "_bucket{le=\"+Inf\"} " << count_ << "\n" << name << "_sum " << number(sum_) << "\n" << name << "_count " << count_ << "\n";
  return out.str();
}

std::string Metrics::text() const {
  std::ostringstream out;
  counter(out, "skylane_http_requests_total", "HTTP requests received.", requests);
  out << "# HELP skylane_http_responses_total HTTP responses by status code.\n# TYPE skylane_http_responses_total counter\n";
  for (const auto& [code, n] : responses) out << "skylane_http_responses_total{code=\"" << code << "\"} " << n << "\n";
  counter(out, "skylane_fixes_accepted_total", "Fixes judged by the tracking engine (fix events).", fixes_accepted);
  counter(out, "skylane_inputs_rejected_total", "Records refused (rejected_input events).", inputs_rejected);
  counter(out, "skylane_input_datagrams_dropped_total",
          "Datagrams of the UDP inputs dropped by the kernel, their receive buffer full (input_dropped events).", datagrams_dropped);
  counter(out, "skylane_events_total", "Tracking events committed.", events);
  counter(out, "skylane_approvals_submitted_total", "Approvals queued.", approvals_submitted);
  counter(out, "skylane_approvals_refused_total", "Approvals refused because the queue was full (429).", approvals_refused_queue_full);
  counter(out, "skylane_rate_limited_total", "Requests refused by the per-token rate limit (429).", rate_limited);
  out << approval_seconds.text("skylane_approval_seconds", "Time from submission to the end of an approval.");
  out << fix_request_seconds.text("skylane_fix_request_seconds", "Time to judge and commit one request's fixes (post to event).");
  for (const auto& [name, g] : gauges) {
    out << "# HELP " << name << " " << g.first << "\n# TYPE " << name << " gauge\n" << name << " " << number(g.second()) << "\n";
  }
  return out.str();
}

}  // namespace skylane::service
