#pragma once
/// \file
/// \brief Where the tracking engine's fixes come from: a pull interface (the engine asks for the
/// next record) over any input format — JSON lines, NMEA 0183, a RINEX observation replay (here),
/// MAVLink, UBX and NATS (the link and service modules) — and a record that could not be read
/// comes back as such, so the stream reports it and goes on.

#include "integrity/gnss/nmea.hpp"
#include "integrity/raim/spp.hpp"
#include "planner/tracking/line_input.hpp"
#include "planner/tracking/track_fix.hpp"

#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace skylane::planner {

/// \brief One record of a fix source.
struct SourceRecord {
  enum class Kind {
    kFix,   ///< a fix (`fix`)
    kBad,   ///< a record that could not be read (`where`, `line`, `error`)
    kIdle,  ///< a live input stayed quiet for the timeout
    kEnd    ///< the input ended
  };
  Kind kind = Kind::kEnd;
  TrackFix fix;
  std::string where;     ///< "input:line"
  std::size_t line = 0;  ///< 0: no line
  std::string error;
  std::string flight;    ///< kBad: the flight the record named, when that much could be read
};

/// \brief A source of fixes.
class FixSource {
 public:
  virtual ~FixSource() = default;
  /// \brief The next record; kIdle after `timeout_ms` with nothing on a live input.
  [[nodiscard]] virtual SourceRecord next(int timeout_ms) = 0;
  /// \brief The same into `out` (all of it replaced). A source may read into out's storage, so
  /// that a stream keeping one record allocates nothing per record (JSON lines do).
  virtual void nextInto(int timeout_ms, SourceRecord& out) { out = next(timeout_ms); }
  /// \brief The input's name (messages, the resume table).
  [[nodiscard]] virtual const std::string& name() const = 0;
  /// \brief Whether the input goes quiet and comes back (stale flights are then swept on the
  /// wall clock while it is quiet).
  [[nodiscard]] virtual bool live() const = 0;
  /// \brief Whether it can be read again after a restart, from resumeAfter() on.
  [[nodiscard]] virtual bool rereadable() const = 0;
  /// \brief A restart: the records up to input line `line` were processed before.
  virtual void resumeAfter(std::size_t line) = 0;
  /// \brief The line a checkpoint stores: everything up to it is processed (an NMEA epoch still
  /// open is not: the line stays before it).
  [[nodiscard]] virtual std::size_t checkpointLine() const = 0;
  /// \brief A UDP input: the datagrams the kernel dropped before they could be read so far
  /// (datagram_socket.hpp); empty for any other input.
  [[nodiscard]] virtual std::optional<std::uint64_t> droppedDatagrams() const { return std::nullopt; }
};

/// \brief One fix per JSON line (track_fix.hpp's schema); blank lines are skipped.
class JsonLinesFixSource final : public FixSource {
 public:
  explicit JsonLinesFixSource(std::unique_ptr<LineInput> in) : in_(std::move(in)) {}
  SourceRecord next(int timeout_ms) override;
  void nextInto(int timeout_ms, SourceRecord& out) override;
  [[nodiscard]] const std::string& name() const override { return in_->name(); }
  [[nodiscard]] bool live() const override { return in_->live(); }
  [[nodiscard]] bool rereadable() const override { return in_->rereadable(); }
  void resumeAfter(std::size_t line) override { resume_line_ = line; }
  [[nodiscard]] std::size_t checkpointLine() const override { return line_; }
  [[nodiscard]] std::optional<std::uint64_t> droppedDatagrams() const override { return in_->droppedDatagrams(); }

 private:
  std::unique_ptr<LineInput> in_;
  std::size_t line_ = 0, resume_line_ = 0;
  std::string text_;    ///< the line being read (reused)
  std::string source_;  ///< "input:line" of it (reused)
};

/// \brief NMEA 0183 sentences (GGA + GST, + GBS, RMC/ZDA for the date), one fix per epoch,
/// numbered by the line of the GGA that opened it. On a resume the input is read again from its
/// start so that the epoch assembler has its date and open epoch back; the epochs opened before
/// the resume line were processed then.
class NmeaFixSource final : public FixSource {
 public:
  NmeaFixSource(std::unique_ptr<LineInput> in, std::optional<integrity::NmeaDate> date)
      : in_(std::move(in)), nmea_(date) {}
  SourceRecord next(int timeout_ms) override;
  [[nodiscard]] const std::string& name() const override { return in_->name(); }
  [[nodiscard]] bool live() const override { return in_->live(); }
  [[nodiscard]] bool rereadable() const override { return in_->rereadable(); }
  void resumeAfter(std::size_t line) override { resume_line_ = line; }
  [[nodiscard]] std::size_t checkpointLine() const override;
  [[nodiscard]] std::optional<std::uint64_t> droppedDatagrams() const override { return in_->droppedDatagrams(); }

 private:
  /// The record of a closed epoch that opened at `first_line` (none before the resume line).
  std::optional<SourceRecord> epochRecord(const std::optional<integrity::NmeaFix>& nf, std::size_t first_line) const;
  /// One sentence: the record of the epoch it closes, if any.
  std::optional<SourceRecord> sentence(const std::string& text);
  std::unique_ptr<LineInput> in_;
  integrity::NmeaEpochAssembler nmea_;
  std::size_t line_ = 0, resume_line_ = 0;
  std::size_t epoch_line_ = 0;       ///< the GGA line that opened the current epoch
  std::size_t open_epoch_line_ = 0;  ///< that line while the epoch is not released (0: none)
  bool flushed_ = false;
};

/// \brief A RINEX observation file replayed epoch by epoch: skylane's own single-point position
/// and protection levels with the configured method (`pl_source` "raw").
class RinexReplayFixSource final : public FixSource {
 public:
  /// \throws maps::ParseError for an unreadable observation or navigation file.
  RinexReplayFixSource(const std::string& obs_path, const std::vector<std::string>& nav_paths, integrity::SppConfig cfg);
  ~RinexReplayFixSource() override;
  SourceRecord next(int timeout_ms) override;
  [[nodiscard]] const std::string& name() const override { return name_; }
  [[nodiscard]] bool live() const override { return false; }
  [[nodiscard]] bool rereadable() const override { return true; }
  void resumeAfter(std::size_t line) override { resume_line_ = line; }
  [[nodiscard]] std::size_t checkpointLine() const override { return line_; }

 private:
  struct Data;
  std::string name_;
  std::unique_ptr<Data> data_;
  integrity::SppConfig cfg_;
  std::size_t next_epoch_ = 0, line_ = 0, resume_line_ = 0;
  std::optional<Eigen::Vector3d> prior_;
};

/// \brief Fixes held in memory (tests, a service's batch), numbered 1, 2, … unless they carry a line.
class MemoryFixSource final : public FixSource {
 public:
  MemoryFixSource(std::string name, std::vector<TrackFix> fixes) : name_(std::move(name)), fixes_(std::move(fixes)) {}
  SourceRecord next(int timeout_ms) override;
  [[nodiscard]] const std::string& name() const override { return name_; }
  [[nodiscard]] bool live() const override { return false; }
  [[nodiscard]] bool rereadable() const override { return false; }
  void resumeAfter(std::size_t line) override { next_ = line; }
  [[nodiscard]] std::size_t checkpointLine() const override { return next_; }

 private:
  std::string name_;
  std::vector<TrackFix> fixes_;
  std::size_t next_ = 0;
};

}  // namespace skylane::planner
