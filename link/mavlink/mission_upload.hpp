#pragma once
/// \file
/// \brief The MAVLink mission protocol's upload, from the ground station's side
/// (docs/vehicle_link.md §2.4): MISSION_COUNT → the vehicle's MISSION_REQUEST_INT (or the older
/// MISSION_REQUEST) per item → MISSION_ITEM_INT → the vehicle's MISSION_ACK, for one mission type
/// (MISSION or FENCE). A message the vehicle does not answer is sent again after the timeout, up
/// to the retry limit; then the upload has timed out.
///
/// Items come from a QGroundControl plan document (link/qgc_plan.hpp): the mission's SimpleItems
/// as they are, and the geofence as MAV_CMD_NAV_FENCE_POLYGON_VERTEX_INCLUSION/EXCLUSION
/// (5001/5002: param1 the polygon's vertex count, one item per vertex) and
/// MAV_CMD_NAV_FENCE_CIRCLE_INCLUSION/EXCLUSION (5003/5004: param1 the radius).

#include "link/mavlink/wire.hpp"

#include <nlohmann/json.hpp>

#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace skylane::link::mavlink {

/// \brief MAV_MISSION_TYPE values.
enum class MissionType : std::uint8_t { kMission = 0, kFence = 1 };
[[nodiscard]] const char* missionTypeName(MissionType t);
/// \brief The name of a MAV_MISSION_RESULT value ("MAV_MISSION_DENIED" …).
[[nodiscard]] std::string missionResultName(std::uint8_t result);

/// \brief One MISSION_ITEM_INT's content.
struct MissionItem {
  std::uint16_t command = 0;
  std::uint8_t frame = 0;  ///< MAV_FRAME
  std::array<float, 4> params{};
  std::int32_t x = 0, y = 0;  ///< latitude, longitude [degE7]
  float z = 0.0f;             ///< altitude in `frame`
};

/// \brief The mission items of a plan document (`mission.items`, SimpleItems).
[[nodiscard]] std::vector<MissionItem> missionItemsOfPlan(const nlohmann::json& plan);
/// \brief The fence items of a plan document (`geoFence.polygons`, `geoFence.circles`).
[[nodiscard]] std::vector<MissionItem> fenceItemsOfPlan(const nlohmann::json& plan);

/// \brief Who sends, and to whom.
struct LinkIds {
  std::uint8_t own_system = 255;    ///< a ground station's system id
  std::uint8_t own_component = 190; ///< MAV_COMP_ID_MISSIONPLANNER
  std::uint8_t target_system = 1;
  std::uint8_t target_component = 1;
};

/// \brief Timeout and retries of the protocol (the MAVLink mission protocol's defaults).
struct UploadTiming {
  double timeout_s = 1.5;
  int max_retries = 5;
};

class MissionUpload {
 public:
  enum class State { kNotStarted, kSending, kAccepted, kRefused, kTimedOut };
  MissionUpload(MissionType type, std::vector<MissionItem> items, LinkIds ids, UploadTiming timing = {});

  /// \brief The frames that start the upload (MISSION_COUNT) at `now_s` (a steady clock).
  [[nodiscard]] std::vector<std::vector<std::uint8_t>> start(double now_s, std::uint8_t& seq);
  /// \brief A frame from the vehicle: the frames it asks for (an item), or none.
  [[nodiscard]] std::vector<std::vector<std::uint8_t>> onFrame(const Frame& fr, double now_s, std::uint8_t& seq);
  /// \brief Time passes: the last message again after the timeout, or the upload times out.
  [[nodiscard]] std::vector<std::vector<std::uint8_t>> poll(double now_s, std::uint8_t& seq);

  [[nodiscard]] State state() const { return state_; }
  [[nodiscard]] bool done() const { return state_ == State::kAccepted || state_ == State::kRefused || state_ == State::kTimedOut; }
  [[nodiscard]] MissionType type() const { return type_; }
  [[nodiscard]] std::size_t items() const { return items_.size(); }
  [[nodiscard]] std::uint8_t result() const { return result_; }  ///< the vehicle's MAV_MISSION_RESULT
  [[nodiscard]] int resends() const { return resends_; }

 private:
  std::vector<std::uint8_t> countFrame(std::uint8_t& seq) const;
  std::vector<std::uint8_t> itemFrame(std::uint16_t index, std::uint8_t& seq) const;
  /// Whether a frame is the vehicle's, addressed to this ground station, of this mission type.
  bool ours(const Frame& fr) const;

  MissionType type_;
  std::vector<MissionItem> items_;
  LinkIds ids_;
  UploadTiming timing_;
  State state_ = State::kNotStarted;
  std::uint8_t result_ = 0;
  double last_sent_s_ = 0.0;
  std::vector<std::uint8_t> last_frame_;  ///< what goes again on a timeout
  int retries_ = 0, resends_ = 0;
};

}  // namespace skylane::link::mavlink
