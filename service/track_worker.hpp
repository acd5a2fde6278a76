#pragma once
/// \file
/// \brief `skylane worker --role track`: the tracking engine on NATS JetStream partitions
/// (docs/nats.md).
///
/// A worker holds the partitions it can lease (a key in skylane_leases it refreshes every
/// second; a stopped worker's lease expires after nats::kLeaseTtl_s and another worker, or the
/// restarted one, takes the partition). For each partition it holds it runs one tracking engine
/// and a pull consumer made anew at the partition's checkpoint, so fixes arrive in stream order.
/// Per batch of fixes:
/// 1. each fix is judged (a flight's first message `{"start": {"approval": ID}}` registers it
///    from the approval's bundle); a fix whose stream sequence its flight's checkpoint already
///    covers was judged before a restart and is skipped;
/// 2. the events are published with a message id made of the fix's stream sequence and the
///    event's index, so that the events of a fix judged again after a crash are dropped by
///    JetStream as repeats (the judgement is deterministic given the checkpointed state);
/// 3. the flights' checkpoints (state, the route after a replan, the sequence covered) are put,
///    then the partition's (the last sequence of the batch) with compare-and-set on its revision:
///    a worker that lost its partition learns it there and lets go.
/// Every accepted fix is thus judged once and each of its events is in the event stream once.
/// Bad messages (a subject without operator and flight, not JSON, not a fix, an unknown flight)
/// give a `rejected_input` event naming the subject and why; they never stop the worker.

#include "planner/tracking/tracker.hpp"

#include <atomic>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

namespace skylane::service {

/// \brief How a track worker runs.
struct TrackWorkerOptions {
  std::string url;                 ///< NATS server(s)
  std::string name;                ///< the worker's name (leases, logs)
  std::vector<int> partitions;     ///< the partitions it may hold; empty: every one
  std::string cache_dir;           ///< approval bundles are unpacked here
  planner::TrackerOptions tracker;
  int batch = 512;                 ///< fixes fetched at once per partition
  std::function<void(const std::string&)> log;
};

/// \brief What a worker has done so far.
struct TrackWorkerCounters {
  std::atomic<std::uint64_t> fixes{0}, events{0}, rejected{0}, skipped{0}, restarts{0};
  std::atomic<int> partitions_held{0};
};

/// \brief Runs until `stop` is set; then lets go of its leases.
/// \throws NatsError when no server answers at start, std::invalid_argument for a partition
/// outside the recorded count.
void runTrackWorker(const TrackWorkerOptions& options, const std::atomic<bool>& stop, TrackWorkerCounters& counters);

}  // namespace skylane::service
