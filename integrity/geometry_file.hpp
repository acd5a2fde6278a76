#pragma once
/// \file
/// \brief The geometry file of `skylane integrity pl`: satellites by azimuth/elevation, the
/// integrity support message, the airborne error model and the integrity requirements.
///
/// ```json
/// {"satellites":[{"id":"G01","az_deg":45,"el_deg":30}, …],
///  "ism":{"GPS":{"ura_m":0.75,"ure_m":0.5,"bnom_m":0.5,"psat":1e-5,"pconst":1e-8},"Galileo":{…}},
///  "user_error_model":"dual_frequency" | "single_frequency" | {"default":…, "GPS":…},
///  "requirements":{"phmi_vert":9.8e-8,"phmi_hor":2e-9,"pfa_vert":3.9e-6,"pfa_hor":9e-8,
///                  "p_thres":8e-8,"p_emt":1e-5,"tol_pl_m":0.05,"val_m":35,"hal_m":40,
///                  "emt_m":15,"sigma_acc_m":1.87},
///  "raim":{"pfa":1e-6,"pmd":1e-3,"formula":"pbias_plus_noise"|"brown"},
///  "araim":{"fault_mode_rule":"adds_until_threshold"|"joint_events"|"blanch2012",
///           "fc_thres":0,"emt_probability":"mode_prior"|"event_product","horizontal_only":false},
///  "position":{"lat_deg":…,"lon_deg":…,"h_m":…},   // optional: single-frequency τ_vert
///  "iono_tau_vert_m": 9}                               // optional override
/// ```
/// Every field but `satellites` is optional; defaults are the ARAIM ADD's LPV-200 values.

#include "integrity/araim/mhss.hpp"
#include "integrity/raim/raim.hpp"
#include "integrity/requirements.hpp"

#include <nlohmann/json_fwd.hpp>

#include <optional>
#include <string>

namespace skylane::integrity {


/// \brief A parsed geometry file.
struct GeometryInput {
  std::vector<SatLook> satellites;
  ErrorModel model;
  Requirements requirements;
  RaimConfig raim;
  AraimConfig araim;  ///< requirements copied from `requirements`
  std::optional<maps::Geodetic> position;
  double tau_vert_m = 9.0;  ///< resolved single-frequency ionospheric bound
};

/// \brief Parses a geometry document; `source` names it in errors (ParseError with the JSON
/// path as the field, e.g. "satellites[3].el_deg").
[[nodiscard]] GeometryInput parseGeometry(const nlohmann::json& doc, const std::string& source);
/// \brief Reads and parses a geometry file (JSON syntax errors name the line).
[[nodiscard]] GeometryInput loadGeometryFile(const std::string& path);

/// \brief Parses the "ism" object into `model` (per-constellation overrides).
void parseIsm(const nlohmann::json& ism, ErrorModel& model, const std::string& source, const std::string& path);

}  // namespace skylane::integrity
