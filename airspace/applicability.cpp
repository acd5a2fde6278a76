#include "airspace/applicability.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <limits>
#include <utility>

namespace skylane::airspace {
namespace {

constexpr double kDay_s = 86400.0;
/// A weekly schedule repeats after 7 days; 8 covers a period that runs past midnight.
constexpr int kScheduleHorizonDays = 8;

/// UTC seconds since 1980-01-06 00:00:00 UTC (the GPS epoch, a Sunday).
double utcSeconds(const maps::GpsTime& t) { return t.totalSeconds() - maps::leapSecondsAtGps(t); }

/// Monday = 0 … Sunday = 6 for the UTC day index counted from the GPS epoch.
unsigned weekday(long day_index) { return static_cast<unsigned>(((day_index % 7) + 7 + 6) % 7); }

/// [begin, end) of the entry's date range in UTC seconds (±infinity when open).
std::pair<double, double> dateRange(const Applicability& a) {
  const double inf = std::numeric_limits<double>::infinity();
  if (a.permanent) return {-inf, inf};  // ED-269 permanent = YES: no date range
  return {a.start ? utcSeconds(*a.start) : -inf, a.end ? utcSeconds(*a.end) : inf};
}

/// True when some scheduled period overlaps [u0, u1] (closed at u1 when `closed_end`).
bool scheduleOverlaps(const std::vector<DailyPeriod>& schedule, double u0, double u1, bool closed_end) {
  if (schedule.empty()) return true;
  // Periods start on the local day; shifted to UTC they may begin up to a day earlier or later.
  const long first = static_cast<long>(std::floor(u0 / kDay_s)) - 2;
  const long last = std::min(static_cast<long>(std::floor(u1 / kDay_s)) + 1, first + kScheduleHorizonDays + 3);
  for (long d = first; d <= last; ++d) {
    for (const DailyPeriod& p : schedule) {
      if (!(p.days & (1u << weekday(d)))) continue;
      const double ps = d * kDay_s + p.start_s;
      double pe = d * kDay_s + p.end_s;
      if (pe <= ps) pe += kDay_s;  // across midnight
      if (closed_end ? (ps <= u1 && u0 < pe) : (ps < u1 && u0 < pe)) return true;
    }
  }
  return false;
}

}  // namespace

bool isActive(const Applicability& a, const maps::GpsTime& t) {
  const double u = utcSeconds(t);
  const auto [begin, end] = dateRange(a);
  if (!(u >= begin && u < end)) return false;
  return scheduleOverlaps(a.schedule, u, u, /*closed_end=*/true);
}

bool isActiveDuring(const Applicability& a, const maps::GpsTime& t0, const maps::GpsTime& t1) {
  double u0 = utcSeconds(t0);
  double u1 = utcSeconds(t1);
  if (u1 <= u0) return isActive(a, t0);
  const auto [begin, end] = dateRange(a);
  u0 = std::max(u0, begin);
  u1 = std::min(u1, end);
  if (!(u0 < u1)) return false;
  // A schedule repeats weekly: an interval longer than the horizon behaves like its first days.
  u1 = std::min(u1, u0 + kScheduleHorizonDays * kDay_s);
  return scheduleOverlaps(a.schedule, u0, u1, /*closed_end=*/false);
}

bool isActive(const Zone& z, const maps::GpsTime& t) {
  if (z.applicability.empty()) return true;
  return std::any_of(z.applicability.begin(), z.applicability.end(),
                     [&](const Applicability& a) { return isActive(a, t); });
}

bool isActiveDuring(const Zone& z, const maps::GpsTime& t0, const maps::GpsTime& t1) {
  if (z.applicability.empty()) return true;
  return std::any_of(z.applicability.begin(), z.applicability.end(),
                     [&](const Applicability& a) { return isActiveDuring(a, t0, t1); });
}

bool isAlwaysActive(const Zone& z) {
  return z.applicability.empty() || std::any_of(z.applicability.begin(), z.applicability.end(), [](const Applicability& a) {
           return a.permanent && a.schedule.empty();
         });
}

std::optional<double> parseTimeOfDay(const std::string& text) {
  const auto two = [&](std::size_t pos, int& out) {
    if (pos + 2 > text.size() || !std::isdigit(static_cast<unsigned char>(text[pos])) ||
        !std::isdigit(static_cast<unsigned char>(text[pos + 1]))) {
      return false;
    }
    out = (text[pos] - '0') * 10 + (text[pos + 1] - '0');
    return true;
  };
  int h = 0, m = 0, s = 0;
  if (!two(0, h) || text.size() < 5 || text[2] != ':' || !two(3, m)) return std::nullopt;
  std::size_t pos = 5;
  double seconds = 0.0;
  if (pos < text.size() && text[pos] == ':') {
    if (!two(pos + 1, s)) return std::nullopt;
    seconds = s;
    pos += 3;
    if (pos < text.size() && text[pos] == '.') {
      double scale = 0.1;
      const std::size_t start = ++pos;
      for (; pos < text.size() && std::isdigit(static_cast<unsigned char>(text[pos])); ++pos, scale /= 10) {
        seconds += (text[pos] - '0') * scale;
      }
      if (pos == start) return std::nullopt;
    }
  }
  if (m > 59 || s > 59 || h > 24 || (h == 24 && (m != 0 || seconds != 0.0))) return std::nullopt;
  const std::string zone = text.substr(pos);
  double offset_s = 0.0;
  int oh = 0, om = 0;
  if (zone == "Z" || zone == "z") {
    offset_s = 0.0;
  } else if (zone.size() == 6 && (zone[0] == '+' || zone[0] == '-') && zone[3] == ':' && two(pos + 1, oh) &&
             two(pos + 4, om) && oh <= 23 && om <= 59) {
    offset_s = (zone[0] == '-' ? -1.0 : 1.0) * (oh * 3600.0 + om * 60.0);
  } else {
    return std::nullopt;
  }
  return h * 3600.0 + m * 60.0 + seconds - offset_s;
}

const char* weekdayName(unsigned d) {
  static const char* const kDays[] = {"MON", "TUE", "WED", "THU", "FRI", "SAT", "SUN"};
  return d < 7 ? kDays[d] : "?";
}

std::optional<unsigned> weekdayMask(const std::string& code) {
  if (code == "ANY") return 0x7fu;
  for (unsigned d = 0; d < 7; ++d) {
    if (code == weekdayName(d)) return 1u << d;
  }
  return std::nullopt;
}

}  // namespace skylane::airspace
