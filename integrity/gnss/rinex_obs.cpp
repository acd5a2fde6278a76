#include "integrity/gnss/rinex_obs.hpp"

#include "integrity/gnss/almanac.hpp"
#include "integrity/gnss/parse_error.hpp"

#include <cctype>
#include <cmath>
#include <limits>
#include <sstream>

namespace skylane::integrity {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
/// Width of one observation field: F14.3 + LLI + signal strength.
constexpr std::size_t kObsWidth = 16;

std::string label(const std::string& line) { return rinexLabel(line); }

void checkEpoch(const CalendarTime& c, const std::string& src, int ln) {
  if (!isValidCalendar(c)) {
    throw ParseError(src, ln, "epoch", std::to_string(c.year) + "-" + std::to_string(c.month) + "-" +
                                           std::to_string(c.day) + " " + std::to_string(c.hour) + ":" +
                                           std::to_string(c.minute),
                     "a valid date and time");
  }
}

double parseObsValue(const std::string& line, std::size_t pos, const std::string& src, int ln,
                     const std::string& code) {
  const std::string f = field(line, pos, 14);
  return parseFortranReal(f, src, ln, code, kNaN);
}

}  // namespace

std::optional<ObsCode> obsCodeFromRinex2(const std::string& code) {
  if (code.size() != 2 || !std::isdigit(static_cast<unsigned char>(code[1]))) return std::nullopt;
  ObsCode c;
  c.as_written = code;
  c.band = code[1] - '0';
  switch (code[0]) {
    case 'C': c.kind = 'C'; c.attribute = c.band == 1 ? 'C' : 'X'; break;
    case 'P': c.kind = 'C'; c.attribute = 'W'; break;
    case 'L': c.kind = 'L'; c.attribute = c.band == 1 ? 'C' : 'W'; break;
    case 'D': c.kind = 'D'; c.attribute = c.band == 1 ? 'C' : 'W'; break;
    case 'S': c.kind = 'S'; c.attribute = c.band == 1 ? 'C' : 'W'; break;
    default: return std::nullopt;
  }
  return c;
}

std::optional<ObsCode> obsCodeFromRinex3(const std::string& code) {
  if (code == "X1") return ObsCode{'X', 1, ' ', code};  // receiver channel number (RINEX 3.02+)
  if (code.size() != 3 || !std::isdigit(static_cast<unsigned char>(code[1]))) return std::nullopt;
  if (std::string("CLDSX").find(code[0]) == std::string::npos) return std::nullopt;
  ObsCode c;
  c.as_written = code;
  c.kind = code[0];
  c.band = code[1] - '0';
  c.attribute = code[2];
  return c;
}

int findObsType(const std::vector<ObsCode>& types, char kind, int band, const std::string& attributes) {
  if (attributes.empty()) {
    for (std::size_t i = 0; i < types.size(); ++i) {
      if (types[i].kind == kind && types[i].band == band) return static_cast<int>(i);
    }
    return -1;
  }
  for (char a : attributes) {
    for (std::size_t i = 0; i < types.size(); ++i) {
      if (types[i].kind == kind && types[i].band == band && types[i].attribute == a) {
        return static_cast<int>(i);
      }
    }
  }
  return -1;
}

namespace {

/// \brief Where the reader stands in the file and what the first header line announced.
struct ObsReader {
  ObsReader(const std::vector<std::string>& file_lines, const std::string& source)
      : lines(file_lines), src(source) {}
  const std::vector<std::string>& lines;
  const std::string& src;
  std::size_t i = 0;           ///< index of the line being read
  bool v3 = false;             ///< RINEX 3 (else 2)
  char default_system = 'G';   ///< RINEX 2: blank system letter means GPS
  std::vector<ObsCode> v2_types;
};

/// \brief The type counts the header announces (RINEX 2's is checked against the types read
/// once the header ends) and the system a RINEX 3 continuation line belongs to.
struct TypeCounts {
  int v2_expected = -1;
  char v3_sys = ' ';
  int v3_expected = 0;
};

/// \brief The epoch line: time, flag and satellite count.
struct EpochLine {
  ObservationEpoch ep;
  CalendarTime calendar;
  int nsat = 0;
};

void readVersionLine(ObsReader& r, ObservationData& obs) {
  const std::vector<std::string>& L = r.lines;
  const std::string& src = r.src;
  if (L.empty()) throw ParseError(src, 1, "RINEX VERSION / TYPE", "", "a RINEX observation header (file is empty)");
  if (label(L[0]) != "RINEX VERSION / TYPE") {
    throw ParseError(src, 1, "RINEX VERSION / TYPE", trim(L[0]).substr(0, 40), "the 'RINEX VERSION / TYPE' header line");
  }
  obs.version = parseFortranReal(field(L[0], 0, 9), src, 1, "RINEX version");
  r.v3 = obs.version >= 3.0 && obs.version < 4.0;
  if (!r.v3 && !(obs.version >= 2.0 && obs.version < 3.0)) {
    throw ParseError(src, 1, "RINEX version", trim(field(L[0], 0, 9)), "2.xx or 3.0x");
  }
  if (field(L[0], 20, 1) != "O") {
    throw ParseError(src, 1, "file type", field(L[0], 20, 1), "'O' (observation data)");
  }
  const std::string s = field(L[0], 40, 1);
  if (!s.empty() && s != " " && s != "M") r.default_system = s[0];
}

void readV2TypesLine(ObsReader& r, TypeCounts& counts, const std::string& line, int ln) {
  const std::string& src = r.src;
  if (counts.v2_expected < 0) {
    counts.v2_expected = parseInt(field(line, 0, 6), src, ln, "# / TYPES OF OBSERV");
    if (counts.v2_expected < 1 || counts.v2_expected > 99) {
      throw ParseError(src, ln, "# / TYPES OF OBSERV", std::to_string(counts.v2_expected), "1 to 99 types");
    }
  }
  for (int k = 0; k < 9 && static_cast<int>(r.v2_types.size()) < counts.v2_expected; ++k) {
    const std::string code = trim(field(line, 10 + 6 * k, 2));
    const auto c = obsCodeFromRinex2(code);
    if (!c) throw ParseError(src, ln, "# / TYPES OF OBSERV", code, "a RINEX 2 observation code such as C1, P2, L1");
    r.v2_types.push_back(*c);
  }
}

void readV3TypesLine(const ObsReader& r, TypeCounts& counts, const std::string& line, int ln,
                     ObservationData& obs) {
  const std::string& src = r.src;
  const std::string sys = field(line, 0, 1);
  if (!sys.empty() && sys != " ") {
    counts.v3_sys = sys[0];
    counts.v3_expected = parseInt(field(line, 3, 3), src, ln, "SYS / # / OBS TYPES count");
    if (counts.v3_expected < 1 || counts.v3_expected > 99) {
      throw ParseError(src, ln, "SYS / # / OBS TYPES count", std::to_string(counts.v3_expected), "1 to 99 types");
    }
  }
  const auto cons = constellationFromLetter(counts.v3_sys);
  std::vector<ObsCode> parsed;
  for (int k = 0; k < 13; ++k) {
    const std::string code = trim(field(line, 7 + 4 * k, 3));
    if (code.empty()) break;
    const auto c = obsCodeFromRinex3(code);
    if (!c) throw ParseError(src, ln, "SYS / # / OBS TYPES", code, "a RINEX 3 observation code such as C1C");
    parsed.push_back(*c);
  }
  if (cons) {
    auto& dst = obs.types[static_cast<int>(*cons)];
    dst.insert(dst.end(), parsed.begin(), parsed.end());
  }
}

void readHeaderLine(ObsReader& r, TypeCounts& counts, const std::string& lab, ObservationData& obs) {
  const std::string& line = r.lines[r.i];
  const int ln = static_cast<int>(r.i + 1);
  if (lab == "MARKER NAME") {
    obs.marker_name = trim(field(line, 0, 60));
  } else if (lab == "APPROX POSITION XYZ") {
    Eigen::Vector3d p;
    for (int k = 0; k < 3; ++k) p[k] = parseFortranReal(field(line, 14 * k, 14), r.src, ln, "APPROX POSITION XYZ");
    obs.approx_position_ecef = p;
  } else if (lab == "INTERVAL") {
    obs.interval_s = parseFortranReal(field(line, 0, 10), r.src, ln, "INTERVAL");
  } else if (!r.v3 && lab == "# / TYPES OF OBSERV") {
    readV2TypesLine(r, counts, line, ln);
  } else if (r.v3 && lab == "SYS / # / OBS TYPES") {
    readV3TypesLine(r, counts, line, ln, obs);
  }
}

/// \brief Reads the header up to END OF HEADER; leaves the reader on the first data line.
void readHeader(ObsReader& r, ObservationData& obs) {
  TypeCounts counts;
  for (r.i = 1; r.i < r.lines.size(); ++r.i) {
    const std::string lab = label(r.lines[r.i]);
    if (lab == "END OF HEADER") break;
    readHeaderLine(r, counts, lab, obs);
  }
  const std::size_t i = r.i;
  if (i == r.lines.size()) throw ParseError(r.src, static_cast<int>(i), "END OF HEADER", "", "the end of the header");
  if (!r.v3) {
    if (r.v2_types.empty()) throw ParseError(r.src, static_cast<int>(i + 1), "# / TYPES OF OBSERV", "", "observation types in the header");
    if (static_cast<int>(r.v2_types.size()) != counts.v2_expected) {
      throw ParseError(r.src, static_cast<int>(i + 1), "# / TYPES OF OBSERV", std::to_string(r.v2_types.size()),
                       std::to_string(counts.v2_expected) + " types as announced");
    }
    for (Constellation c : kAllConstellations) obs.types[static_cast<int>(c)] = r.v2_types;
  }
  ++r.i;
}

EpochLine readEpochLineV3(const std::string& line, const std::string& src, int ln) {
  EpochLine e;
  CalendarTime& c = e.calendar;
  if (line[0] != '>') throw ParseError(src, ln, "epoch record", trim(line).substr(0, 30), "a '>' epoch line");
  c.year = parseInt(field(line, 2, 4), src, ln, "epoch year");
  c.month = parseInt(field(line, 7, 2), src, ln, "epoch month");
  c.day = parseInt(field(line, 10, 2), src, ln, "epoch day");
  c.hour = parseInt(field(line, 13, 2), src, ln, "epoch hour");
  c.minute = parseInt(field(line, 16, 2), src, ln, "epoch minute");
  c.second = parseFortranReal(field(line, 18, 11), src, ln, "epoch second");
  e.ep.flag = parseInt(field(line, 31, 1), src, ln, "epoch flag");
  e.nsat = parseInt(field(line, 32, 3), src, ln, "number of satellites");
  return e;
}

EpochLine readEpochLineV2(const std::string& line, const std::string& src, int ln) {
  EpochLine e;
  CalendarTime& c = e.calendar;
  c.year = rinexFullYear(parseInt(field(line, 1, 2), src, ln, "epoch year"));
  c.month = parseInt(field(line, 4, 2), src, ln, "epoch month");
  c.day = parseInt(field(line, 7, 2), src, ln, "epoch day");
  c.hour = parseInt(field(line, 10, 2), src, ln, "epoch hour");
  c.minute = parseInt(field(line, 13, 2), src, ln, "epoch minute");
  c.second = parseFortranReal(field(line, 15, 11), src, ln, "epoch second");
  e.ep.flag = parseInt(field(line, 28, 1), src, ln, "epoch flag");
  e.nsat = parseInt(field(line, 29, 3), src, ln, "number of satellites");
  return e;
}

/// \brief RINEX 2: the satellite list of the epoch line and its continuation lines; leaves
/// the reader on the first observation line.
std::vector<std::string> readV2SatelliteList(ObsReader& r, int nsat) {
  std::vector<std::string> sat_list;
  std::size_t row = r.i;
  for (int k = 0; k < nsat; ++k) {
    if (k > 0 && k % 12 == 0) {
      ++row;
      if (row >= r.lines.size()) throw ParseError(r.src, static_cast<int>(row + 1), "satellite list", "", "a continuation line");
    }
    std::string s = field(r.lines[row], 32 + 3 * static_cast<std::size_t>(k % 12), 3);
    if (trim(s).empty()) throw ParseError(r.src, static_cast<int>(row + 1), "satellite list", "", std::to_string(nsat) + " satellites");
    if (s[0] == ' ') s[0] = r.default_system;
    sat_list.push_back(s);
  }
  r.i = row + 1;
  return sat_list;
}

/// \brief RINEX 2: one satellite's observations, five to a line.
SatObservation readV2SatObservation(ObsReader& r, const std::string& sat, int ln) {
  const std::vector<ObsCode>& types = r.v2_types;
  const std::size_t nt = types.size();
  const auto id = parseSatId(sat);
  if (!id) throw ParseError(r.src, ln, "satellite list", sat, "satellite ids like G05");
  SatObservation so;
  so.sat = *id;
  so.values.assign(nt, kNaN);
  for (std::size_t t = 0; t < nt; ++t) {
    const std::size_t row = r.i + t / 5;
    if (row >= r.lines.size()) throw ParseError(r.src, static_cast<int>(row + 1), types[t].as_written, "", "an observation line (file is truncated)");
    so.values[t] = parseObsValue(r.lines[row], kObsWidth * (t % 5), r.src, static_cast<int>(row + 1), types[t].as_written);
  }
  r.i += (nt + 4) / 5;
  return so;
}

void readV2Satellites(ObsReader& r, int nsat, int ln, ObservationEpoch& ep) {
  const std::vector<std::string> sat_list = readV2SatelliteList(r, nsat);
  for (int k = 0; k < nsat; ++k) {
    SatObservation so = readV2SatObservation(r, sat_list[static_cast<std::size_t>(k)], ln);
    const auto cons = so.sat.constellation;
    if (cons == Constellation::kGps || cons == Constellation::kGalileo || cons == Constellation::kGlonass ||
        cons == Constellation::kBeidou) {
      ep.sats.push_back(std::move(so));
    }
  }
}

/// \brief RINEX 3: one line per satellite; systems skylane does not use are counted and skipped.
void readV3Satellites(ObsReader& r, int nsat, ObservationData& obs, ObservationEpoch& ep) {
  const std::string& src = r.src;
  ++r.i;
  for (int k = 0; k < nsat; ++k, ++r.i) {
    if (r.i >= r.lines.size()) throw ParseError(src, static_cast<int>(r.i + 1), "observation record", "", std::to_string(nsat) + " satellite lines (file is truncated)");
    const std::string& sl = r.lines[r.i];
    const int sln = static_cast<int>(r.i + 1);
    const auto id = parseSatId(field(sl, 0, 3));
    if (!id) {
      const std::string sys = field(sl, 0, 1);
      if (!sys.empty() && std::isalpha(static_cast<unsigned char>(sys[0]))) {  // SBAS, QZSS, IRNSS
        ++obs.skipped_satellites;
        continue;
      }
      throw ParseError(src, sln, "satellite", field(sl, 0, 3), "a satellite id like G05 or E11");
    }
    const auto& types = obs.types[static_cast<int>(id->constellation)];
    if (types.empty()) throw ParseError(src, sln, "satellite", id->str(), "a system listed in SYS / # / OBS TYPES");
    SatObservation so;
    so.sat = *id;
    so.values.assign(types.size(), kNaN);
    for (std::size_t t = 0; t < types.size(); ++t) {
      so.values[t] = parseObsValue(sl, 3 + kObsWidth * t, src, sln, types[t].as_written);
    }
    ep.sats.push_back(std::move(so));
  }
}

/// \brief One epoch record from the reader's line on: an event record (flag 2 to 6) is
/// skipped with its special records, an observation epoch is appended to `obs`.
void readEpoch(ObsReader& r, ObservationData& obs) {
  const std::string& line = r.lines[r.i];
  const int ln = static_cast<int>(r.i + 1);
  EpochLine e = r.v3 ? readEpochLineV3(line, r.src, ln) : readEpochLineV2(line, r.src, ln);
  e.ep.source_line = ln;
  if (e.nsat < 0 || e.nsat > 999) throw ParseError(r.src, ln, "number of satellites", std::to_string(e.nsat), "0 to 999");
  if (e.ep.flag > 1) {  // event: the count gives the number of special records that follow
    if (e.ep.flag > 6) throw ParseError(r.src, ln, "epoch flag", std::to_string(e.ep.flag), "0 to 6");
    r.i += 1 + static_cast<std::size_t>(e.nsat);
    return;
  }
  checkEpoch(e.calendar, r.src, ln);
  e.ep.t = gpsFromCalendar(e.calendar);
  if (!r.v3) {
    readV2Satellites(r, e.nsat, ln, e.ep);
  } else {
    readV3Satellites(r, e.nsat, obs, e.ep);
  }
  obs.epochs.push_back(std::move(e.ep));
}

}  // namespace

ObservationData parseRinexObs(const std::string& text, const std::string& src) {
  const std::vector<std::string> lines = splitLines(text);
  ObsReader r(lines, src);
  ObservationData obs;
  readVersionLine(r, obs);
  readHeader(r, obs);
  while (r.i < lines.size()) {
    if (trim(lines[r.i]).empty()) {
      ++r.i;
      continue;
    }
    readEpoch(r, obs);
  }
  return obs;
}

ObservationData loadRinexObs(const std::string& path) { return parseRinexObs(readTextFile(path), path); }

}  // namespace skylane::integrity
