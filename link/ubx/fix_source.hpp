#pragma once
/// \file
/// \brief A u-blox receiver as a fix source of the tracking engine (docs/vehicle_link.md §3).
/// Every UBX-NAV-PVT with gnssFixOK, a 3-D fix (or GNSS + dead reckoning) and a valid date and
/// time is a fix. Its protection levels are the receiver's own, from the UBX-NAV-PL of the same
/// epoch (iTOW), converted to the mission's integrity risk by receiverProtectionLevels()
/// (`pl_source` "ubx_pl"). Without a usable NAV-PL they come from hAcc/vAcc by the NMEA GST
/// rule (`pl_source` "ubx_accuracy"), and a NAV-PL that could not be used is named in the fix's
/// note. Garbage and bad checksums are bad records with their counts; other UBX messages are
/// passed over.

#include "link/byte_link.hpp"
#include "link/ubx/ubx.hpp"
#include "planner/tracking/fix_source.hpp"

#include <memory>
#include <optional>
#include <string>
#include <utility>

namespace skylane::link::ubx {

/// \brief The mission's PLs from a receiver's NAV-PL, or why it cannot be used.
struct ReceiverPl {
  std::optional<std::pair<double, double>> hpl_vpl_m;
  std::string why_not;  ///< when not usable
};

/// \brief The conversion rule (docs/vehicle_link.md §3.2). Each axis PL_i bounds that axis's
/// error with probability TMIR (p_r = tmir_coeff·10^tmir_exp / 100 per epoch), read as a
/// two-sided Gaussian bound: σ_i = PL_i / Q⁻¹(p_r/2). The horizontal σ is σ₁ (frame 3: the
/// semi-major axis) or √(σ₁² + σ₂²) (frames 1, 2: two axes whose correlation is not given);
/// HPL = √(−2 ln p_H)·σ_H, VPL = Q⁻¹(p_V/2)·σ₃ (the GST rule), and never below the receiver's
/// own horizontal and vertical PLs. Not usable: an invalid PL, frame 0, or a TMIR outside (0, 1).
[[nodiscard]] ReceiverPl receiverProtectionLevels(const NavPl& pl, const planner::NmeaPlRisk& risk);

class UbxFixSource final : public planner::FixSource {
 public:
  UbxFixSource(std::shared_ptr<ByteLink> link, std::string flight, planner::NmeaPlRisk risk = {});
  planner::SourceRecord next(int timeout_ms) override;
  [[nodiscard]] const std::string& name() const override { return link_->name(); }
  [[nodiscard]] bool live() const override { return link_->live(); }
  [[nodiscard]] bool rereadable() const override { return link_->rereadable(); }
  void resumeAfter(std::size_t line) override { resume_frame_ = line; }
  [[nodiscard]] std::size_t checkpointLine() const override { return frame_; }
  [[nodiscard]] std::optional<std::uint64_t> droppedDatagrams() const override { return link_->droppedDatagrams(); }
  [[nodiscard]] const ParserStats& stats() const { return parser_.stats(); }

 private:
  /// The record of a frame (or of the held NAV-PVT it closes), if any.
  std::optional<planner::SourceRecord> handle(const Frame& fr);
  /// The fix of the held NAV-PVT with the NAV-PL of its epoch, if one came.
  planner::SourceRecord release();
  std::optional<planner::SourceRecord> parserTrouble();

  std::shared_ptr<ByteLink> link_;
  std::string flight_;
  planner::NmeaPlRisk risk_;
  FrameParser parser_;
  std::optional<NavPvt> held_;       ///< a NAV-PVT waiting for its epoch's NAV-PL
  std::size_t held_frame_ = 0;
  std::optional<NavPl> pl_;          ///< the latest NAV-PL
  std::optional<planner::SourceRecord> ready_;  ///< a record made while handling a frame, to return next
  std::size_t frame_ = 0, resume_frame_ = 0;
  ParserStats reported_;
  bool ended_ = false, truncation_reported_ = false;
};

}  // namespace skylane::link::ubx
