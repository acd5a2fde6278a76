#include "link/mavlink/fix_source.hpp"

#include "integrity/stats.hpp"
#include "maps/geodesy.hpp"
#include "maps/geoid.hpp"
#include "maps/time.hpp"

#include <chrono>
#include <cmath>

namespace skylane::link::mavlink {
namespace {

/// GPS_RAW_INT.fix_type of a 3-D fix (GPS_FIX_TYPE_3D_FIX; DGPS, RTK … are higher).
constexpr std::uint8_t kFix3d = 3;
/// A time_usec below this (2001-09-09) counts from boot, not from the UNIX epoch.
constexpr std::uint64_t kUnixTimeFloor_us = 1000000000ULL * 1000000ULL;
/// Seconds from the UNIX epoch to the GPS epoch (1980-01-06T00:00:00Z).
constexpr double kGpsEpochUnix_s = 315964800.0;
constexpr double kWeek_s = 604800.0;
/// Mission-protocol frames kept for the hand-off between two ticks.
constexpr std::size_t kMaxOtherFrames = 256;
/// Records read ahead of the session at most (a live link's backlog beyond stays in the kernel).
constexpr std::size_t kMaxReady = 4096;
/// While records wait, a live link is looked at again no sooner than this: a reply behind a
/// backlog is read within it, and the tracking does not ask the kernel once per record.
constexpr std::chrono::milliseconds kReadAheadPeriod{10};

/// The GPS time of a UTC instant given in microseconds since the UNIX epoch (leap seconds applied).
maps::GpsTime gpsFromUnix(std::uint64_t time_usec) {
  const double s = static_cast<double>(time_usec / 1000000ULL) - kGpsEpochUnix_s;
  const double frac = static_cast<double>(time_usec % 1000000ULL) * 1e-6;
  const int week = static_cast<int>(std::floor(s / kWeek_s));
  const maps::GpsTime calendar_only{week, s - week * kWeek_s + frac};  // UTC on the GPS scale, no leap seconds
  return maps::gpsFromUtc(maps::calendarFromGps(calendar_only));
}

}  // namespace

MavlinkFixSource::MavlinkFixSource(std::shared_ptr<ByteLink> link, std::string flight, planner::NmeaPlRisk risk)
    : link_(std::move(link)), flight_(std::move(flight)), risk_(risk) {}

std::deque<Frame> MavlinkFixSource::takeOtherFrames() {
  std::deque<Frame> out;
  out.swap(other_);
  return out;
}

std::optional<planner::SourceRecord> MavlinkFixSource::parserTrouble() {
  const ParserStats& s = parser_.stats();
  if (s.skipped_bytes == reported_.skipped_bytes && s.bad_crc == reported_.bad_crc && s.bad_length == reported_.bad_length) {
    return std::nullopt;
  }
  planner::SourceRecord r;
  r.kind = planner::SourceRecord::Kind::kBad;
  r.where = link_->name() + ":frame " + std::to_string(frame_ + 1);
  std::string what;
  const auto part = [&what](std::uint64_t n, const char* text) {
    if (n > 0) what += (what.empty() ? "" : ", ") + std::to_string(n) + text;
  };
  part(s.bad_crc - reported_.bad_crc, " frame(s) with a bad checksum");
  part(s.bad_length - reported_.bad_length, " frame(s) longer than their message");
  part(s.skipped_bytes - reported_.skipped_bytes, " byte(s) outside any frame");
  r.error = "MAVLink: skipped " + what + "; expected MAVLink 1/2 frames with known message ids";
  reported_ = s;
  return r;
}

planner::SourceRecord MavlinkFixSource::fromGps(const Frame& fr) {
  planner::SourceRecord r;
  r.line = frame_;
  r.where = link_->name() + ":frame " + std::to_string(frame_);
  const MessageDef& d = *fr.def;
  const auto fail = [&](const std::string& field, const std::string& value, const std::string& expected) {
    r.kind = planner::SourceRecord::Kind::kBad;
    r.error = d.name + "." + field + ": got " + value + ", expected " + expected;
    return r;
  };
  const auto fix_type = fr.get<std::uint8_t>(d.field("fix_type"));
  if (fix_type < kFix3d) return fail("fix_type", std::to_string(fix_type), "a 3-D fix (3 or more)");
  const auto t_us = fr.get<std::uint64_t>(d.field("time_usec"));
  if (t_us < kUnixTimeFloor_us) return fail("time_usec", std::to_string(t_us), "microseconds since the UNIX epoch (a GNSS time)");
  const auto h_acc = fr.get<std::uint32_t>(d.field("h_acc")), v_acc = fr.get<std::uint32_t>(d.field("v_acc"));
  if (h_acc == 0 || v_acc == 0) return fail("h_acc/v_acc", std::to_string(h_acc) + "/" + std::to_string(v_acc), "accuracy estimates > 0 mm");
  planner::TrackFix& f = r.fix;
  f.flight = flight_;
  f.time = gpsFromUnix(t_us);
  f.lat_rad = maps::deg2rad(fr.get<std::int32_t>(d.field("lat")) * 1e-7);
  f.lon_rad = maps::deg2rad(fr.get<std::int32_t>(d.field("lon")) * 1e-7);
  const auto alt_ellipsoid = fr.get<std::int32_t>(d.field("alt_ellipsoid"));
  f.h_ell_m = alt_ellipsoid != 0 ? alt_ellipsoid * 1e-3
                                 : maps::Geoid::egm96().ellipsoidalFromAmsl_m(f.lat_rad, f.lon_rad, fr.get<std::int32_t>(d.field("alt")) * 1e-3);
  f.hpl_m = std::sqrt(-2.0 * std::log(risk_.p_h)) * h_acc * 1e-3;
  f.vpl_m = integrity::normalTailInverse(risk_.p_v / 2.0) * v_acc * 1e-3;
  f.pl_source = planner::PlSource::kMavlinkAccuracy;
  f.source = r.where;
  f.line = frame_;
  r.kind = planner::SourceRecord::Kind::kFix;
  return r;
}

std::optional<planner::SourceRecord> MavlinkFixSource::handle(const Frame& fr) {
  ++frame_;
  if (frame_ <= resume_frame_) return std::nullopt;  // processed before a restart
  switch (fr.msgid) {
    case kHeartbeat:
      if (!vehicle_.sysid) vehicle_.sysid = fr.sysid, vehicle_.compid = fr.compid;
      return std::nullopt;
    case kGlobalPositionInt: {
      const MessageDef& d = *fr.def;
      vehicle_.fused = FusedPosition{maps::deg2rad(fr.get<std::int32_t>(d.field("lat")) * 1e-7),
                                     maps::deg2rad(fr.get<std::int32_t>(d.field("lon")) * 1e-7),
                                     fr.get<std::int32_t>(d.field("alt")) * 1e-3, fr.get<std::int32_t>(d.field("relative_alt")) * 1e-3,
                                     fr.get<std::uint32_t>(d.field("time_boot_ms"))};
      return std::nullopt;
    }
    case kGpsRawInt:
    case kGps2Raw:
      return fromGps(fr);
    default:
      // Mission-protocol frames wait for the hand-off's next tick; without one (a recording,
      // --no-handoff) only the latest few are kept.
      if (other_.size() >= kMaxOtherFrames) other_.pop_front();
      other_.push_back(fr);
      return std::nullopt;
  }
}

void MavlinkFixSource::parseReady() {
  while (ready_.size() < kMaxReady) {
    const std::optional<Frame> fr = parser_.next();
    if (!fr) return;
    // Garbage the parser skipped before this frame is reported first, numbered as the frame.
    if (auto trouble = parserTrouble()) ready_.push_back({std::move(*trouble), frame_});
    if (auto record = handle(*fr)) ready_.push_back({std::move(*record), frame_});
  }
}

bool MavlinkFixSource::readAheadDue() {
  if (ready_.empty()) return true;
  const auto now = std::chrono::steady_clock::now();
  return now - last_read_ahead_ >= kReadAheadPeriod;
}

void MavlinkFixSource::readAhead() {
  last_read_ahead_ = std::chrono::steady_clock::now();
  parseReady();
  while (!ended_ && ready_.size() < kMaxReady) {
    bytes_.clear();
    const ByteLink::Status s = link_->read(bytes_, 0);
    if (s == ByteLink::Status::kTimeout) return;
    if (s == ByteLink::Status::kEnd) ended_ = true;
    parser_.push(bytes_.data(), bytes_.size());
    parseReady();
  }
}

planner::SourceRecord MavlinkFixSource::takeReady() {
  Ready r = std::move(ready_.front());
  ready_.pop_front();
  returned_frame_ = r.frame;
  return std::move(r.record);
}

std::size_t MavlinkFixSource::checkpointLine() const { return ready_.empty() ? frame_ : returned_frame_; }

planner::SourceRecord MavlinkFixSource::next(int timeout_ms) {
  for (;;) {
    // A live link is read ahead: the mission protocol's frames behind a backlog of telemetry
    // reach the hand-off at its next tick, not after every fix before them has been tracked.
    if (link_->live() && readAheadDue()) readAhead();
    if (!ready_.empty()) return takeReady();
    if (auto trouble = parserTrouble()) return *trouble;
    if (ended_) return endOfInput();
    bytes_.clear();
    const ByteLink::Status s = link_->read(bytes_, timeout_ms);
    if (s == ByteLink::Status::kTimeout) {
      planner::SourceRecord idle;
      idle.kind = planner::SourceRecord::Kind::kIdle;
      return idle;
    }
    if (s == ByteLink::Status::kEnd) ended_ = true;
    parser_.push(bytes_.data(), bytes_.size());
    parseReady();
  }
}

planner::SourceRecord MavlinkFixSource::endOfInput() {
  planner::SourceRecord r;  // kEnd
  if (parser_.pending() > 0 && !truncation_reported_) {
    truncation_reported_ = true;
    r.kind = planner::SourceRecord::Kind::kBad;
    r.where = link_->name() + ":frame " + std::to_string(frame_ + 1);
    r.error = "MAVLink: the input ends inside a frame (" + std::to_string(parser_.pending()) + " byte(s) of it); expected a whole frame";
  }
  return r;
}

}  // namespace skylane::link::mavlink
