#include "integrity/gnss/rinex_nav.hpp"

#include "integrity/gnss/almanac.hpp"
#include "integrity/gnss/parse_error.hpp"

#include <cmath>
#include <sstream>

namespace skylane::integrity {
namespace {

/// Half-width of the window around toe in which a broadcast ephemeris is used [s].
constexpr double kMaxDtoeGps_s = 7200.0;
constexpr double kMaxDtoeGalileo_s = 7200.0;

struct Lines {
  std::vector<std::string> v;
  explicit Lines(const std::string& text) : v(splitLines(text)) {}
};

std::string label(const std::string& line) { return rinexLabel(line); }

/// The names of the 4 values on each broadcast-orbit line (GPS and Galileo share the layout).
const char* const kOrbitFields[7][4] = {
    {"IODE", "Crs", "Delta n", "M0"},
    {"Cuc", "e", "Cus", "sqrt(A)"},
    {"Toe", "Cic", "OMEGA0", "Cis"},
    {"i0", "Crc", "omega", "OMEGA DOT"},
    {"IDOT", "codes/data sources", "week", "L2P flag/spare"},
    {"SV accuracy", "SV health", "TGD/BGD E5a", "IODC/BGD E5b"},
    {"transmission time", "fit interval", "spare", "spare"}};

void checkCalendar(const CalendarTime& c, const std::string& src, int ln) {
  if (!isValidCalendar(c)) {
    throw ParseError(src, ln, "epoch", std::to_string(c.year) + "-" + std::to_string(c.month) + "-" +
                                           std::to_string(c.day),
                     "a valid calendar date and time of clock (toc)");
  }
}

/// Reads a record's 7 orbit lines; `col0` is where the first value starts (3 in RINEX 2, 4 in 3).
std::array<std::array<double, 4>, 7> readOrbitLines(const Lines& L, std::size_t first, std::size_t col0,
                                                    const std::string& src) {
  std::array<std::array<double, 4>, 7> o{};
  for (int r = 0; r < 7; ++r) {
    const std::size_t idx = first + static_cast<std::size_t>(r);
    const int ln = static_cast<int>(idx + 1);
    if (idx >= L.v.size()) {
      throw ParseError(src, ln, kOrbitFields[r][0], "", "broadcast orbit line " + std::to_string(r + 1) +
                                                            " (record is truncated)");
    }
    const std::string& line = L.v[idx];
    if (trim(field(line, 0, col0)).size() != 0) {
      throw ParseError(src, ln, kOrbitFields[r][0], trim(line).substr(0, 20),
                       "a continuation line starting with " + std::to_string(col0) + " blanks");
    }
    for (int c = 0; c < 4; ++c) {
      o[r][c] = parseFortranReal(field(line, col0 + 19 * c, 19), src, ln, kOrbitFields[r][c]);
    }
  }
  return o;
}

void fillEphemeris(BroadcastEphemeris& e, const std::array<std::array<double, 4>, 7>& o,
                   const std::string& src, int ln) {
  KeplerOrbit& k = e.orbit;
  k.constellation = e.sat.constellation;
  e.iode = integerField(o[0][0], 0, 1023, src, ln + 1, "IODE/IODnav");
  k.crs = o[0][1];
  k.delta_n_radps = o[0][2];
  k.m0_rad = o[0][3];
  k.cuc = o[1][0];
  k.e = o[1][1];
  k.cus = o[1][2];
  k.sqrt_a = o[1][3];
  k.toe.sow = o[2][0];
  k.cic = o[2][1];
  k.omega0_rad = o[2][2];
  k.cis = o[2][3];
  k.i0_rad = o[3][0];
  k.crc = o[3][1];
  k.omega_rad = o[3][2];
  k.omega_dot_radps = o[3][3];
  k.idot_radps = o[4][0];
  k.toe.week = integerField(o[4][2], 0, 10000, src, ln + 5, "week");
  e.accuracy_m = o[5][0];
  e.health = integerField(o[5][1], 0, 65535, src, ln + 6, "SV health");
  e.tgd_s = o[5][2];
  if (e.sat.constellation == Constellation::kGalileo) {
    e.bgd_e5b_s = o[5][3];
    e.data_sources = integerField(o[4][1], 0, 65535, src, ln + 5, "data sources");
  }
  if (e.sat.constellation == Constellation::kGps && o[6][1] > 0) e.fit_interval_h = o[6][1];
  if (!(k.e >= 0 && k.e < 1)) throw ParseError(src, ln + 2, "e", std::to_string(k.e), "an eccentricity in [0, 1)");
  if (!(k.sqrt_a > 1000 && k.sqrt_a < 10000)) {
    throw ParseError(src, ln + 2, "sqrt(A)", std::to_string(k.sqrt_a), "a value between 1000 and 10000 m^1/2");
  }
  if (!(k.toe.sow >= 0 && k.toe.sow <= kSecondsPerWeek)) {
    throw ParseError(src, ln + 3, "Toe", std::to_string(k.toe.sow), "seconds of week in [0, 604800]");
  }
  // The week field is modulo 1024 in some old files and toe may sit in the week before or after
  // toc: toc (a full calendar date) decides, toe goes to the week that puts it nearest to toc.
  k.toe.week = e.toc.week + static_cast<int>(std::round((e.toc.sow - k.toe.sow) / kSecondsPerWeek));
}

void parseHeaderIono(NavigationData& nav, const std::string& line, const std::string& lab,
                     const std::string& src, int ln, bool v3) {
  auto num = [&](std::size_t pos, std::size_t len, const char* f) {
    return parseFortranReal(field(line, pos, len), src, ln, f);
  };
  if (!v3 && (lab == "ION ALPHA" || lab == "ION BETA")) {
    if (!nav.klobuchar) nav.klobuchar = KlobucharParams{};
    auto& dst = lab == "ION ALPHA" ? nav.klobuchar->alpha : nav.klobuchar->beta;
    for (int i = 0; i < 4; ++i) dst[i] = num(2 + 12 * i, 12, lab.c_str());
  } else if (v3 && lab == "IONOSPHERIC CORR") {
    const std::string kind = field(line, 0, 4);
    if (kind == "GPSA" || kind == "GPSB") {
      if (!nav.klobuchar) nav.klobuchar = KlobucharParams{};
      auto& dst = kind == "GPSA" ? nav.klobuchar->alpha : nav.klobuchar->beta;
      for (int i = 0; i < 4; ++i) dst[i] = num(5 + 12 * i, 12, kind.c_str());
    } else if (kind == "GAL ") {
      std::array<double, 3> ai{};
      for (int i = 0; i < 3; ++i) ai[i] = num(5 + 12 * i, 12, "GAL ai");
      nav.nequick_ai = ai;
    }
  } else if (lab == "LEAP SECONDS") {
    nav.leap_seconds = parseInt(field(line, 0, 6), src, ln, "leap seconds");
  }
}

/// The RINEX VERSION / TYPE line: a GPS (RINEX 2) or mixed (RINEX 3) navigation file; returns
/// whether it is RINEX 3.
bool readVersionLine(const Lines& L, const std::string& src, NavigationData& nav) {
  if (L.v.empty()) throw ParseError(src, 1, "RINEX VERSION / TYPE", "", "a RINEX navigation header (file is empty)");
  const std::string& first = L.v[0];
  if (label(first) != "RINEX VERSION / TYPE") {
    throw ParseError(src, 1, "RINEX VERSION / TYPE", trim(first).substr(0, 40),
                     "the 'RINEX VERSION / TYPE' header line");
  }
  nav.version = parseFortranReal(field(first, 0, 9), src, 1, "RINEX version");
  const char type = field(first, 20, 1).empty() ? ' ' : first[20];
  const bool v3 = nav.version >= 3.0 && nav.version < 4.0;
  if (!v3 && !(nav.version >= 2.0 && nav.version < 3.0)) {
    throw ParseError(src, 1, "RINEX version", trim(field(first, 0, 9)), "2.xx or 3.0x");
  }
  if (type != 'N') {
    throw ParseError(src, 1, "file type", std::string(1, type), "'N' (navigation data)");
  }
  if (!v3 && field(first, 40, 1) == "G" && first.find("GLONASS") != std::string::npos) {
    throw ParseError(src, 1, "file type", "GLONASS", "a GPS navigation file (RINEX 2 type N)");
  }
  return v3;
}

/// The header lines up to END OF HEADER; returns the index of the first record line.
std::size_t readHeader(const Lines& L, const std::string& src, bool v3, NavigationData& nav) {
  std::size_t i = 1;
  for (; i < L.v.size(); ++i) {
    const std::string lab = label(L.v[i]);
    if (lab == "END OF HEADER") break;
    parseHeaderIono(nav, L.v[i], lab, src, static_cast<int>(i + 1), v3);
  }
  if (i == L.v.size()) throw ParseError(src, static_cast<int>(i), "END OF HEADER", "", "the end of the header");
  return i + 1;
}

/// RINEX 3: a record of a system skylane does not use is counted and skipped (its continuation
/// lines start with blanks); returns the index of the line after it.
std::size_t skipRecord(const Lines& L, std::size_t i, const std::string& src, NavigationData& nav) {
  const std::string& line = L.v[i];
  if (!std::isalpha(static_cast<unsigned char>(line[0]))) {
    throw ParseError(src, static_cast<int>(i + 1), "SV", trim(field(line, 0, 3)),
                     "a satellite system letter (G, E, R, C, J, S, I)");
  }
  ++nav.skipped_records;
  ++i;
  while (i < L.v.size() && !L.v[i].empty() && L.v[i][0] == ' ') ++i;
  return i;
}

/// RINEX 3 SV / EPOCH / SV CLK line: satellite and toc; returns the column of af0.
std::size_t readSvEpochV3(const std::string& line, const std::string& src, int ln, Constellation cons,
                          BroadcastEphemeris& e, CalendarTime& toc) {
  e.sat.constellation = cons;
  e.sat.prn = parseInt(field(line, 1, 2), src, ln, "SV PRN");
  toc.year = parseInt(field(line, 4, 4), src, ln, "toc year");
  toc.month = parseInt(field(line, 9, 2), src, ln, "toc month");
  toc.day = parseInt(field(line, 12, 2), src, ln, "toc day");
  toc.hour = parseInt(field(line, 15, 2), src, ln, "toc hour");
  toc.minute = parseInt(field(line, 18, 2), src, ln, "toc minute");
  toc.second = parseInt(field(line, 21, 2), src, ln, "toc second");
  return 23;
}

/// RINEX 2 PRN / EPOCH / SV CLK line: satellite and toc; returns the column of af0.
std::size_t readSvEpochV2(const std::string& line, const std::string& src, int ln, BroadcastEphemeris& e,
                          CalendarTime& toc) {
  e.sat.constellation = Constellation::kGps;
  e.sat.prn = parseInt(field(line, 0, 2), src, ln, "PRN");
  toc.year = rinexFullYear(parseInt(field(line, 3, 2), src, ln, "toc year"));
  toc.month = parseInt(field(line, 6, 2), src, ln, "toc month");
  toc.day = parseInt(field(line, 9, 2), src, ln, "toc day");
  toc.hour = parseInt(field(line, 12, 2), src, ln, "toc hour");
  toc.minute = parseInt(field(line, 15, 2), src, ln, "toc minute");
  toc.second = parseFortranReal(field(line, 17, 5), src, ln, "toc second");
  return 22;
}

/// One ephemeris record from line i (or a skipped RINEX 3 record of another system); returns
/// the index of the line after it.
std::size_t readRecord(const Lines& L, std::size_t i, const std::string& src, bool v3, NavigationData& nav) {
  const std::string& line = L.v[i];
  const int ln = static_cast<int>(i + 1);
  BroadcastEphemeris e;
  e.source_line = ln;
  CalendarTime toc;
  std::size_t vcol = 0;  // column of af0
  if (v3) {
    const auto cons = constellationFromLetter(line[0]);
    if (!cons || (*cons != Constellation::kGps && *cons != Constellation::kGalileo)) return skipRecord(L, i, src, nav);
    vcol = readSvEpochV3(line, src, ln, *cons, e, toc);
  } else {
    vcol = readSvEpochV2(line, src, ln, e, toc);
  }
  if (e.sat.prn < 1 || e.sat.prn > 99) {
    throw ParseError(src, ln, "PRN", std::to_string(e.sat.prn), "a PRN between 1 and 99");
  }
  checkCalendar(toc, src, ln);
  e.toc = gpsFromCalendar(toc);  // GPS and Galileo toc are in their own (aligned) system time
  e.af0_s = parseFortranReal(field(line, vcol, 19), src, ln, "SV clock bias");
  e.af1_sps = parseFortranReal(field(line, vcol + 19, 19), src, ln, "SV clock drift");
  e.af2_sps2 = parseFortranReal(field(line, vcol + 38, 19), src, ln, "SV clock drift rate");
  const auto orbit = readOrbitLines(L, i + 1, v3 ? 4 : 3, src);
  fillEphemeris(e, orbit, src, ln);
  nav.ephemerides.push_back(e);
  return i + 8;
}

}  // namespace

void NavigationData::merge(const NavigationData& other) {
  ephemerides.insert(ephemerides.end(), other.ephemerides.begin(), other.ephemerides.end());
  if (!klobuchar) klobuchar = other.klobuchar;
  if (!nequick_ai) nequick_ai = other.nequick_ai;
  if (!leap_seconds) leap_seconds = other.leap_seconds;
  skipped_records += other.skipped_records;
}

NavigationData parseRinexNav(const std::string& text, const std::string& src) {
  const Lines L(text);
  NavigationData nav;
  const bool v3 = readVersionLine(L, src, nav);
  std::size_t i = readHeader(L, src, v3, nav);
  while (i < L.v.size()) {
    if (trim(L.v[i]).empty()) {
      ++i;
      continue;
    }
    i = readRecord(L, i, src, v3, nav);
  }
  return nav;
}

NavigationData loadRinexNav(const std::string& path) { return parseRinexNav(readTextFile(path), path); }

const BroadcastEphemeris* selectEphemeris(const NavigationData& nav, const SatId& sat, const GpsTime& t) {
  const double max_dt = sat.constellation == Constellation::kGalileo ? kMaxDtoeGalileo_s : kMaxDtoeGps_s;
  const BroadcastEphemeris* best = nullptr;
  double best_dt = 0;
  for (const BroadcastEphemeris& e : nav.ephemerides) {
    if (e.sat != sat || e.health != 0) continue;
    const double dt = std::abs(t - e.orbit.toe);
    if (dt > max_dt) continue;
    // Ties (Galileo I/NAV and F/NAV with one toe): prefer I/NAV (bits 0 or 2), the E1 message.
    const bool inav = (e.data_sources & 0x5) != 0;
    if (!best || dt < best_dt || (dt == best_dt && inav && (best->data_sources & 0x5) == 0)) {
      best = &e;
      best_dt = dt;
    }
  }
  return best;
}

}  // namespace skylane::integrity
