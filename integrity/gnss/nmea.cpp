#include "integrity/gnss/nmea.hpp"

#include "integrity/gnss/parse_error.hpp"

#include <cctype>
#include <cmath>
#include <cstdlib>
#include <stdexcept>
#include <vector>

namespace skylane::integrity {

namespace {

/// The comma-separated fields of a sentence body (address first), after the checksum check.
std::vector<std::string> fieldsOf(const std::string& raw, const std::string& source) {
  std::string line = raw;
  while (!line.empty() && (line.back() == '\r' || line.back() == '\n' || line.back() == ' ')) line.pop_back();
  if (line.size() < 7 || (line[0] != '$' && line[0] != '!')) {
    throw ParseError(source, 0, "sentence", line.substr(0, 40), "an NMEA 0183 sentence starting with '$'");
  }
  const std::size_t star = line.rfind('*');
  if (star == std::string::npos || star + 3 != line.size()) {
    throw ParseError(source, 0, "checksum", line.substr(line.size() > 6 ? line.size() - 6 : 0),
                     "'*' and two hex digits at the end of the sentence");
  }
  unsigned sum = 0;
  for (std::size_t i = 1; i < star; ++i) sum ^= static_cast<unsigned char>(line[i]);
  const std::string given = line.substr(star + 1);
  char* end = nullptr;
  const unsigned long value = std::strtoul(given.c_str(), &end, 16);
  if (end != given.c_str() + 2 || !std::isxdigit(static_cast<unsigned char>(given[0])) ||
      !std::isxdigit(static_cast<unsigned char>(given[1]))) {
    throw ParseError(source, 0, "checksum", given, "two hex digits");
  }
  if (value != sum) {
    char want[8];
    std::snprintf(want, sizeof want, "%02X", sum);
    throw ParseError(source, 0, "checksum", given, std::string("the XOR of the sentence, ") + want);
  }
  std::vector<std::string> out;
  std::string cur;
  for (std::size_t i = 1; i < star; ++i) {
    if (line[i] == ',') {
      out.push_back(cur);
      cur.clear();
    } else {
      cur += line[i];
    }
  }
  out.push_back(cur);
  return out;
}

struct Reader {
  const std::vector<std::string>& f;
  const std::string& source;
  const std::string& type;

  [[nodiscard]] std::string name(std::size_t i, const char* what) const {
    return type + " field " + std::to_string(i) + " (" + what + ")";
  }
  [[nodiscard]] const std::string& text(std::size_t i) const {
    static const std::string kEmpty;
    return i < f.size() ? f[i] : kEmpty;
  }
  [[nodiscard]] std::optional<double> real(std::size_t i, const char* what) const {
    const std::string& t = text(i);
    if (t.empty()) return std::nullopt;
    char* end = nullptr;
    const double v = std::strtod(t.c_str(), &end);
    if (end != t.c_str() + t.size() || !std::isfinite(v)) throw ParseError(source, 0, name(i, what), t, "a number");
    return v;
  }
  [[nodiscard]] std::optional<int> integer(std::size_t i, const char* what, int lo, int hi) const {
    const auto v = real(i, what);
    if (!v) return std::nullopt;
    if (*v != std::floor(*v) || *v < lo || *v > hi) {
      throw ParseError(source, 0, name(i, what), text(i), "a whole number " + std::to_string(lo) + "…" + std::to_string(hi));
    }
    return static_cast<int>(*v);
  }
  [[nodiscard]] NmeaTimeOfDay time(std::size_t i) const {
    const std::string& t = text(i);
    const auto v = real(i, "UTC hhmmss.ss");
    if (!v || t.size() < 6 || t.find_first_not_of("0123456789.") != std::string::npos) {
      throw ParseError(source, 0, name(i, "UTC hhmmss.ss"), t, "a UTC time hhmmss(.ss)");
    }
    const int hh = std::atoi(t.substr(0, 2).c_str()), mm = std::atoi(t.substr(2, 2).c_str());
    const double ss = std::strtod(t.substr(4).c_str(), nullptr);
    if (hh > 23 || mm > 59 || ss >= 61.0) throw ParseError(source, 0, name(i, "UTC hhmmss.ss"), t, "a valid time of day");
    return {hh * 3600.0 + mm * 60.0 + ss};
  }
  /// ddmm.mmmm (or dddmm.mmmm) and a hemisphere letter.
  [[nodiscard]] std::optional<double> angle(std::size_t i, int degree_digits, char positive, char negative,
                                            const char* what, double limit_deg) const {
    const std::string& t = text(i);
    const std::string& h = text(i + 1);
    if (t.empty() && h.empty()) return std::nullopt;
    const auto v = real(i, what);
    const std::size_t dot = t.find('.');
    const std::size_t int_digits = dot == std::string::npos ? t.size() : dot;
    if (!v || *v < 0 || int_digits != static_cast<std::size_t>(degree_digits + 2)) {
      throw ParseError(source, 0, name(i, what), t,
                       degree_digits == 2 ? "a latitude ddmm.mmmm" : "a longitude dddmm.mmmm");
    }
    const double deg = std::floor(*v / 100.0);
    const double min = *v - 100.0 * deg;
    if (min >= 60.0) throw ParseError(source, 0, name(i, what), t, "minutes below 60");
    double out = deg + min / 60.0;
    if (out > limit_deg) throw ParseError(source, 0, name(i, what), t, "an angle within ±" + std::to_string(static_cast<int>(limit_deg)) + "°");
    if (h.size() != 1 || (h[0] != positive && h[0] != negative)) {
      throw ParseError(source, 0, name(i + 1, "hemisphere"), h, std::string("'") + positive + "' or '" + negative + "'");
    }
    if (h[0] == negative) out = -out;
    return out * M_PI / 180.0;
  }
};

NmeaGga readGga(const Reader& r) {
  NmeaGga g;
  g.utc = r.time(1);
  g.lat_rad = r.angle(2, 2, 'N', 'S', "latitude", 90.0);
  g.lon_rad = r.angle(4, 3, 'E', 'W', "longitude", 180.0);
  g.quality = r.integer(6, "fix quality", 0, 9).value_or(0);
  g.satellites = r.integer(7, "satellites used", 0, 999).value_or(0);
  g.hdop = r.real(8, "HDOP");
  g.alt_msl_m = r.real(9, "altitude above the geoid");
  if (g.alt_msl_m && r.text(10) != "M") throw ParseError(r.source, 0, r.name(10, "altitude unit"), r.text(10), "'M'");
  g.geoid_separation_m = r.real(11, "geoid separation");
  if (g.geoid_separation_m && r.text(12) != "M") {
    throw ParseError(r.source, 0, r.name(12, "separation unit"), r.text(12), "'M'");
  }
  if (g.lat_rad.has_value() != g.lon_rad.has_value()) {
    throw ParseError(r.source, 0, r.name(2, "position"), "", "both latitude and longitude, or neither");
  }
  return g;
}

NmeaGst readGst(const Reader& r) {
  NmeaGst g;
  g.utc = r.time(1);
  g.rms_m = r.real(2, "RMS");
  g.semi_major_m = r.real(3, "semi-major σ");
  g.semi_minor_m = r.real(4, "semi-minor σ");
  g.orientation_deg = r.real(5, "orientation");
  g.sigma_lat_m = r.real(6, "latitude σ");
  g.sigma_lon_m = r.real(7, "longitude σ");
  g.sigma_alt_m = r.real(8, "altitude σ");
  for (const auto* v : {&g.rms_m, &g.semi_major_m, &g.semi_minor_m, &g.sigma_lat_m, &g.sigma_lon_m, &g.sigma_alt_m}) {
    if (*v && **v < 0) throw ParseError(r.source, 0, "GST", r.text(2), "error statistics ≥ 0");
  }
  return g;
}

NmeaGbs readGbs(const Reader& r) {
  NmeaGbs g;
  g.utc = r.time(1);
  g.err_lat_m = r.real(2, "expected latitude error");
  g.err_lon_m = r.real(3, "expected longitude error");
  g.err_alt_m = r.real(4, "expected altitude error");
  g.failed_satellite = r.integer(5, "failed satellite", 0, 999);
  g.p_missed_detection = r.real(6, "probability of missed detection");
  if (g.p_missed_detection && (*g.p_missed_detection < 0 || *g.p_missed_detection > 1)) {
    throw ParseError(r.source, 0, r.name(6, "probability of missed detection"), r.text(6), "a probability 0…1");
  }
  g.bias_m = r.real(7, "bias");
  g.bias_sigma_m = r.real(8, "bias σ");
  return g;
}

NmeaDate readRmc(const Reader& r) {
  NmeaDate d;
  d.utc = r.time(1);
  const std::string& t = r.text(9);
  if (t.size() != 6 || t.find_first_not_of("0123456789") != std::string::npos) {
    throw ParseError(r.source, 0, r.name(9, "date ddmmyy"), t, "a date ddmmyy");
  }
  d.day = std::atoi(t.substr(0, 2).c_str());
  d.month = std::atoi(t.substr(2, 2).c_str());
  const int yy = std::atoi(t.substr(4, 2).c_str());
  d.year = yy < 80 ? 2000 + yy : 1900 + yy;  // NMEA's two-digit year: 1980–2079
  if (!isValidCalendar({d.year, d.month, d.day, 0, 0, 0.0})) throw ParseError(r.source, 0, r.name(9, "date ddmmyy"), t, "a valid date");
  return d;
}

NmeaDate readZda(const Reader& r) {
  NmeaDate d;
  d.utc = r.time(1);
  d.day = r.integer(2, "day", 1, 31).value_or(0);
  d.month = r.integer(3, "month", 1, 12).value_or(0);
  d.year = r.integer(4, "year", 1980, 2200).value_or(0);
  if (!isValidCalendar({d.year, d.month, d.day, 0, 0, 0.0})) throw ParseError(r.source, 0, r.name(2, "date"), r.text(2), "a valid date");
  return d;
}

}  // namespace

NmeaSentence parseNmeaSentence(const std::string& line, const std::string& source) {
  const std::vector<std::string> f = fieldsOf(line, source);
  const std::string& address = f[0];
  if (address.size() != 5 || !std::isupper(static_cast<unsigned char>(address[0]))) {
    throw ParseError(source, 0, "address field", address, "a talker and sentence type such as GNGGA");
  }
  const std::string type = address.substr(2);
  const Reader r{f, source, type};
  if (type == "GGA") return readGga(r);
  if (type == "GST") return readGst(r);
  if (type == "GBS") return readGbs(r);
  if (type == "RMC") return readRmc(r);
  if (type == "ZDA") return readZda(r);
  return NmeaOther{type};
}

NmeaEpochAssembler::NmeaEpochAssembler(std::optional<NmeaDate> default_date) : date_(default_date) {}

std::optional<NmeaFix> NmeaEpochAssembler::release() {
  std::optional<NmeaFix> out;
  if (gga_ && gga_->lat_rad && gga_->lon_rad && gga_->quality > 0) {
    if (!date_) throw std::invalid_argument("NMEA: a fix needs a date: an RMC or ZDA sentence before it, or a default date (skylane track --date YYYY-MM-DD)");
    NmeaFix f;
    // The time of day belongs to the known date; a time of day far before the date's own
    // (past midnight since the RMC/ZDA) moves to the next day.
    double tod = gga_->utc.seconds;
    int day_shift = tod + 43200.0 < date_->utc.seconds ? 1 : 0;
    const GpsTime midnight = gpsFromUtc({date_->year, date_->month, date_->day, 0, 0, 0.0});
    f.time = midnight.plus(day_shift * 86400.0 + tod);
    f.lat_rad = *gga_->lat_rad;
    f.lon_rad = *gga_->lon_rad;
    f.h_ell_m = gga_->alt_msl_m.value_or(0.0) + gga_->geoid_separation_m.value_or(0.0);
    f.quality = gga_->quality;
    f.satellites = gga_->satellites;
    f.hdop = gga_->hdop;
    if (gst_ && gst_->utc.seconds == gga_->utc.seconds) f.gst = gst_;
    if (gbs_ && gbs_->utc.seconds == gga_->utc.seconds) f.gbs = gbs_;
    out = f;
  }
  gga_.reset();
  gst_.reset();
  gbs_.reset();
  return out;
}

std::optional<NmeaFix> NmeaEpochAssembler::add(const NmeaSentence& s) {
  std::optional<NmeaFix> out;
  auto close_if_other = [&](double tod) {
    if (gga_ && gga_->utc.seconds != tod) out = release();
  };
  if (const auto* g = std::get_if<NmeaGga>(&s)) {
    if (gga_) out = release();
    gga_ = *g;
  } else if (const auto* t = std::get_if<NmeaGst>(&s)) {
    close_if_other(t->utc.seconds);
    gst_ = *t;
  } else if (const auto* b = std::get_if<NmeaGbs>(&s)) {
    close_if_other(b->utc.seconds);
    gbs_ = *b;
  } else if (const auto* d = std::get_if<NmeaDate>(&s)) {
    close_if_other(d->utc.seconds);
    date_ = *d;
  }
  return out;
}

std::optional<NmeaFix> NmeaEpochAssembler::flush() { return release(); }

}  // namespace skylane::integrity
