#pragma once
/// \file
/// \brief A GNSS/INS simulation scenario: where and when, the flight, the sensors, the faults,
/// the integrity requirement; read from JSON (schema in the README, "skylane simulate").

#include "integrity/ins/navigator.hpp"
#include "integrity/sim/sensors.hpp"
#include "integrity/sim/trajectory.hpp"

#include <nlohmann/json_fwd.hpp>

namespace skylane::maps {
struct JsonNode;
}

#include <cstdint>
#include <string>
#include <vector>

namespace skylane::integrity::sim {

/// \brief Everything one simulated flight needs.
struct Scenario {
  std::string source;  ///< file name, for messages
  maps::Geodetic origin;
  GpsTime start;
  std::vector<std::string> orbit_files;  ///< almanacs (YUMA/SEM) or RINEX navigation files, resolved paths
  std::vector<Waypoint> waypoints;
  double turn_radius_m = 30.0;
  ImuGrade grade = ImuGrade::kConsumer;
  SensorSpec sensors;
  std::vector<FaultSpec> faults;
  ins::NavigatorConfig navigator;
  double hal_m = 40.0;  ///< Zhao & Song 2024 Table 2 (LPV): HAL 40 m, VAL 50 m
  double val_m = 50.0;
  std::uint64_t seed = 1;
};

/// \brief The navigator's filter and three-hypothesis INS PL settings that match an IMU grade and the sensors
/// (the filter assumes the simulator's noise figures; the three-hypothesis λ from the grade).
void matchFilterToSensors(Scenario& s);
/// \brief The same for any navigator: its filter noise from `sensors` (IMU, clock, baro,
/// magnetometer), its error model and mask, the three-hypothesis λ from `grade`.
void matchFilterToSensors(ins::NavigatorConfig& nav, const SensorSpec& sensors, ImuGrade grade);

/// \brief Parses a scenario document; relative file names are resolved against `base_dir`.
/// \throws maps::ParseError naming the source, the field and what was expected.
[[nodiscard]] Scenario parseScenario(const nlohmann::json& doc, const std::string& source, const std::string& base_dir);
/// \brief One fault object of a scenario's "faults" (README, "skylane simulate").
/// \throws maps::ParseError naming the field and what was expected.
[[nodiscard]] FaultSpec parseFault(const maps::JsonNode& f);
/// \brief readJsonFile + parseScenario (base directory = the file's directory).
[[nodiscard]] Scenario loadScenario(const std::string& path);

}  // namespace skylane::integrity::sim
