#pragma once
/// \file
/// \brief One live position fix for `skylane track`, from any input format: a JSON line, an
/// NMEA 0183 epoch (GGA + GST, + GBS) or a RINEX observation epoch (README "Live tracking").
///
/// JSON line (one object per line; unknown fields are errors):
///   {"flight": "F1", "time": "2020-01-01T14:00:05Z", "lat": 47.37, "lon": 8.53, "h_ell_m": 520.0,
///    "hpl_m": 1.1, "vpl_m": 1.3,
///    "pseudoranges": [{"sat": "G05", "pr_m": 21456789.123, "ecef_m": [x, y, z]}, …],
///    "imu": {"grade": "tactical", "sigma_n_m": 0.4, "sigma_e_m": 0.4, "sigma_u_m": 0.7}}
/// or, with the IMU's own increments since the previous fix (GNSS/INS, below):
///    "imu": {"grade": "tactical", "increments": [[dt_s, dθx, dθy, dθz, dvx, dvy, dvz], …]},
///    "velocity_enu_mps": [ve, vn, vu], "attitude_deg": {"roll": r, "pitch": p, "heading": h},
///    "baro_h_m": 519.2, "mag_heading_deg": 87.0
/// - `flight` (or `vehicle`) names the approval; it may be left out when only one is tracked;
/// - `hpl_m`/`vpl_m`: the onboard protection levels (both or neither);
/// - `pseudoranges`: corrected pseudoranges (integrity/raim/live_fix.hpp), each with the
///   satellite's ECEF position at transmit time or, without it, from the mission's orbit files;
///   with them skylane computes its own position and PLs with the mission's method;
/// - `imu`: the onboard INS's position σ's (north, east, up) and grade; the PL is then
///   max(GNSS PL, the three-hypothesis nominal-INS PL) — HPL_IMU,nominal = Q⁻¹(λ·P_nom,H)·√(σ_N² + σ_E²),
///   VPL alike with σ_U (docs/method.md Eq. (7.3); λ by grade, P_nom = ⅓ of 0.5e-7 as ThreeHypothesisInsConfig).
/// - `imu.increments`: the IMU's body-frame increments (Δθ in rad, Δv in m/s, axes forward-left-
///   up, each over dt_s ≤ 1 s) from the previous fix to this one. With pseudoranges, skylane runs
///   the fault-mode GNSS/INS flow (integrity/ins/navigator.hpp: LSR FDE, tightly coupled EKF, the IMU
///   innovation test, its fault-mode PLs; the filter's noise model is the grade's). The
///   filter is aligned at a fix that gives `velocity_enu_mps` and `attitude_deg` (heading
///   clockwise from north, pitch nose up, roll right wing down) — the onboard navigation's —
///   and skylane's snapshot position; until then, and at that fix, the snapshot PLs are used;
/// - `baro_h_m` (barometric height, ellipsoidal, bias estimated) and `mag_heading_deg` (heading
///   from the magnetometer, declination removed) aid the filter when given.
/// A fix needs a protection level from one of these.

#include "integrity/gnss/nmea.hpp"
#include "integrity/raim/live_fix.hpp"
#include "maps/time.hpp"

#include <nlohmann/json_fwd.hpp>

#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace skylane::planner {

/// \brief The onboard INS's position uncertainty (1σ) [m] and grade (0 aviation, 1 tactical, 2 consumer).
struct InsUncertainty {
  int grade = 2;
  double sigma_n_m = 0.0, sigma_e_m = 0.0, sigma_u_m = 0.0;
};

/// \brief One IMU interval: body-frame (forward-left-up) angle and velocity increments.
struct ImuIncrement {
  double dt_s = 0.0;
  Eigen::Vector3d dtheta_rad = Eigen::Vector3d::Zero();
  Eigen::Vector3d dv_mps = Eigen::Vector3d::Zero();
};

/// \brief The IMU's increments from the previous fix to this one, and its grade (0 aviation,
/// 1 tactical, 2 consumer; integrity/sim/sensors.hpp gives each grade's error figures).
struct ImuRecord {
  int grade = 2;
  std::vector<ImuIncrement> increments;
  [[nodiscard]] double span_s() const {
    double s = 0.0;
    for (const ImuIncrement& i : increments) s += i.dt_s;
    return s;
  }
};

/// \brief Where a fix's protection levels came from.
enum class PlSource { kOnboard, kRaw, kNmeaGst, kIns, kGnssIns, kMavlinkAccuracy, kUbxPl, kUbxAccuracy };

/// \brief "onboard", "raw", "nmea_gst", "ins" (the INS σ block alone), "gnss_ins" (the fault-mode
/// flow over the fix's pseudoranges and IMU increments), "mavlink_accuracy" (a MAVLink GPS
/// message's h_acc/v_acc, link/mavlink/fix_source.hpp), "ubx_pl" (a u-blox receiver's UBX-NAV-PL,
/// converted to the mission's risk) and "ubx_accuracy" (UBX-NAV-PVT's hAcc/vAcc; link/ubx/).
[[nodiscard]] const char* plSourceName(PlSource s);

/// \brief One fix of a stream.
struct TrackFix {
  std::string flight;  ///< empty: the only flight tracked
  maps::GpsTime time;
  double lat_rad = 0.0, lon_rad = 0.0, h_ell_m = 0.0;
  std::optional<double> hpl_m, vpl_m;          ///< onboard (or from GST)
  PlSource pl_source = PlSource::kOnboard;
  std::vector<integrity::RawRange> ranges;     ///< raw pseudoranges, when given
  std::optional<InsUncertainty> ins;
  std::optional<ImuRecord> imu;                ///< raw IMU increments, when given
  std::optional<Eigen::Vector3d> velocity_enu_mps;
  std::optional<Eigen::Vector3d> attitude_rad;  ///< roll, pitch, heading
  std::optional<double> baro_h_m, mag_heading_rad;
  std::string source;  ///< "file:line"
  std::size_t line = 0;
  std::string note;    ///< what the source wants the fix event to say (e.g. a receiver PL it could not use)
};

/// \brief Parses one JSON-lines fix (the file comment's schema).
/// \throws maps::ParseError naming `source`, the field, the value and what was expected.
[[nodiscard]] TrackFix parseTrackFixJson(const nlohmann::json& doc, const std::string& source);
/// \brief One JSON-lines fix from its text: a plain line (one flat object of flight or vehicle,
/// time, position, onboard PLs, baro_h_m, mag_heading_deg; ASCII strings without escapes) is
/// read directly, anything else through maps::parseJsonLine and parseTrackFixJson — the same fix
/// and the same errors either way (fix_line.cpp). \throws maps::ParseError as parseTrackFixJson.
[[nodiscard]] TrackFix parseTrackFixLine(const std::string& text, const std::string& source);
/// \brief The same into `out` (all of it replaced): a plain line is read into out's storage, so a
/// stream that keeps one fix allocates nothing per line once its strings have grown.
void parseTrackFixLine(const std::string& text, const std::string& source, TrackFix& out);
/// \brief The direct way alone: the fix of a plain line whose values parseTrackFixJson accepts,
/// else none (never an error of its own).
[[nodiscard]] std::optional<TrackFix> parsePlainFixLine(std::string_view text, const std::string& source);
/// \brief The same into `out`: true when the line was read (all of `out` replaced), false (out
/// untouched) when it goes the general way.
[[nodiscard]] bool parsePlainFixLine(std::string_view text, const std::string& source, TrackFix& out);
/// \brief `fix` as a default TrackFix, its strings keeping their storage.
void clearTrackFix(TrackFix& fix);

/// \brief A fix as one JSON-lines object (the file comment's schema; parseTrackFixJson reads
/// it back: positions to 1e-9°, heights and ranges to 0.1 mm, increments with full precision).
[[nodiscard]] nlohmann::json trackFixJson(const TrackFix& fix);

/// \brief Integrity risks behind the NMEA protection levels.
struct NmeaPlRisk {
  double p_h = 2e-9;    ///< horizontal: K_H = √(−2 ln p_h) (the RAIM fault-free horizontal budget)
  double p_v = 9.8e-8;  ///< vertical: K_V = Q⁻¹(p_v / 2)
};

/// \brief An NMEA epoch as a fix. HPL = K_H·σ_H with σ_H the GST error ellipse's semi-major axis
/// (the larger of the latitude and longitude σ's when the ellipse is empty): P(|e_H| > K·σ_major)
/// ≤ e^(−K²/2) for any ellipse. VPL = K_V·σ_alt. With GBS, each σ is the larger of GST's and the
/// receiver's RAIM expected error. A fix without GST has no PL.
/// \throws maps::ParseError naming `source` when the epoch has no position (quality 0 or empty
/// fields) or no GST.
[[nodiscard]] TrackFix trackFixFromNmea(const integrity::NmeaFix& fix, const std::string& source, const NmeaPlRisk& risk = {});

/// \brief The PLs of an INS uncertainty (the three-hypothesis INS PL's nominal hypothesis, docs/method.md Eq. (7.3); see the file comment).
[[nodiscard]] std::pair<double, double> insNominalPl(const InsUncertainty& ins);

}  // namespace skylane::planner
