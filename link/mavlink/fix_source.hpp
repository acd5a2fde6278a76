#pragma once
/// \file
/// \brief A MAVLink vehicle as a fix source of the tracking engine (docs/vehicle_link.md §2.3).
///
/// Every GPS_RAW_INT (and GPS2_RAW, a second receiver) with a 3-D fix, a UNIX time and accuracy
/// estimates becomes a fix: the receiver's own position (latitude, longitude, the ellipsoidal
/// height `alt_ellipsoid`, else the AMSL `alt` lifted by the EGM96 undulation) and protection
/// levels from its accuracy estimates by the rule NMEA GST fixes use (track_fix.hpp):
/// HPL = √(−2 ln p_H)·h_acc, VPL = Q⁻¹(p_V/2)·v_acc, h_acc taken as the σ of the horizontal
/// error ellipse's major axis (`pl_source` "mavlink_accuracy"). HEARTBEAT names the vehicle
/// (system id) and GLOBAL_POSITION_INT, the autopilot's fused estimate, is kept for the link
/// (it has no time and no accuracy, so it is not a fix). A GPS message without a fix, without
/// a UNIX time or without accuracies is a bad record that says why; garbage bytes and bad
/// checksums are reported as bad records with their counts, and the stream goes on.
///
/// Records are numbered by the frames read (1, 2, …): a file can be resumed after a frame.
///
/// A live link is read ahead of the tracking: every frame that has arrived is parsed at once
/// (up to 4,096 records waiting), so that the vehicle's mission-protocol replies reach the
/// hand-off at its next tick even when the tracker is behind on telemetry. The checkpoint is the
/// frame of the last record handed out, so a restart reads the waiting ones again.

#include "link/byte_link.hpp"
#include "link/mavlink/wire.hpp"
#include "planner/tracking/fix_source.hpp"

#include <chrono>
#include <deque>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace skylane::link::mavlink {

/// \brief The fused position the autopilot last reported (GLOBAL_POSITION_INT).
struct FusedPosition {
  double lat_rad = 0.0, lon_rad = 0.0, alt_amsl_m = 0.0, relative_alt_m = 0.0;
  std::uint32_t time_boot_ms = 0;
};

/// \brief What the source knows of the vehicle at the other end.
struct VehicleState {
  std::optional<std::uint8_t> sysid;  ///< from its HEARTBEAT
  std::uint8_t compid = 1;
  std::optional<FusedPosition> fused;
};

class MavlinkFixSource final : public planner::FixSource {
 public:
  /// \param flight the fixes' flight (empty: the only flight tracked)
  MavlinkFixSource(std::shared_ptr<ByteLink> link, std::string flight, planner::NmeaPlRisk risk = {});
  planner::SourceRecord next(int timeout_ms) override;
  [[nodiscard]] const std::string& name() const override { return link_->name(); }
  [[nodiscard]] bool live() const override { return link_->live(); }
  [[nodiscard]] bool rereadable() const override { return link_->rereadable(); }
  void resumeAfter(std::size_t line) override { resume_frame_ = returned_frame_ = line; }
  [[nodiscard]] std::size_t checkpointLine() const override;
  [[nodiscard]] std::optional<std::uint64_t> droppedDatagrams() const override { return link_->droppedDatagrams(); }

  [[nodiscard]] const VehicleState& vehicle() const { return vehicle_; }
  [[nodiscard]] const ParserStats& stats() const { return parser_.stats(); }
  /// \brief The link, for a sender that answers on it (the mission upload).
  [[nodiscard]] ByteLink& link() { return *link_; }
  /// \brief Frames other than telemetry (mission protocol replies) since the last call.
  [[nodiscard]] std::deque<Frame> takeOtherFrames();

 private:
  /// A record made, and the frame count when it was made (the checkpoint once it is handed out).
  struct Ready {
    planner::SourceRecord record;
    std::size_t frame;
  };
  /// Parses the whole frames the parser holds into ready_ (mission frames to other_).
  void parseReady();
  /// parseReady, then what the link has now (no waiting), until ready_ is full.
  void readAhead();
  /// Whether to read ahead now: nothing waits, or kReadAheadPeriod has passed since the last time.
  [[nodiscard]] bool readAheadDue();
  /// The first waiting record.
  planner::SourceRecord takeReady();
  /// The record a frame makes, if any.
  std::optional<planner::SourceRecord> handle(const Frame& fr);
  /// A bad record for the garbage and bad checksums counted since the last one, if any.
  std::optional<planner::SourceRecord> parserTrouble();
  planner::SourceRecord fromGps(const Frame& fr);
  /// kEnd, after one bad record for a frame the input cut short.
  planner::SourceRecord endOfInput();

  std::shared_ptr<ByteLink> link_;
  std::string flight_;
  planner::NmeaPlRisk risk_;
  FrameParser parser_;
  VehicleState vehicle_;
  std::deque<Frame> other_;
  std::size_t frame_ = 0, resume_frame_ = 0;
  ParserStats reported_;
  std::deque<Ready> ready_;
  std::size_t returned_frame_ = 0;
  std::vector<std::uint8_t> bytes_;  ///< the last read, reused
  std::chrono::steady_clock::time_point last_read_ahead_{};
  bool ended_ = false, truncation_reported_ = false;
};

}  // namespace skylane::link::mavlink
