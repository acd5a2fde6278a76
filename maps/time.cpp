#include "maps/time.hpp"

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <stdexcept>
#include <string>

namespace skylane::maps {
namespace {

/// Days from 1970-01-01 to the GPS epoch 1980-01-06.
constexpr long kGpsEpochDays = 3657;

/// IERS leap seconds (Bulletin C): the first UTC day on which GPS − UTC took each value.
struct LeapEntry {
  int year, month, day;  // first UTC day with the new offset
  int gps_minus_utc_s;
};
constexpr std::array<LeapEntry, 18> kLeapTable = {{
    {1981, 7, 1, 1},  {1982, 7, 1, 2},  {1983, 7, 1, 3},  {1985, 7, 1, 4},  {1988, 1, 1, 5},
    {1990, 1, 1, 6},  {1991, 1, 1, 7},  {1992, 7, 1, 8},  {1993, 7, 1, 9},  {1994, 7, 1, 10},
    {1996, 1, 1, 11}, {1997, 7, 1, 12}, {1999, 1, 1, 13}, {2006, 1, 1, 14}, {2009, 1, 1, 15},
    {2012, 7, 1, 16}, {2015, 7, 1, 17}, {2017, 1, 1, 18},
}};

double utcSecondsSinceGpsEpoch(const CalendarTime& c) {
  const long days = daysFromCivil(c.year, c.month, c.day) - kGpsEpochDays;
  return days * kSecondsPerDay + c.hour * 3600.0 + c.minute * 60.0 + c.second;
}

int leapSecondsAtUtc(double utc_s) {
  // The table's instants in seconds, computed once (every time conversion asks).
  static const std::array<double, kLeapTable.size()> kStarts = [] {
    std::array<double, kLeapTable.size()> out{};
    for (std::size_t i = 0; i < kLeapTable.size(); ++i) {
      const LeapEntry& e = kLeapTable[i];
      out[i] = utcSecondsSinceGpsEpoch({e.year, e.month, e.day, 0, 0, 0.0});
    }
    return out;
  }();
  int offset = 0;
  for (std::size_t i = 0; i < kLeapTable.size() && utc_s >= kStarts[i]; ++i) offset = kLeapTable[i].gps_minus_utc_s;
  return offset;
}

CalendarTime calendarFromSeconds(double t_s) {
  double days_f = std::floor(t_s / kSecondsPerDay);
  double sod = t_s - days_f * kSecondsPerDay;
  long z = static_cast<long>(days_f) + kGpsEpochDays + 719468;  // civil_from_days
  const long era = (z >= 0 ? z : z - 146096) / 146097;
  const long doe = z - era * 146097;
  const long yoe = (doe - doe / 1460 + doe / 36524 - doe / 146096) / 365;
  const long doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
  const long mp = (5 * doy + 2) / 153;
  CalendarTime c;
  c.day = static_cast<int>(doy - (153 * mp + 2) / 5 + 1);
  c.month = static_cast<int>(mp < 10 ? mp + 3 : mp - 9);
  c.year = static_cast<int>(yoe + era * 400 + (c.month <= 2 ? 1 : 0));
  c.hour = static_cast<int>(sod / 3600.0);
  sod -= c.hour * 3600.0;
  c.minute = static_cast<int>(sod / 60.0);
  c.second = sod - c.minute * 60.0;
  return c;
}

}  // namespace

long daysFromCivil(int y, int m, int d) {
  y -= m <= 2 ? 1 : 0;
  const long era = (y >= 0 ? y : y - 399) / 400;
  const long yoe = y - era * 400;
  const long doy = (153L * (m + (m > 2 ? -3 : 9)) + 2) / 5 + d - 1;
  const long doe = yoe * 365 + yoe / 4 - yoe / 100 + doy;
  return era * 146097 + doe - 719468;
}

bool isValidCalendar(const CalendarTime& c) {
  static constexpr int kDaysInMonth[] = {31, 29, 31, 30, 31, 30, 31, 31, 30, 31, 30, 31};
  if (c.year < 1980 || c.year > 2200 || c.month < 1 || c.month > 12) return false;
  const bool leap = (c.year % 4 == 0 && c.year % 100 != 0) || c.year % 400 == 0;
  const int days = c.month == 2 && !leap ? 28 : kDaysInMonth[c.month - 1];
  return c.day >= 1 && c.day <= days && c.hour >= 0 && c.hour <= 23 && c.minute >= 0 && c.minute <= 59 &&
         c.second >= 0 && c.second < 61;
}

GpsTime GpsTime::fromTotalSeconds(double t_s) {
  // A non-finite time, or one whose week does not fit an int, would make the cast below
  // undefined behaviour; every input time is range-checked before it gets here.
  const double week = std::floor(t_s / kSecondsPerWeek);
  if (!(std::abs(week) <= static_cast<double>(std::numeric_limits<int>::max()) - 1.0)) {
    char value[40];
    std::snprintf(value, sizeof value, "%g", t_s);
    throw std::invalid_argument(std::string("GPS time: ") + value + " s since the GPS epoch is not a time (|weeks| < 2^31 expected)");
  }
  GpsTime t;
  t.week = static_cast<int>(week);
  t.sow = t_s - t.week * kSecondsPerWeek;
  return t;
}

GpsTime gpsFromCalendar(const CalendarTime& c) {
  return GpsTime::fromTotalSeconds(utcSecondsSinceGpsEpoch(c));
}

CalendarTime calendarFromGps(const GpsTime& t) { return calendarFromSeconds(t.totalSeconds()); }

int leapSecondsAtGps(const GpsTime& t) {
  // The offset in force at GPS instant t is the one in force at UTC instant t − offset.
  const double gps_s = t.totalSeconds();
  int offset = leapSecondsAtUtc(gps_s);
  offset = leapSecondsAtUtc(gps_s - offset);
  return offset;
}

GpsTime gpsFromUtc(const CalendarTime& utc) {
  const double utc_s = utcSecondsSinceGpsEpoch(utc);
  return GpsTime::fromTotalSeconds(utc_s + leapSecondsAtUtc(utc_s));
}

CalendarTime utcFromGps(const GpsTime& t) {
  return calendarFromSeconds(t.totalSeconds() - leapSecondsAtGps(t));
}

namespace {

std::optional<GpsTime> parseRfc3339Text(std::string_view text) {
  // YYYY-MM-DDTHH:MM:SS[.frac](Z|±HH:MM), every digit where RFC 3339 §5.6 puts it.
  const auto digits = [&](std::size_t pos, std::size_t n, int& out) {
    if (pos + n > text.size()) return false;
    out = 0;
    for (std::size_t i = pos; i < pos + n; ++i) {
      if (!std::isdigit(static_cast<unsigned char>(text[i]))) return false;
      out = out * 10 + (text[i] - '0');
    }
    return true;
  };
  int y = 0, mo = 0, d = 0, h = 0, mi = 0, si = 0;
  if (text.size() < 20 || !digits(0, 4, y) || text[4] != '-' || !digits(5, 2, mo) || text[7] != '-' ||
      !digits(8, 2, d) || (text[10] != 'T' && text[10] != 't' && text[10] != ' ') || !digits(11, 2, h) ||
      text[13] != ':' || !digits(14, 2, mi) || text[16] != ':' || !digits(17, 2, si)) {
    return std::nullopt;
  }
  std::size_t pos = 19;
  double s = si;
  if (pos < text.size() && text[pos] == '.') {
    double scale = 0.1;
    std::size_t start = ++pos;
    for (; pos < text.size() && std::isdigit(static_cast<unsigned char>(text[pos])); ++pos, scale /= 10) {
      s += (text[pos] - '0') * scale;
    }
    if (pos == start) return std::nullopt;
  }
  static constexpr int kDaysInMonth[] = {31, 29, 31, 30, 31, 30, 31, 31, 30, 31, 30, 31};
  const bool leap_year = (y % 4 == 0 && y % 100 != 0) || y % 400 == 0;
  if (y < 1980 || mo < 1 || mo > 12 || d < 1 || d > kDaysInMonth[mo - 1] || (mo == 2 && d == 29 && !leap_year) ||
      h > 23 || mi > 59 || si > 59) {
    return std::nullopt;  // 23:59:60 is not accepted: skylane cannot tell a real leap second apart
  }
  const std::string_view zone = text.substr(pos);
  int offset_min = 0;
  if (zone == "Z" || zone == "z") {
    offset_min = 0;
  } else if (zone.size() == 6 && (zone[0] == '+' || zone[0] == '-') && zone[3] == ':' &&
             std::isdigit(static_cast<unsigned char>(zone[1])) &&
             std::isdigit(static_cast<unsigned char>(zone[2])) &&
             std::isdigit(static_cast<unsigned char>(zone[4])) &&
             std::isdigit(static_cast<unsigned char>(zone[5]))) {
    const int oh = (zone[1] - '0') * 10 + (zone[2] - '0');
    const int om = (zone[4] - '0') * 10 + (zone[5] - '0');
    if (oh > 23 || om > 59) return std::nullopt;
    offset_min = (zone[0] == '-' ? -1 : 1) * (oh * 60 + om);
  } else {
    return std::nullopt;
  }
  const double utc_s = utcSecondsSinceGpsEpoch({y, mo, d, h, mi, s}) - offset_min * 60.0;
  return GpsTime::fromTotalSeconds(utc_s + leapSecondsAtUtc(utc_s));
}

/// The last text read and written on this thread: a stream's fixes come in runs of the same
/// time (every flight's fix of one second), so the last answer is given again, unchanged.
struct LastRfc3339 {
  std::string parsed_text;
  std::optional<GpsTime> parsed;
  GpsTime formatted_time{-1, -1.0};
  int formatted_digits = -1;
  char formatted[kRfc3339MaxChars] = {};
  std::size_t formatted_size = 0;
};

/// formatRfc3339To without the memo.
char* formatRfc3339Text(char* out, const GpsTime& t, int fraction_digits);

LastRfc3339& lastRfc3339() {
  thread_local LastRfc3339 last;
  return last;
}

}  // namespace

std::optional<GpsTime> parseRfc3339(std::string_view text) {
  static constexpr std::size_t kLongestKept = 64;
  LastRfc3339& last = lastRfc3339();
  if (text == last.parsed_text && !text.empty()) return last.parsed;
  const std::optional<GpsTime> t = parseRfc3339Text(text);
  if (text.size() <= kLongestKept) {
    last.parsed_text.assign(text);
    last.parsed = t;
  }
  return t;
}

namespace {

/// The general form (any year, any number of digits), with snprintf.
std::string formatRfc3339Printf(const GpsTime& t, int fraction_digits) {
  const double scale = std::pow(10.0, fraction_digits);
  const double utc_s = std::round((t.totalSeconds() - leapSecondsAtGps(t)) * scale) / scale;
  const CalendarTime c = calendarFromSeconds(utc_s);
  char buf[64];
  if (fraction_digits <= 0) {
    std::snprintf(buf, sizeof buf, "%04d-%02d-%02dT%02d:%02d:%02dZ", c.year, c.month, c.day, c.hour, c.minute,
                  static_cast<int>(std::lround(c.second) % 60));
  } else {
    std::snprintf(buf, sizeof buf, "%04d-%02d-%02dT%02d:%02d:%0*.*fZ", c.year, c.month, c.day, c.hour, c.minute,
                  fraction_digits + 3, fraction_digits, c.second);
  }
  return buf;
}

}  // namespace

std::string formatRfc3339(const GpsTime& t, int fraction_digits) {
  char buf[kRfc3339MaxChars];
  const char* end = formatRfc3339To(buf, t, fraction_digits);
  return end != nullptr ? std::string(static_cast<const char*>(buf), end) : formatRfc3339Printf(t, fraction_digits);
}

char* formatRfc3339To(char* out, const GpsTime& t, int fraction_digits) {
  LastRfc3339& last = lastRfc3339();
  if (t.week == last.formatted_time.week && t.sow == last.formatted_time.sow && fraction_digits == last.formatted_digits) {
    std::memcpy(out, last.formatted, last.formatted_size);
    return out + last.formatted_size;
  }
  char* end = formatRfc3339Text(out, t, fraction_digits);
  if (end != nullptr) {
    last.formatted_time = t;
    last.formatted_digits = fraction_digits;
    last.formatted_size = static_cast<std::size_t>(end - out);
    std::memcpy(last.formatted, out, last.formatted_size);
  }
  return end;
}

namespace {

char* formatRfc3339Text(char* out, const GpsTime& t, int fraction_digits) {
  // 0–6 digits for years 1–9998 by hand (the common case: snprintf's "%0*.*f" was a third of a
  // tracker fix event's time); anything else in the general form.
  if (fraction_digits < 0 || fraction_digits > 6) return nullptr;
  const int digits = fraction_digits;
  long long unit = 1;
  for (int i = 0; i < digits; ++i) unit *= 10;
  const double scale = static_cast<double>(unit);
  // Round once in seconds so that 59.9996 does not print as 60.000.
  const double utc_s = std::round((t.totalSeconds() - leapSecondsAtGps(t)) * scale) / scale;
  const CalendarTime c = calendarFromSeconds(utc_s);
  if (c.year < 1 || c.year > 9998) return nullptr;
  const long long units = std::llround(c.second * scale);
  const long long whole = (units / unit) % 60;
  long long frac = units % unit;
  char* p = out;
  auto put = [&p](long long v, int width) {
    for (int i = width - 1; i >= 0; --i, v /= 10) p[i] = static_cast<char>('0' + v % 10);
    p += width;
  };
  put(c.year, 4);
  *p++ = '-';
  put(c.month, 2);
  *p++ = '-';
  put(c.day, 2);
  *p++ = 'T';
  put(c.hour, 2);
  *p++ = ':';
  put(c.minute, 2);
  *p++ = ':';
  put(whole, 2);
  if (digits > 0) {
    *p++ = '.';
    put(frac, digits);
  }
  *p++ = 'Z';
  return p;
}

}  // namespace

std::optional<double> parseDuration(const std::string& text) {
  if (text.empty()) return std::nullopt;
  double total = 0;
  std::size_t i = 0;
  bool any = false;
  while (i < text.size()) {
    char* end = nullptr;
    const double v = std::strtod(text.c_str() + i, &end);
    const std::size_t used = static_cast<std::size_t>(end - (text.c_str() + i));
    if (used == 0 || !std::isfinite(v) || v < 0) return std::nullopt;
    i += used;
    double unit = 1.0;
    if (i < text.size()) {
      switch (text[i]) {
        case 'd': unit = 86400.0; break;
        case 'h': unit = 3600.0; break;
        case 'm': unit = 60.0; break;
        case 's': unit = 1.0; break;
        default: return std::nullopt;
      }
      ++i;
    } else if (any) {
      return std::nullopt;  // "1h30" is ambiguous
    }
    total += v * unit;
    any = true;
  }
  if (!(total > 0) || !std::isfinite(total)) return std::nullopt;
  return total;
}

}  // namespace skylane::maps
