/// \file
/// \brief libFuzzer target for the live-tracking fix inputs (planner/tracking/track_fix.hpp).
/// The input is split into lines and every line is read both ways:
/// - as a JSON-lines fix: nlohmann's parse without exceptions (syntax errors are nlohmann's
///   business and skipped, as in fuzz_mission), then `parseTrackFixJson`;
/// - as an NMEA 0183 sentence (`parseNmeaSentence`) fed to one `NmeaEpochAssembler` with a
///   default date; every epoch it releases goes through `trackFixFromNmea`.
/// Each must return or throw ParseError naming its source ("fuzz.jsonl:<line>",
/// "fuzz.nmea:<line>", "fuzz.nmea epoch <n>"). The direct reading of plain lines
/// (`parsePlainFixLine`) gives a fix only where the general one does, and the same fix. Every
/// line is also read the way a stream reads it, into one fix kept over the whole input
/// (`parseTrackFixLine(text, source, fix)`): the same fix as a fresh reading of the line, or the
/// same error, whatever the lines before it left in the kept fix.
///
/// Every fix that parses: finite latitude and longitude within ±90° and ±180° (in radians), a
/// finite height and time, its own source, both PLs or neither and each ≥ 0, every pseudorange
/// and satellite position finite, an INS block with σ's ≥ 0 whose nominal PLs are ≥ 0.
/// A JSON fix besides: finite PLs, a height within ±100 km, pseudoranges of 1,000–100,000 km,
/// satellite positions 10,000–100,000 km from the Earth's centre, each satellite once, a PL
/// from one of PLs, pseudoranges and imu, and the raw PL source exactly when it has
/// pseudoranges. An NMEA fix: HPL > 0 and VPL ≥ 0 from GST, no pseudoranges, no INS, no flight.

#include "fuzz/fuzz_common.hpp"
#include "integrity/gnss/nmea.hpp"
#include "planner/tracking/track_fix.hpp"

#include <nlohmann/json.hpp>

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <sstream>
#include <string>

namespace {

using namespace skylane;
using nlohmann::json;

void checkFix(const planner::TrackFix& f, const std::string& source) {
  SKYLANE_FUZZ_CHECK(f.source == source, source + ": fix names source '" + f.source + "'");
  SKYLANE_FUZZ_CHECK(std::isfinite(f.lat_rad) && std::isfinite(f.lon_rad), source);
  SKYLANE_FUZZ_CHECK(std::abs(f.lat_rad) <= M_PI / 2 + 1e-12 && std::abs(f.lon_rad) <= M_PI + 1e-12, source);
  SKYLANE_FUZZ_CHECK(std::isfinite(f.h_ell_m) && std::isfinite(f.time.totalSeconds()), source);
  SKYLANE_FUZZ_CHECK(f.hpl_m.has_value() == f.vpl_m.has_value(), source);
  if (f.hpl_m) SKYLANE_FUZZ_CHECK(*f.hpl_m >= 0.0 && *f.vpl_m >= 0.0, source);  // NaN fails too
  for (const integrity::RawRange& r : f.ranges) {
    SKYLANE_FUZZ_CHECK(std::isfinite(r.pr_m), source + ": pseudorange of " + r.sat.str());
    SKYLANE_FUZZ_CHECK(!r.sat_ecef_m || r.sat_ecef_m->allFinite(), source + ": position of " + r.sat.str());
  }
  if (f.ins) {
    const planner::InsUncertainty& u = *f.ins;
    SKYLANE_FUZZ_CHECK(u.grade >= 0 && u.grade <= 2, source);
    SKYLANE_FUZZ_CHECK(u.sigma_n_m >= 0.0 && u.sigma_e_m >= 0.0 && u.sigma_u_m >= 0.0, source);
    const auto [h, v] = planner::insNominalPl(u);
    SKYLANE_FUZZ_CHECK(h >= 0.0 && v >= 0.0, source + ": INS PLs " + std::to_string(h) + ", " + std::to_string(v));
    fuzz::keepAlive(h + v);
  }
  SKYLANE_FUZZ_CHECK(planner::plSourceName(f.pl_source) != nullptr, source);
}

void checkJsonFix(const planner::TrackFix& f, const std::string& source) {
  checkFix(f, source);
  SKYLANE_FUZZ_CHECK(std::abs(f.h_ell_m) <= 1e5, source);
  if (f.hpl_m) SKYLANE_FUZZ_CHECK(std::isfinite(*f.hpl_m) && std::isfinite(*f.vpl_m), source);
  for (std::size_t i = 0; i < f.ranges.size(); ++i) {
    const integrity::RawRange& r = f.ranges[i];
    SKYLANE_FUZZ_CHECK(r.pr_m > 1e6 && r.pr_m < 1e8, source + ": pseudorange of " + r.sat.str());
    if (r.sat_ecef_m) {
      const double d = r.sat_ecef_m->norm();
      SKYLANE_FUZZ_CHECK(d > 1e7 && d < 1e8, source + ": position of " + r.sat.str());
    }
    for (std::size_t k = 0; k < i; ++k) {
      SKYLANE_FUZZ_CHECK(f.ranges[k].sat != r.sat, source + ": " + r.sat.str() + " twice");
    }
  }
  SKYLANE_FUZZ_CHECK(f.hpl_m || !f.ranges.empty() || f.ins, source + ": a fix without a PL source");
  SKYLANE_FUZZ_CHECK((f.pl_source == planner::PlSource::kRaw) == !f.ranges.empty(), source);
  if (f.ranges.empty()) SKYLANE_FUZZ_CHECK(f.pl_source == planner::PlSource::kOnboard, source);
}

void checkNmeaFix(const planner::TrackFix& f, const std::string& source) {
  checkFix(f, source);
  SKYLANE_FUZZ_CHECK(f.hpl_m && *f.hpl_m > 0.0, source + ": an NMEA fix has its HPL from GST");
  SKYLANE_FUZZ_CHECK(f.pl_source == planner::PlSource::kNmeaGst, source);
  SKYLANE_FUZZ_CHECK(f.ranges.empty() && !f.ins && f.flight.empty(), source);
}

}  // namespace

/// The direct reading of a plain line gives a fix only where the general one does, the same.
void checkDirectReading(const std::string& line, const std::string& source, const std::optional<planner::TrackFix>& general) {
  const std::optional<planner::TrackFix> direct = planner::parsePlainFixLine(line, source);
  if (!direct) return;
  SKYLANE_FUZZ_CHECK(general.has_value(), source + ": the direct reading gave a fix the general reading refuses");
  const planner::TrackFix &a = *direct, &b = *general;
  const bool same = a.flight == b.flight && a.time.week == b.time.week && a.time.sow == b.time.sow && a.lat_rad == b.lat_rad &&
                    a.lon_rad == b.lon_rad && a.h_ell_m == b.h_ell_m && a.hpl_m == b.hpl_m && a.vpl_m == b.vpl_m &&
                    a.baro_h_m == b.baro_h_m && a.mag_heading_rad == b.mag_heading_rad && a.pl_source == b.pl_source &&
                    a.ranges.empty() && b.ranges.empty() && !b.ins && !b.imu;
  SKYLANE_FUZZ_CHECK(same, source + ": the direct and the general reading give different fixes");
}

/// Reading the line into `kept` (the stream's way) gives what a fresh reading gives: the same
/// fix, or the same error.
void checkReadingInPlace(const std::string& line, const std::string& source, planner::TrackFix& kept) {
  std::string fresh_error, kept_error;
  std::optional<planner::TrackFix> fresh;
  try {
    fresh = planner::parseTrackFixLine(line, source);
  } catch (const integrity::ParseError& e) {
    fresh_error = e.what();
  }
  try {
    planner::parseTrackFixLine(line, source, kept);
  } catch (const integrity::ParseError& e) {
    kept_error = e.what();
  }
  SKYLANE_FUZZ_CHECK(kept_error == fresh_error, source + ": read in place '" + kept_error + "', fresh '" + fresh_error + "'");
  if (!fresh) return;
  const bool same = planner::trackFixJson(kept) == planner::trackFixJson(*fresh) && kept.source == fresh->source &&
                    kept.note == fresh->note && kept.pl_source == fresh->pl_source && kept.line == fresh->line;
  SKYLANE_FUZZ_CHECK(same, source + ": the fix read in place differs from a fresh reading");
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  integrity::NmeaEpochAssembler assembler(integrity::NmeaDate{{0.0}, 2026, 11, 23});
  int epochs = 0;
  auto fromEpoch = [&epochs](const std::optional<integrity::NmeaFix>& nf) {
    if (!nf) return;
    const std::string source = "fuzz.nmea epoch " + std::to_string(++epochs);
    fuzz::parseThenUse(source, [&] { return planner::trackFixFromNmea(*nf, source); },
                       [&](const planner::TrackFix& f) { checkNmeaFix(f, source); });
  };
  std::istringstream in(text);
  std::string line;
  planner::TrackFix kept;  // read into line after line, as a stream does
  int n = 0;
  while (std::getline(in, line)) {
    ++n;
    const json doc = json::parse(line, nullptr, /*allow_exceptions=*/false);
    const std::string json_source = "fuzz.jsonl:" + std::to_string(n);
    std::optional<planner::TrackFix> general;
    if (!doc.is_discarded()) {
      fuzz::parseThenUse(json_source, [&] { return planner::parseTrackFixJson(doc, json_source); },
                         [&](const planner::TrackFix& f) {
                           checkJsonFix(f, json_source);
                           general = f;
                         });
    }
    checkDirectReading(line, json_source, general);
    checkReadingInPlace(line, json_source, kept);
    const std::string nmea_source = "fuzz.nmea:" + std::to_string(n);
    fuzz::parseThenUse(nmea_source, [&] { return integrity::parseNmeaSentence(line, nmea_source); },
                       [&](const integrity::NmeaSentence& s) { fromEpoch(assembler.add(s)); });
  }
  fromEpoch(assembler.flush());
  return 0;
}
