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

ObservationData parseRinexObs(const std::string& text, const std::string& src) {
  const std::vector<std::string> L = splitLines(text);
  ObservationData obs;
  if (L.empty()) throw ParseError(src, 1, "RINEX VERSION / TYPE", "", "a RINEX observation header (file is empty)");
  if (label(L[0]) != "RINEX VERSION / TYPE") {
    throw ParseError(src, 1, "RINEX VERSION / TYPE", trim(L[0]).substr(0, 40), "the 'RINEX VERSION / TYPE' header line");
  }
  obs.version = parseFortranReal(field(L[0], 0, 9), src, 1, "RINEX version");
  const bool v3 = obs.version >= 3.0 && obs.version < 4.0;
  if (!v3 && !(obs.version >= 2.0 && obs.version < 3.0)) {
    throw ParseError(src, 1, "RINEX version", trim(field(L[0], 0, 9)), "2.xx or 3.0x");
  }
  if (field(L[0], 20, 1) != "O") {
    throw ParseError(src, 1, "file type", field(L[0], 20, 1), "'O' (observation data)");
  }
  char default_system = 'G';  // RINEX 2: blank system letter means GPS
  {
    const std::string s = field(L[0], 40, 1);
    if (!s.empty() && s != " " && s != "M") default_system = s[0];
  }

  // --- header -------------------------------------------------------------
  std::vector<ObsCode> v2_types;
  int v2_expected = -1;
  char v3_sys = ' ';
  int v3_expected = 0;
  std::size_t i = 1;
  for (; i < L.size(); ++i) {
    const std::string& line = L[i];
    const int ln = static_cast<int>(i + 1);
    const std::string lab = label(line);
    if (lab == "END OF HEADER") break;
    if (lab == "MARKER NAME") {
      obs.marker_name = trim(field(line, 0, 60));
    } else if (lab == "APPROX POSITION XYZ") {
      Eigen::Vector3d p;
      for (int k = 0; k < 3; ++k) p[k] = parseFortranReal(field(line, 14 * k, 14), src, ln, "APPROX POSITION XYZ");
      obs.approx_position_ecef = p;
    } else if (lab == "INTERVAL") {
      obs.interval_s = parseFortranReal(field(line, 0, 10), src, ln, "INTERVAL");
    } else if (!v3 && lab == "# / TYPES OF OBSERV") {
      if (v2_expected < 0) {
        v2_expected = parseInt(field(line, 0, 6), src, ln, "# / TYPES OF OBSERV");
        if (v2_expected < 1 || v2_expected > 99) {
          throw ParseError(src, ln, "# / TYPES OF OBSERV", std::to_string(v2_expected), "1 to 99 types");
        }
      }
      for (int k = 0; k < 9 && static_cast<int>(v2_types.size()) < v2_expected; ++k) {
        const std::string code = trim(field(line, 10 + 6 * k, 2));
        const auto c = obsCodeFromRinex2(code);
        if (!c) throw ParseError(src, ln, "# / TYPES OF OBSERV", code, "a RINEX 2 observation code such as C1, P2, L1");
        v2_types.push_back(*c);
      }
    } else if (v3 && lab == "SYS / # / OBS TYPES") {
      const std::string sys = field(line, 0, 1);
      if (!sys.empty() && sys != " ") {
        v3_sys = sys[0];
        v3_expected = parseInt(field(line, 3, 3), src, ln, "SYS / # / OBS TYPES count");
        if (v3_expected < 1 || v3_expected > 99) {
          throw ParseError(src, ln, "SYS / # / OBS TYPES count", std::to_string(v3_expected), "1 to 99 types");
        }
      }
      const auto cons = constellationFromLetter(v3_sys);
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
  }
  if (i == L.size()) throw ParseError(src, static_cast<int>(i), "END OF HEADER", "", "the end of the header");
  if (!v3) {
    if (v2_types.empty()) throw ParseError(src, static_cast<int>(i + 1), "# / TYPES OF OBSERV", "", "observation types in the header");
    if (static_cast<int>(v2_types.size()) != v2_expected) {
      throw ParseError(src, static_cast<int>(i + 1), "# / TYPES OF OBSERV", std::to_string(v2_types.size()),
                       std::to_string(v2_expected) + " types as announced");
    }
    for (Constellation c : kAllConstellations) obs.types[static_cast<int>(c)] = v2_types;
  }
  ++i;

  // --- epochs --------------------------------------------------------------
  while (i < L.size()) {
    const std::string& line = L[i];
    const int ln = static_cast<int>(i + 1);
    if (trim(line).empty()) { ++i; continue; }
    ObservationEpoch ep;
    ep.source_line = ln;
    CalendarTime c;
    int nsat = 0;
    std::vector<std::string> sat_list;  // RINEX 2 only
    if (v3) {
      if (line[0] != '>') throw ParseError(src, ln, "epoch record", trim(line).substr(0, 30), "a '>' epoch line");
      c.year = parseInt(field(line, 2, 4), src, ln, "epoch year");
      c.month = parseInt(field(line, 7, 2), src, ln, "epoch month");
      c.day = parseInt(field(line, 10, 2), src, ln, "epoch day");
      c.hour = parseInt(field(line, 13, 2), src, ln, "epoch hour");
      c.minute = parseInt(field(line, 16, 2), src, ln, "epoch minute");
      c.second = parseFortranReal(field(line, 18, 11), src, ln, "epoch second");
      ep.flag = parseInt(field(line, 31, 1), src, ln, "epoch flag");
      nsat = parseInt(field(line, 32, 3), src, ln, "number of satellites");
    } else {
      c.year = rinexFullYear(parseInt(field(line, 1, 2), src, ln, "epoch year"));
      c.month = parseInt(field(line, 4, 2), src, ln, "epoch month");
      c.day = parseInt(field(line, 7, 2), src, ln, "epoch day");
      c.hour = parseInt(field(line, 10, 2), src, ln, "epoch hour");
      c.minute = parseInt(field(line, 13, 2), src, ln, "epoch minute");
      c.second = parseFortranReal(field(line, 15, 11), src, ln, "epoch second");
      ep.flag = parseInt(field(line, 28, 1), src, ln, "epoch flag");
      nsat = parseInt(field(line, 29, 3), src, ln, "number of satellites");
    }
    if (nsat < 0 || nsat > 999) throw ParseError(src, ln, "number of satellites", std::to_string(nsat), "0 to 999");
    if (ep.flag > 1) {  // event: the count gives the number of special records that follow
      if (ep.flag > 6) throw ParseError(src, ln, "epoch flag", std::to_string(ep.flag), "0 to 6");
      i += 1 + static_cast<std::size_t>(nsat);
      continue;
    }
    checkEpoch(c, src, ln);
    ep.t = gpsFromCalendar(c);
    if (!v3) {
      std::size_t row = i;
      for (int k = 0; k < nsat; ++k) {
        if (k > 0 && k % 12 == 0) {
          ++row;
          if (row >= L.size()) throw ParseError(src, static_cast<int>(row + 1), "satellite list", "", "a continuation line");
        }
        std::string s = field(L[row], 32 + 3 * static_cast<std::size_t>(k % 12), 3);
        if (trim(s).empty()) throw ParseError(src, static_cast<int>(row + 1), "satellite list", "", std::to_string(nsat) + " satellites");
        if (s[0] == ' ') s[0] = default_system;
        sat_list.push_back(s);
      }
      i = row + 1;
      const std::size_t nt = v2_types.size();
      const std::size_t lines_per_sat = (nt + 4) / 5;
      for (int k = 0; k < nsat; ++k) {
        const auto id = parseSatId(sat_list[static_cast<std::size_t>(k)]);
        if (!id) throw ParseError(src, ln, "satellite list", sat_list[static_cast<std::size_t>(k)], "satellite ids like G05");
        SatObservation so;
        so.sat = *id;
        so.values.assign(nt, kNaN);
        for (std::size_t t = 0; t < nt; ++t) {
          const std::size_t r = i + t / 5;
          if (r >= L.size()) throw ParseError(src, static_cast<int>(r + 1), v2_types[t].as_written, "", "an observation line (file is truncated)");
          so.values[t] = parseObsValue(L[r], kObsWidth * (t % 5), src, static_cast<int>(r + 1), v2_types[t].as_written);
        }
        i += lines_per_sat;
        const auto cons = so.sat.constellation;
        if (cons == Constellation::kGps || cons == Constellation::kGalileo || cons == Constellation::kGlonass ||
            cons == Constellation::kBeidou) {
          ep.sats.push_back(std::move(so));
        }
      }
    } else {
      ++i;
      for (int k = 0; k < nsat; ++k, ++i) {
        if (i >= L.size()) throw ParseError(src, static_cast<int>(i + 1), "observation record", "", std::to_string(nsat) + " satellite lines (file is truncated)");
        const std::string& sl = L[i];
        const int sln = static_cast<int>(i + 1);
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
    obs.epochs.push_back(std::move(ep));
  }
  return obs;
}

ObservationData loadRinexObs(const std::string& path) { return parseRinexObs(readTextFile(path), path); }

}  // namespace skylane::integrity
