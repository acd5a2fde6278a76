#include "link/ubx/fix_source.hpp"

#include "integrity/stats.hpp"
#include "maps/geodesy.hpp"
#include "maps/time.hpp"

#include <cmath>

namespace skylane::link::ubx {
namespace {

constexpr std::uint8_t kValidDate = 0x01, kValidTime = 0x02, kGnssFixOk = 0x01;

planner::SourceRecord bad(const std::string& where, std::size_t line, const std::string& why) {
  planner::SourceRecord r;
  r.kind = planner::SourceRecord::Kind::kBad;
  r.where = where;
  r.line = line;
  r.error = why;
  return r;
}

}  // namespace

ReceiverPl receiverProtectionLevels(const NavPl& pl, const planner::NmeaPlRisk& risk) {
  ReceiverPl out;
  if (pl.pos_valid != 1) {
    out.why_not = "UBX-NAV-PL: position PL not valid (invalidity reason " + std::to_string(pl.pos_invalidity_reason) + ")";
    return out;
  }
  if (pl.pos_frame < 1 || pl.pos_frame > 3) {
    out.why_not = "UBX-NAV-PL: position PL frame " + std::to_string(pl.pos_frame) + " (expected 1, 2 or 3)";
    return out;
  }
  const double p_r = pl.tmir_coeff * std::pow(10.0, pl.tmir_exp) / 100.0;  // TMIR is in % per epoch
  if (!(p_r > 0.0 && p_r < 1.0)) {
    out.why_not = "UBX-NAV-PL: TMIR " + std::to_string(pl.tmir_coeff) + "e" + std::to_string(pl.tmir_exp) +
                  " % is not a probability in (0, 1)";
    return out;
  }
  const double k_r = integrity::normalTailInverse(p_r / 2.0);
  const double pl1 = pl.pl_pos_mm[0] * 1e-3, pl2 = pl.pl_pos_mm[1] * 1e-3, pl3 = pl.pl_pos_mm[2] * 1e-3;
  const double receiver_h = pl.pos_frame == 3 ? pl1 : std::hypot(pl1, pl2);
  const double sigma_h = receiver_h / k_r, sigma_v = pl3 / k_r;
  const double hpl = std::max(receiver_h, std::sqrt(-2.0 * std::log(risk.p_h)) * sigma_h);
  const double vpl = std::max(pl3, integrity::normalTailInverse(risk.p_v / 2.0) * sigma_v);
  out.hpl_vpl_m = std::make_pair(hpl, vpl);
  return out;
}

UbxFixSource::UbxFixSource(std::shared_ptr<ByteLink> link, std::string flight, planner::NmeaPlRisk risk)
    : link_(std::move(link)), flight_(std::move(flight)), risk_(risk) {}

planner::SourceRecord UbxFixSource::release() {
  const NavPvt v = *held_;
  held_.reset();
  const std::string where = link_->name() + ":frame " + std::to_string(held_frame_);
  if (!(v.flags & kGnssFixOk) || (v.fix_type != 3 && v.fix_type != 4)) {
    return bad(where, held_frame_, "UBX-NAV-PVT: fixType " + std::to_string(v.fix_type) + ", gnssFixOK " + std::to_string(v.flags & 1) +
                                       "; expected a valid 3-D fix");
  }
  if ((v.valid & (kValidDate | kValidTime)) != (kValidDate | kValidTime)) {
    return bad(where, held_frame_, "UBX-NAV-PVT: valid " + std::to_string(v.valid) + "; expected a valid date and time (bits 0, 1)");
  }
  planner::SourceRecord r;
  r.kind = planner::SourceRecord::Kind::kFix;
  r.line = held_frame_;
  r.where = where;
  planner::TrackFix& f = r.fix;
  f.flight = flight_;
  f.time = maps::gpsFromUtc({v.year, v.month, v.day, v.hour, v.minute, v.second + v.nano_ns * 1e-9});
  f.lat_rad = maps::deg2rad(v.lat_e7 * 1e-7);
  f.lon_rad = maps::deg2rad(v.lon_e7 * 1e-7);
  f.h_ell_m = v.height_mm * 1e-3;
  f.source = where;
  f.line = held_frame_;
  const ReceiverPl own = pl_ && pl_->itow_ms == v.itow_ms ? receiverProtectionLevels(*pl_, risk_) : ReceiverPl{};
  if (own.hpl_vpl_m) {
    std::tie(f.hpl_m, f.vpl_m) = *own.hpl_vpl_m;
    f.pl_source = planner::PlSource::kUbxPl;
    return r;
  }
  f.note = own.why_not.empty() ? "" : own.why_not + "; PLs from hAcc/vAcc";
  f.hpl_m = std::sqrt(-2.0 * std::log(risk_.p_h)) * v.h_acc_mm * 1e-3;
  f.vpl_m = integrity::normalTailInverse(risk_.p_v / 2.0) * v.v_acc_mm * 1e-3;
  f.pl_source = planner::PlSource::kUbxAccuracy;
  return r;
}

std::optional<planner::SourceRecord> UbxFixSource::handle(const Frame& fr) {
  ++frame_;
  if (frame_ <= resume_frame_ || fr.cls != kClassNav) return std::nullopt;
  if (fr.id == kIdNavPvt) {
    const auto v = decodeNavPvt(fr.payload);
    if (!v) return bad(link_->name() + ":frame " + std::to_string(frame_), frame_, "UBX-NAV-PVT of " + std::to_string(fr.payload.size()) + " bytes; expected 92");
    std::optional<planner::SourceRecord> earlier;
    if (held_) earlier = release();  // the previous epoch had no NAV-PL after it
    held_ = *v;
    held_frame_ = frame_;
    if (!pl_ || pl_->itow_ms != v->itow_ms) return earlier;
    planner::SourceRecord now = release();  // its NAV-PL came first
    if (!earlier) return now;
    ready_ = now;
    return earlier;
  }
  if (fr.id == kIdNavPl) {
    const auto pl = decodeNavPl(fr.payload);
    if (!pl) return bad(link_->name() + ":frame " + std::to_string(frame_), frame_, "UBX-NAV-PL of " + std::to_string(fr.payload.size()) + " bytes; expected 52");
    pl_ = *pl;
    if (held_ && held_->itow_ms == pl->itow_ms) return release();
  }
  return std::nullopt;
}

std::optional<planner::SourceRecord> UbxFixSource::parserTrouble() {
  const ParserStats& s = parser_.stats();
  if (s.skipped_bytes == reported_.skipped_bytes) return std::nullopt;
  std::string why = "UBX: skipped " + std::to_string(s.skipped_bytes - reported_.skipped_bytes) + " byte(s) outside frames";
  if (s.bad_checksum > reported_.bad_checksum) why += ", " + std::to_string(s.bad_checksum - reported_.bad_checksum) + " bad checksum(s)";
  reported_ = s;
  return bad(link_->name() + ":frame " + std::to_string(frame_ + 1), 0, why + "; expected UBX frames (0xB5 0x62 …)");
}

planner::SourceRecord UbxFixSource::next(int timeout_ms) {
  for (;;) {
    if (ready_) {
      planner::SourceRecord r = *ready_;
      ready_.reset();
      return r;
    }
    while (const std::optional<Frame> fr = parser_.next()) {
      if (auto trouble = parserTrouble()) {
        if (auto record = handle(*fr)) ready_ = *record;
        return *trouble;
      }
      if (auto record = handle(*fr)) return *record;
    }
    if (auto trouble = parserTrouble()) return *trouble;
    if (ended_) {
      if (held_) return release();
      if (parser_.pending() > 0 && !truncation_reported_) {
        truncation_reported_ = true;
        return bad(link_->name() + ":frame " + std::to_string(frame_ + 1), 0,
                   "UBX: the input ends inside a frame (" + std::to_string(parser_.pending()) + " byte(s)); expected a whole frame");
      }
      return planner::SourceRecord{};
    }
    std::vector<std::uint8_t> bytes;
    const ByteLink::Status s = link_->read(bytes, timeout_ms);
    if (s == ByteLink::Status::kTimeout) {
      if (held_) return release();  // no NAV-PL came for the last epoch: it goes out as it is
      planner::SourceRecord idle;
      idle.kind = planner::SourceRecord::Kind::kIdle;
      return idle;
    }
    if (s == ByteLink::Status::kEnd) ended_ = true;
    parser_.push(bytes.data(), bytes.size());
  }
}

}  // namespace skylane::link::ubx
