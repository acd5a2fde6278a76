#pragma once
/// \file
/// \brief `skylane worker --role approve`: route approvals taken from the JetStream work queue
/// (docs/nats.md). Any number of workers share one durable consumer, so each request is taken by
/// one of them; a request is acknowledged (and leaves the queue) only once its outcome is in the
/// skylane_approvals bucket, and a redelivered request whose outcome is already there is only
/// acknowledged: each request is done once. While an approval runs the worker tells the server
/// it is in progress, so a slow search is not handed to a second worker; a worker killed in the
/// middle leaves the request unacknowledged and another takes it after the ack wait.
///
/// Each approval runs as `skylane approve … --progress` in a process of its own (approval_pool.hpp),
/// in a folder made from the request's bundle (approval_bundle.hpp). Its outcome: the status
/// (`approved`, `rejected`, `invalid` for a bad request, `failed`), and for a decided approval the
/// bundle with the report (what a track worker registers a flight from) and the route.geojson;
/// then an `approval` event on skylane.event.<operator>.<id>.

#include <atomic>
#include <cstdint>
#include <functional>
#include <string>

namespace skylane::service {

/// \brief How an approve worker runs.
struct ApproveWorkerOptions {
  std::string url;
  std::string name;
  std::string program;   ///< the skylane executable
  std::string work_dir;  ///< approvals run in <work_dir>/<operator>/<id>/
  std::function<void(const std::string&)> log;
};

struct ApproveWorkerCounters {
  std::atomic<std::uint64_t> approved{0}, rejected{0}, invalid{0}, failed{0}, repeats{0};
};

/// \brief Takes approval requests until `stop` is set.
void runApproveWorker(const ApproveWorkerOptions& options, const std::atomic<bool>& stop, ApproveWorkerCounters& counters);

}  // namespace skylane::service
