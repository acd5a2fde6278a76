#include "integrity/ins/filter_tuning.hpp"

namespace skylane::integrity::ins {

void tuneFilterToSensors(NavigatorConfig& nav, const SensorErrorSpec& sensors, ImuGrade grade) {
  EkfConfig& e = nav.ekf;
  const ImuSpec& imu = sensors.imu;
  e.accel_noise_mps_rts = imu.accel_noise_mps_rts;
  e.gyro_noise_rad_rts = imu.gyro_noise_rad_rts;
  e.accel_bias_rw_mps2_rts = imu.accel_bias_rw_mps2_rts;
  e.gyro_bias_rw_radps_rts = imu.gyro_bias_rw_radps_rts;
  e.accel_bias_mps2 = imu.accel_bias_mps2;
  e.gyro_bias_radps = imu.gyro_bias_radps;
  e.clock_h0 = sensors.clock_h0;
  e.clock_hm2 = sensors.clock_hm2;
  e.baro_noise_m = sensors.baro_noise_m;
  e.baro_bias_m = sensors.baro_bias_m;
  e.baro_bias_rw_m_rts = sensors.baro_bias_rw_m_rts;
  e.heading_noise_rad = sensors.heading_noise_rad;
  nav.three_hypothesis_ins.lambda = imuErrorWeightRatio(static_cast<int>(grade));
  nav.three_hypothesis_ins.phmi_h = nav.fault_modes.risk.i_req * (1.0 - nav.fault_modes.risk.vertical_share);
  nav.three_hypothesis_ins.phmi_v = nav.fault_modes.risk.i_req * nav.fault_modes.risk.vertical_share;
}

NavigatorConfig trackingNavigatorConfig(ImuGrade grade, const ErrorModel& model, double elevation_mask_rad,
                                        double initial_position_m) {
  SensorErrorSpec sensors;
  sensors.imu = imuSpec(grade);
  NavigatorConfig c;
  tuneFilterToSensors(c, sensors, grade);
  c.model = model;
  c.elevation_mask_rad = elevation_mask_rad;
  c.ekf.initial_position_m = initial_position_m;
  c.compute_araim = false;  // the snapshot ARAIM beside the flow is not used when tracking
  return c;
}

}  // namespace skylane::integrity::ins
