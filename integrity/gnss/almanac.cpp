#include "integrity/gnss/almanac.hpp"

#include "integrity/gnss/parse_error.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <fstream>
#include <limits>
#include <sstream>

namespace skylane::integrity {
namespace {

constexpr double kSemicircle_rad = M_PI;
/// MAAST numbers Galileo almanac entries from 75 (PRN = ID − 74).
constexpr int kMaastGalileoIdOffset = 74;
/// Largest almanac ID: MAAST's Galileo 75 … 110 plus margin; PRNs are then checked to 1 … 99.
constexpr int kMaxAlmanacId = 173;
/// GPS weeks beyond this (year 2171) are taken as corrupt input.
constexpr int kMaxWeek = 10000;

SatId assignSat(int id, bool header_says_galileo, AlmanacSystem system) {
  SatId sat;
  const bool galileo = system == AlmanacSystem::kGalileo ||
                       (system == AlmanacSystem::kAuto && (header_says_galileo || id > kMaastGalileoIdOffset));
  sat.constellation = galileo ? Constellation::kGalileo : Constellation::kGps;
  sat.prn = (galileo && id > kMaastGalileoIdOffset) ? id - kMaastGalileoIdOffset : id;
  return sat;
}

void checkOrbit(const AlmanacRecord& r, const std::string& source) {
  if (!(r.orbit.e >= 0.0 && r.orbit.e < 1.0)) {
    throw ParseError(source, r.source_line, "eccentricity", std::to_string(r.orbit.e), "a value in [0, 1)");
  }
  if (!(r.orbit.sqrt_a > 1000.0 && r.orbit.sqrt_a < 10000.0)) {
    throw ParseError(source, r.source_line, "sqrt(A)", std::to_string(r.orbit.sqrt_a),
                     "a GNSS orbit's square root of semi-major axis between 1000 and 10000 m^1/2");
  }
  if (!(r.orbit.toe.sow >= 0.0 && r.orbit.toe.sow <= kSecondsPerWeek)) {
    throw ParseError(source, r.source_line, "time of applicability", std::to_string(r.orbit.toe.sow),
                     "seconds of week in [0, 604800]");
  }
  if (r.sat.prn < 1 || r.sat.prn > 99) {
    throw ParseError(source, r.source_line, "ID", std::to_string(r.sat.prn), "a PRN between 1 and 99");
  }
}

}  // namespace

std::vector<AlmanacRecord> parseYuma(const std::string& text, const std::string& source,
                                     AlmanacSystem system) {
  // Field order of a YUMA record (labels vary slightly between producers, values follow ':').
  static const char* const kLabels[] = {"ID",   "Health", "Eccentricity", "Time of Applicability",
                                        "Orbital Inclination", "Rate of Right Ascen", "SQRT(A)",
                                        "Right Ascen at", "Argument of Perigee", "Mean Anom",
                                        "Af0", "Af1", "week"};
  constexpr int kFields = 13;
  const auto lines = splitLines(text);
  std::vector<AlmanacRecord> out;
  std::size_t i = 0;
  while (i < lines.size()) {
    const std::string t = trim(lines[i]);
    if (t.empty()) { ++i; continue; }
    if (t.rfind("****", 0) != 0) {
      throw ParseError(source, static_cast<int>(i + 1), "record header", t,
                       "a '******** Week … almanac for PRN-nn ********' line");
    }
    const bool header_gal = t.find("GAL") != std::string::npos || t.find("SVID") != std::string::npos;
    AlmanacRecord r;
    r.source_line = static_cast<int>(i + 1);
    double v[kFields];
    int line_of[kFields];
    for (int f = 0; f < kFields; ++f) {
      ++i;
      const int ln = static_cast<int>(i + 1);
      line_of[f] = ln;
      if (i >= lines.size()) {
        throw ParseError(source, ln, kLabels[f], "", "the record to continue (file is truncated)");
      }
      const std::string& line = lines[i];
      const auto colon = line.find(':');
      const std::string label = trim(line.substr(0, colon == std::string::npos ? 0 : colon));
      if (colon == std::string::npos || label.rfind(kLabels[f], 0) != 0) {
        throw ParseError(source, ln, kLabels[f], trim(line), std::string("a '") + kLabels[f] + ": value' line");
      }
      v[f] = parseFortranReal(line.substr(colon + 1), source, ln, kLabels[f],
                              std::numeric_limits<double>::quiet_NaN());
      if (std::isnan(v[f])) throw ParseError(source, ln, kLabels[f], "", "a number");
    }
    ++i;
    const int id = integerField(v[0], 1, kMaxAlmanacId, source, line_of[0], kLabels[0]);
    r.sat = assignSat(id, header_gal, system);
    r.health = integerField(v[1], 0, 255, source, line_of[1], kLabels[1]);
    r.orbit.constellation = r.sat.constellation;
    r.orbit.e = v[2];
    r.orbit.toe.sow = v[3];
    r.orbit.i0_rad = v[4];
    r.orbit.omega_dot_radps = v[5];
    r.orbit.sqrt_a = v[6];
    r.orbit.omega0_rad = v[7];
    r.orbit.omega_rad = v[8];
    r.orbit.m0_rad = v[9];
    r.af0_s = v[10];
    r.af1_sps = v[11];
    r.week_field = integerField(v[12], 0, kMaxWeek, source, line_of[12], kLabels[12]);
    r.orbit.toe.week = r.week_field;
    checkOrbit(r, source);
    out.push_back(r);
  }
  if (out.empty()) throw ParseError(source, 0, "almanac", "", "at least one YUMA record");
  return out;
}

std::vector<AlmanacRecord> parseSem(const std::string& text, const std::string& source,
                                    AlmanacSystem system) {
  // Tokenise keeping line numbers: SEM is whitespace-separated with a fixed token order.
  struct Token { std::string text; int line; };
  std::vector<Token> tok;
  const auto lines = splitLines(text);
  for (std::size_t i = 0; i < lines.size(); ++i) {
    std::istringstream in(lines[i]);
    std::string w;
    while (in >> w) tok.push_back({w, static_cast<int>(i + 1)});
  }
  std::size_t k = 0;
  auto next = [&](const char* name) -> const Token& {
    if (k >= tok.size()) {
      throw ParseError(source, static_cast<int>(lines.size()), name, "", "more data (file is truncated)");
    }
    return tok[k++];
  };
  auto real = [&](const char* name) {
    const Token& t = next(name);
    return parseFortranReal(t.text, source, t.line, name);
  };
  auto integer = [&](const char* name) {
    const Token& t = next(name);
    return parseInt(t.text, source, t.line, name);
  };
  const int count = integer("number of records");
  if (count < 1 || count > 64) {
    throw ParseError(source, 1, "number of records", std::to_string(count), "1 to 64 records");
  }
  // The rest of line 1 is a free title; the week is the first token on line 2.
  while (k < tok.size() && tok[k].line == 1) ++k;
  const Token& week_tok = tok[std::min(k, tok.size() - 1)];
  const int week = integer("week");
  if (week < 0 || week > kMaxWeek) {
    throw ParseError(source, week_tok.line, "week", std::to_string(week), "a GPS week in [0, 10000]");
  }
  const double toa = real("time of applicability");
  std::vector<AlmanacRecord> out;
  for (int n = 0; n < count; ++n) {
    AlmanacRecord r;
    r.source_line = k < tok.size() ? tok[k].line : static_cast<int>(lines.size());
    const int id = integer("PRN");
    integer("SVN");
    integer("URA index");
    r.sat = assignSat(id, false, system);
    r.orbit.constellation = r.sat.constellation;
    r.orbit.e = real("eccentricity");
    r.orbit.i0_rad = (0.30 + real("inclination offset")) * kSemicircle_rad;
    r.orbit.omega_dot_radps = real("rate of right ascension") * kSemicircle_rad;
    r.orbit.sqrt_a = real("sqrt(A)");
    r.orbit.omega0_rad = real("right ascension") * kSemicircle_rad;
    r.orbit.omega_rad = real("argument of perigee") * kSemicircle_rad;
    r.orbit.m0_rad = real("mean anomaly") * kSemicircle_rad;
    r.af0_s = real("af0");
    r.af1_sps = real("af1");
    r.health = integer("health");
    integer("configuration");
    r.week_field = week;
    r.orbit.toe = {week, toa};
    checkOrbit(r, source);
    out.push_back(r);
  }
  if (k != tok.size()) {
    throw ParseError(source, tok[k].line, "record count", std::to_string(count),
                     "the number of records announced on line 1 (extra data follows)");
  }
  return out;
}

std::vector<AlmanacRecord> loadAlmanac(const std::string& path, AlmanacSystem system) {
  const std::string text = readTextFile(path);
  const auto first = text.find_first_not_of(" \t\r\n");
  if (first != std::string::npos && text[first] == '*') return parseYuma(text, path, system);
  if (first != std::string::npos && std::isdigit(static_cast<unsigned char>(text[first]))) {
    return parseSem(text, path, system);
  }
  throw ParseError(path, 1, "format", first == std::string::npos ? "" : text.substr(first, 20),
                   "a YUMA ('********') or SEM (record count) almanac");
}

GpsTime resolveAlmanacEpoch(int week_field, double toa_s, const GpsTime& near) {
  if (week_field >= kAlmanacWeekModulus) return GpsTime{week_field, toa_s};
  // The roll-over count that brings t_oa nearest to `near` (never before week_field itself).
  const double rollovers = std::round((near.totalSeconds() - GpsTime{week_field, toa_s}.totalSeconds()) /
                                      (kAlmanacWeekModulus * kSecondsPerWeek));
  // (NaN, from a time that is not one, is taken as no roll-over: its cast would be undefined.)
  const int k = std::isfinite(rollovers) ? static_cast<int>(std::clamp(rollovers, 0.0, 1e6)) : 0;
  return GpsTime{week_field + k * kAlmanacWeekModulus, toa_s};
}

SatelliteState almanacState(const AlmanacRecord& rec, const GpsTime& t) {
  KeplerOrbit orbit = rec.orbit;
  orbit.toe = resolveAlmanacEpoch(rec.week_field, rec.orbit.toe.sow, t);
  const OrbitState o = keplerPosition(orbit, t);
  SatelliteState s;
  s.sat = rec.sat;
  s.p_ecef = o.p_ecef;
  s.relativistic_s = relativisticClock(orbit, o.eccentric_anomaly_rad);
  s.clock_s = rec.af0_s + rec.af1_sps * (t - orbit.toe) + s.relativistic_s;
  return s;
}

}  // namespace skylane::integrity
