#pragma once
/// \file
/// \brief Approvals on a pool of workers with a bounded queue. Each approval runs as its own
/// process (`skylane approve MISSION --out DIR --progress`): a route search is seconds of CPU on
/// operator input, and a process of its own keeps a crash, a runaway search or its memory away
/// from the service and from the other approvals (OMPL's random generator is process-wide too,
/// so approvals in threads of one process would not be reproducible). The worker reads the
/// child's progress lines as they come and hands the outcome back.

#include <condition_variable>
#include <cstddef>
#include <deque>
#include <functional>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

namespace skylane::service {

/// \brief One approval to run.
struct ApprovalJob {
  std::string id;
  std::string mission;  ///< the mission file
  std::string out_dir;  ///< where `approve --out` writes
};

/// \brief How an approval ended.
struct ApprovalOutcome {
  int exit_code = -1;    ///< 0 approved, 1 rejected (or an internal error), 2 bad input; -1 killed
  std::string message;   ///< the child's last error line, without the "skylane: error: " prefix
};

/// \brief The workers and their queue. Callbacks run on a worker thread.
class ApprovalPool {
 public:
  using Progress = std::function<void(const std::string& id, const std::string& line)>;
  using Done = std::function<void(const std::string& id, const ApprovalOutcome& outcome)>;
  /// \brief `program`: the skylane executable; `workers` threads; at most `capacity` waiting jobs.
  ApprovalPool(std::string program, int workers, std::size_t capacity, Progress progress, Done done);
  /// \brief Stops the workers; running children are killed.
  ~ApprovalPool();
  ApprovalPool(const ApprovalPool&) = delete;
  ApprovalPool& operator=(const ApprovalPool&) = delete;

  /// \brief Queues a job; false when the queue is full.
  bool submit(ApprovalJob job);
  /// \brief Jobs waiting, and running.
  [[nodiscard]] std::size_t waiting() const;
  [[nodiscard]] std::size_t running() const;
  [[nodiscard]] std::size_t capacity() const { return capacity_; }

 private:
  void work();
  ApprovalOutcome runChild(const ApprovalJob& job);
  std::string program_;
  std::size_t capacity_;
  Progress progress_;
  Done done_;
  mutable std::mutex mutex_;
  std::condition_variable wake_;
  std::deque<ApprovalJob> queue_;
  std::vector<int> children_;  ///< pids running
  std::size_t running_ = 0;
  bool stopping_ = false;
  std::vector<std::thread> threads_;
};

}  // namespace skylane::service
