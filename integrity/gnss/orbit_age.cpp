#include "integrity/gnss/orbit_age.hpp"

#include "integrity/gnss/parse_error.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <map>

namespace skylane::integrity {
namespace {

/// The age limits of a kind of file.
OrbitAgeLimits limitsOf(OrbitKind kind) {
  return kind == OrbitKind::kAlmanac ? kAlmanacAgeLimits : kEphemerisAgeLimits;
}

/// A duration in the unit a reader takes in at a glance: hours below two days, days beyond.
std::string readableDuration(double s) {
  char buf[64];
  if (s < 2.0 * kSecondsPerDay) std::snprintf(buf, sizeof buf, "%.1f h", s / 3600.0);
  else std::snprintf(buf, sizeof buf, "%.1f days", s / kSecondsPerDay);
  return buf;
}

/// Almanac: the record whose t_oa (week resolved near t) is farthest from t.
std::pair<GpsTime, double> farthestAlmanacEpoch(const OrbitFileEpochs& f, const GpsTime& t) {
  std::pair<GpsTime, double> worst{t, -1.0};
  for (const auto& [sat, written] : f.epochs) {
    const GpsTime toa = resolveAlmanacEpoch(written.week, written.sow, t);
    if (std::abs(t - toa) > worst.second) worst = {toa, std::abs(t - toa)};
  }
  return worst;
}

/// Ephemeris: per satellite the t_oe nearest t; the satellite whose nearest is farthest.
std::pair<GpsTime, double> farthestNearestToe(const OrbitFileEpochs& f, const GpsTime& t) {
  std::map<SatId, std::pair<GpsTime, double>> nearest;
  for (const auto& [sat, toe] : f.epochs) {
    const double d = std::abs(t - toe);
    const auto it = nearest.find(sat);
    if (it == nearest.end() || d < it->second.second) nearest[sat] = {toe, d};
  }
  std::pair<GpsTime, double> worst{t, -1.0};
  for (const auto& [sat, e] : nearest) {
    if (e.second > worst.second) worst = e;
  }
  return worst;
}

}  // namespace

const char* orbitKindName(OrbitKind kind) { return kind == OrbitKind::kAlmanac ? "almanac" : "ephemeris"; }

OrbitFileEpochs almanacEpochs(const std::string& file, const std::vector<AlmanacRecord>& records) {
  OrbitFileEpochs f{file, OrbitKind::kAlmanac, {}};
  for (const AlmanacRecord& r : records) f.epochs.emplace_back(r.sat, GpsTime{r.week_field, r.orbit.toe.sow});
  return f;
}

OrbitFileEpochs ephemerisEpochs(const std::string& file, const NavigationData& nav) {
  OrbitFileEpochs f{file, OrbitKind::kEphemeris, {}};
  for (const BroadcastEphemeris& e : nav.ephemerides) f.epochs.emplace_back(e.sat, e.orbit.toe);
  return f;
}

OrbitFileAge orbitFileAge(const OrbitFileEpochs& file, const GpsTime& t) {
  OrbitFileAge a;
  a.file = file.file;
  a.kind = file.kind;
  a.at = t;
  a.limits = limitsOf(file.kind);
  const auto [epoch, age_s] = file.kind == OrbitKind::kAlmanac ? farthestAlmanacEpoch(file, t) : farthestNearestToe(file, t);
  if (age_s < 0.0) {  // no epochs: nothing is old
    a.epoch = t;
    return a;
  }
  a.epoch = epoch;
  a.age_s = age_s;
  a.verdict = age_s > a.limits.error_s ? AgeVerdict::kError
              : age_s > a.limits.warning_s ? AgeVerdict::kWarning
                                           : AgeVerdict::kCurrent;
  return a;
}

std::string describeEpoch(const OrbitFileAge& a) {
  char gps[96];
  std::snprintf(gps, sizeof gps, " (GPS week %d, %.0f s)", a.epoch.week, a.epoch.sow);
  return formatRfc3339(a.epoch) + gps;
}

std::string describeAge(const OrbitFileAge& a, const std::string& time_name) {
  const bool error = a.verdict == AgeVerdict::kError;
  const double limit_s = error ? a.limits.error_s : a.limits.warning_s;
  return a.file + ": the " + orbitKindName(a.kind) + (a.kind == OrbitKind::kAlmanac ? "'s t_oa " : "'s nearest t_oe ") +
         describeEpoch(a) + " is " + readableDuration(a.age_s) + " from " + time_name + " " + formatRfc3339(a.at) +
         ", beyond the " + readableDuration(limit_s) + (error ? " limit" : " warning limit");
}

std::string requireUsableAge(const OrbitFileAge& a, const std::string& time_name) {
  if (a.verdict == AgeVerdict::kError) {
    throw ParseError(a.file, 0, a.kind == OrbitKind::kAlmanac ? "almanac epoch t_oa" : "ephemeris epoch t_oe",
                     describeEpoch(a),
                     std::string("an ") + orbitKindName(a.kind) + " within " + readableDuration(a.limits.error_s) + " of " +
                         time_name + " " + formatRfc3339(a.at) + "; it is " + readableDuration(a.age_s) + " from it");
  }
  return a.verdict == AgeVerdict::kWarning ? describeAge(a, time_name) : std::string();
}

}  // namespace skylane::integrity
