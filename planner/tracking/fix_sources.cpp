#include "planner/tracking/fix_source.hpp"

#include "integrity/gnss/rinex_nav.hpp"
#include "integrity/gnss/rinex_obs.hpp"
#include "maps/json_node.hpp"
#include "maps/parse_error.hpp"

#include <algorithm>
#include <charconv>
#include <variant>

namespace skylane::planner {

namespace {

/// The "flight" (or "vehicle") a JSON line names, when the line is a JSON object with that
/// string member, whatever else is wrong with it; empty otherwise.
std::string namedFlight(const std::string& text) {
  try {
    const nlohmann::json j = maps::parseJsonLine(text, "");
    if (!j.is_object()) return {};
    for (const char* key : {"flight", "vehicle"}) {
      const auto it = j.find(key);
      if (it != j.end() && it->is_string()) return it->get<std::string>();
    }
  } catch (const std::exception&) {  // not even JSON: no flight to name
  }
  return {};
}

SourceRecord badRecord(const std::string& name, std::size_t line, const std::string& error) {
  SourceRecord r;
  r.kind = SourceRecord::Kind::kBad;
  r.where = name + ":" + std::to_string(line);
  r.line = line;
  r.error = error;
  return r;
}

SourceRecord fixRecord(TrackFix fix) {
  SourceRecord r;
  r.kind = SourceRecord::Kind::kFix;
  r.fix = std::move(fix);
  return r;
}

/// `r` as a record of `kind` without an error (its fix left as it is: the kind says whether it
/// is one; the strings keep their storage).
void setKind(SourceRecord& r, SourceRecord::Kind kind) {
  r.kind = kind;
  r.where.clear();
  r.line = 0;
  r.error.clear();
  r.flight.clear();
}

/// "input:line" into `out`, its storage reused.
void setWhere(std::string& out, const std::string& input, std::size_t line) {
  out.assign(input);
  out += ':';
  char digits[24];
  const auto r = std::to_chars(digits, digits + sizeof digits, line);
  out.append(digits, r.ptr);
}

SourceRecord kindRecord(SourceRecord::Kind kind) {
  SourceRecord r;
  r.kind = kind;
  return r;
}

std::string tooLong() { return "a line longer than " + std::to_string(kMaxLineBytes) + " bytes"; }

bool blank(const std::string& text) { return text.find_first_not_of(" \t\r") == std::string::npos; }

}  // namespace

SourceRecord JsonLinesFixSource::next(int timeout_ms) {
  SourceRecord r;
  nextInto(timeout_ms, r);
  return r;
}

void JsonLinesFixSource::nextInto(int timeout_ms, SourceRecord& out) {
  for (;;) {
    const LineInput::Status st = in_->next(text_, timeout_ms);
    if (st == LineInput::Status::kEnd) return setKind(out, SourceRecord::Kind::kEnd);
    if (st == LineInput::Status::kTimeout) return setKind(out, SourceRecord::Kind::kIdle);
    ++line_;
    if (line_ <= resume_line_) continue;
    if (st == LineInput::Status::kTooLong) {
      out = badRecord(name(), line_, tooLong());
      return;
    }
    if (blank(text_)) continue;
    setWhere(source_, name(), line_);
    try {
      parseTrackFixLine(text_, source_, out.fix);  // into the record's storage
      setKind(out, SourceRecord::Kind::kFix);
      out.fix.line = line_;
    } catch (const std::exception& e) {
      out = badRecord(name(), line_, e.what());
      out.flight = namedFlight(text_);
    }
    return;
  }
}

std::size_t NmeaFixSource::checkpointLine() const {
  return open_epoch_line_ > 0 ? std::min(line_, open_epoch_line_) : line_;
}

std::optional<SourceRecord> NmeaFixSource::epochRecord(const std::optional<integrity::NmeaFix>& nf, std::size_t first_line) const {
  if (!nf || first_line < resume_line_) return std::nullopt;
  const std::string source = name() + ":" + std::to_string(first_line);
  try {
    TrackFix f = trackFixFromNmea(*nf, source);
    f.line = first_line;
    return fixRecord(std::move(f));
  } catch (const maps::ParseError& e) {
    return badRecord(name(), first_line, e.what());
  }
}

std::optional<SourceRecord> NmeaFixSource::sentence(const std::string& text) {
  const bool replaying = line_ <= resume_line_;
  try {
    const integrity::NmeaSentence s = integrity::parseNmeaSentence(text, name() + ":" + std::to_string(line_));
    if (std::holds_alternative<integrity::NmeaGga>(s)) {
      const std::size_t closed_line = epoch_line_;
      const std::optional<integrity::NmeaFix> closed = nmea_.add(s);
      epoch_line_ = open_epoch_line_ = line_;  // before the checkpoint the closed fix may make
      return epochRecord(closed, closed_line);
    }
    const std::optional<integrity::NmeaFix> closed = nmea_.add(s);
    if (closed) open_epoch_line_ = 0;
    return epochRecord(closed, epoch_line_);
  } catch (const std::exception& e) {
    if (replaying) return std::nullopt;
    return badRecord(name(), line_, e.what());
  }
}

SourceRecord NmeaFixSource::next(int timeout_ms) {
  std::string text;
  for (;;) {
    const LineInput::Status st = in_->next(text, timeout_ms);
    if (st == LineInput::Status::kTimeout) return kindRecord(SourceRecord::Kind::kIdle);
    if (st == LineInput::Status::kEnd) {
      if (flushed_) return kindRecord(SourceRecord::Kind::kEnd);
      flushed_ = true;
      std::optional<integrity::NmeaFix> last;
      try {
        last = nmea_.flush();
      } catch (const std::invalid_argument& e) {  // the last epoch cannot be a fix: said, not fatal
        const std::size_t at = open_epoch_line_ > 0 ? open_epoch_line_ : line_;
        open_epoch_line_ = 0;
        return badRecord(name(), at, e.what());
      }
      open_epoch_line_ = 0;
      if (std::optional<SourceRecord> r = epochRecord(last, epoch_line_)) return std::move(*r);
      continue;
    }
    ++line_;
    if (st == LineInput::Status::kTooLong) {
      if (line_ > resume_line_) return badRecord(name(), line_, tooLong());
      continue;
    }
    if (blank(text)) continue;
    if (std::optional<SourceRecord> r = sentence(text)) return std::move(*r);
  }
}

struct RinexReplayFixSource::Data {
  integrity::ObservationData obs;
  integrity::NavigationData nav;
};

RinexReplayFixSource::RinexReplayFixSource(const std::string& obs_path, const std::vector<std::string>& nav_paths,
                                           integrity::SppConfig cfg)
    : name_(obs_path), data_(std::make_unique<Data>()), cfg_(std::move(cfg)) {
  if (nav_paths.empty()) throw maps::ParseError("--nav", 0, "--nav", "", "a RINEX navigation file for the observation replay");
  data_->obs = integrity::loadRinexObs(obs_path);
  for (const std::string& n : nav_paths) data_->nav.merge(integrity::loadRinexNav(n));
  prior_ = data_->obs.approx_position_ecef;
}

RinexReplayFixSource::~RinexReplayFixSource() = default;

SourceRecord RinexReplayFixSource::next(int /*timeout_ms*/) {
  while (next_epoch_ < data_->obs.epochs.size()) {
    const integrity::ObservationEpoch& ep = data_->obs.epochs[next_epoch_++];
    line_ = static_cast<std::size_t>(ep.source_line);
    if (line_ <= resume_line_) continue;
    const integrity::SppEpoch s = integrity::solveSppEpoch(ep, data_->obs, data_->nav, cfg_, prior_);
    if (!s.solved || !s.pl.pl_computed) {
      return badRecord(name_, line_, "no position or protection level at this epoch: " + s.note);
    }
    prior_ = s.p_ecef;
    TrackFix f;
    f.time = s.t;
    f.lat_rad = s.position.lat_rad;
    f.lon_rad = s.position.lon_rad;
    f.h_ell_m = s.position.h_ell_m;
    f.hpl_m = s.pl.hpl_m;
    f.vpl_m = s.pl.vpl_m;
    f.pl_source = PlSource::kRaw;
    f.source = name_ + ":" + std::to_string(line_);
    f.line = line_;
    return fixRecord(std::move(f));
  }
  return kindRecord(SourceRecord::Kind::kEnd);
}

SourceRecord MemoryFixSource::next(int /*timeout_ms*/) {
  if (next_ >= fixes_.size()) return kindRecord(SourceRecord::Kind::kEnd);
  TrackFix f = fixes_[next_++];
  if (f.line == 0) f.line = next_;
  if (f.source.empty()) f.source = name_ + ":" + std::to_string(f.line);
  return fixRecord(std::move(f));
}

}  // namespace skylane::planner
