#pragma once
/// \file
/// \brief A rehearsal flight for `skylane track` (`skylane fly`): an approved route flown by skylane's GNSS/INS sensor
/// simulator (docs/method.md §5.6) (integrity/sim: real orbits, the ARAIM error model, fault injection),
/// one tracker fix per GNSS epoch with raw pseudoranges and, optionally, the IMU's increments,
/// the onboard velocity and attitude and the barometer and magnetometer — what a vehicle's
/// receiver and IMU would stream.

#include "integrity/sim/sensors.hpp"
#include "planner/approval.hpp"
#include "planner/report_formats.hpp"
#include "planner/tracking/track_fix.hpp"

#include <nlohmann/json_fwd.hpp>

#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

namespace skylane::planner {

/// \brief What the IMU side of a simulated flight gives the tracker (GNSS/INS fixes).
struct ImuFeed {
  integrity::ins::ImuGrade grade = integrity::ins::ImuGrade::kTactical;
  bool aiding = true;  ///< barometer and magnetometer in every fix
  /// The onboard navigation's velocity and attitude in each fix (the filter aligns with them):
  /// the truth perturbed with the σ's the filter assumes at alignment (EkfConfig defaults).
  double velocity_sigma_mps = 0.5;
  double attitude_sigma_rad = 2.0 * M_PI / 180.0;
};

/// \brief How the route is flown.
struct FlightSimOptions {
  std::string flight = "F1";    ///< the flight id written in every fix
  std::uint64_t seed = 1;       ///< every random draw (sensors, faults, the onboard solution)
  double turn_radius_m = 30.0;  ///< corners are rounded (the simulator's trajectory)
  double reported_dh_m = 0.0;   ///< the reported position is the truth raised by this (it only starts skylane's solution)
  std::vector<integrity::sim::FaultSpec> faults;
  std::optional<ImuFeed> imu;   ///< absent: GNSS only
};

/// \brief One GNSS epoch of the flight as a fix, with what the simulator did.
struct SimulatedFix {
  TrackFix fix;
  std::optional<integrity::SatId> faulty;  ///< the satellite carrying an injected bias, if any
  double t_s = 0.0;                        ///< after departure
  maps::Geodetic truth;                    ///< where the vehicle is
};

/// \brief Flies `flight`'s route from its departure at the mission's cruise speed. Every
/// pseudorange carries its satellite's position. `progress` (optional) gets the fraction done.
[[nodiscard]] std::vector<SimulatedFix> simulateFlight(const ApprovedFlight& flight, const Approver& approver,
                                                       const FlightSimOptions& options,
                                                       const std::function<void(double)>& progress = {});

/// \brief The same for an approval report's route (a rehearsal before the report is written).
[[nodiscard]] std::vector<SimulatedFix> simulateFlight(const ApprovalReport& report, const Approver& approver,
                                                       const FlightSimOptions& options,
                                                       const std::function<void(double)>& progress = {});

}  // namespace skylane::planner
