#pragma once
/// \file
/// \brief The event stream of a tracker with a database, appended to a file so that it stays
/// consistent with the database across a kill at any moment: every event is in the file
/// exactly once, and no torn line survives a restart.
///
/// How: the events of a batch are held in memory and appended in one write only after the
/// database has committed the batch; in the same transaction the database records where the
/// batch goes in the file (bytes before and after, the first and last event's seq). At start
/// the file is compared with that mark: at its end, nothing to do; cut inside the last batch
/// (a kill between the commit and the end of the write, or in the middle of a line), the file is
/// cut back to the batch's start and the batch's lines are written again from the database,
/// which holds every event's line as it was streamed. A file shorter than the batch's start
/// (removed, rotated) or longer than its end (written by another program) is not touched: a new
/// file, or an error naming it. A file of exactly the batch's start length is taken as cut
/// before the batch (a removed file that the new one happens to match gets that batch again).
/// A device or FIFO (/dev/null, a pipe) is written as is, without a mark.

#include "planner/tracking/event_sink.hpp"

#include <cstdint>
#include <string>

namespace skylane::planner {

class TrackStore;

/// \brief Events appended to a file in step with a TrackStore (see the file comment).
class EventFileSink final : public EventSink {
 public:
  /// \brief Opens (creates) `path` for appending and repairs its end from `store`'s mark.
  /// \throws maps::OutputError when the file cannot be opened or written; maps::ParseError when
  /// it is longer than the database recorded (another writer).
  EventFileSink(std::string path, TrackStore& store);
  ~EventFileSink() override;
  EventFileSink(const EventFileSink&) = delete;
  EventFileSink& operator=(const EventFileSink&) = delete;

  void write(const TrackEvent& event, const std::string& json_line) override;
  /// \brief Records in the open transaction where the held lines go in the file.
  void beforeCommit() override;
  /// \brief Appends the held lines (after the commit). \throws maps::OutputError on a failed write.
  void flush() override;
  /// \brief Lines written again at start from the database (0 when the file was whole).
  [[nodiscard]] std::size_t repairedLines() const { return repaired_lines_; }

 private:
  void repair();
  void append(const std::string& bytes);
  std::string path_;
  TrackStore& store_;
  int fd_ = -1;
  std::uint64_t bytes_ = 0;  ///< the file's length once every committed batch is written
  std::string pending_;      ///< the lines of the batch not yet committed
  std::int64_t first_seq_ = 0, last_seq_ = 0;
  std::size_t repaired_lines_ = 0;
  bool regular_ = false;  ///< a regular file (a device or FIFO is written as is, without a mark)
};

}  // namespace skylane::planner
