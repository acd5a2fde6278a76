#include "link/mavlink/mission_upload.hpp"

#include <cmath>

namespace skylane::link::mavlink {
namespace {

using nlohmann::json;

constexpr std::uint16_t kFencePolygonInclusion = 5001;
constexpr std::uint16_t kFencePolygonExclusion = 5002;
constexpr std::uint16_t kFenceCircleInclusion = 5003;
constexpr std::uint16_t kFenceCircleExclusion = 5004;
constexpr std::uint8_t kFrameGlobal = 0;  ///< MAV_FRAME_GLOBAL (the fence's altitude is not used)

std::int32_t degE7(double deg) { return static_cast<std::int32_t>(std::lround(deg * 1e7)); }

/// A JSON number as a float, NaN for null (a MISSION_ITEM parameter left unused).
float paramOf(const json& v) { return v.is_null() ? std::nanf("") : v.get<float>(); }

}  // namespace

const char* missionTypeName(MissionType t) { return t == MissionType::kFence ? "fence" : "mission"; }

std::string missionResultName(std::uint8_t result) {
  static const char* const kNames[] = {"MAV_MISSION_ACCEPTED", "MAV_MISSION_ERROR", "MAV_MISSION_UNSUPPORTED_FRAME",
                                       "MAV_MISSION_UNSUPPORTED", "MAV_MISSION_NO_SPACE", "MAV_MISSION_INVALID",
                                       "MAV_MISSION_INVALID_PARAM1", "MAV_MISSION_INVALID_PARAM2", "MAV_MISSION_INVALID_PARAM3",
                                       "MAV_MISSION_INVALID_PARAM4", "MAV_MISSION_INVALID_PARAM5_X", "MAV_MISSION_INVALID_PARAM6_Y",
                                       "MAV_MISSION_INVALID_PARAM7", "MAV_MISSION_INVALID_SEQUENCE", "MAV_MISSION_DENIED",
                                       "MAV_MISSION_OPERATION_CANCELLED"};
  return result < sizeof kNames / sizeof kNames[0] ? kNames[result] : "MAV_MISSION_RESULT " + std::to_string(result);
}

std::vector<MissionItem> missionItemsOfPlan(const json& plan) {
  std::vector<MissionItem> out;
  for (const json& it : plan.at("mission").at("items")) {
    const json& p = it.at("params");
    MissionItem m;
    m.command = it.at("command").get<std::uint16_t>();
    m.frame = it.at("frame").get<std::uint8_t>();
    for (int i = 0; i < 4; ++i) m.params[static_cast<std::size_t>(i)] = paramOf(p.at(static_cast<std::size_t>(i)));
    m.x = degE7(p.at(4).get<double>());
    m.y = degE7(p.at(5).get<double>());
    m.z = p.at(6).get<float>();
    out.push_back(m);
  }
  return out;
}

std::vector<MissionItem> fenceItemsOfPlan(const json& plan) {
  std::vector<MissionItem> out;
  const json& fence = plan.at("geoFence");
  for (const json& poly : fence.at("polygons")) {
    const json& ring = poly.at("polygon");
    for (const json& v : ring) {
      MissionItem m;
      m.command = poly.at("inclusion").get<bool>() ? kFencePolygonInclusion : kFencePolygonExclusion;
      m.frame = kFrameGlobal;
      m.params[0] = static_cast<float>(ring.size());
      m.x = degE7(v.at(0).get<double>());
      m.y = degE7(v.at(1).get<double>());
      out.push_back(m);
    }
  }
  for (const json& c : fence.at("circles")) {
    MissionItem m;
    m.command = c.at("inclusion").get<bool>() ? kFenceCircleInclusion : kFenceCircleExclusion;
    m.frame = kFrameGlobal;
    m.params[0] = c.at("circle").at("radius").get<float>();
    m.x = degE7(c.at("circle").at("center").at(0).get<double>());
    m.y = degE7(c.at("circle").at("center").at(1).get<double>());
    out.push_back(m);
  }
  return out;
}

MissionUpload::MissionUpload(MissionType type, std::vector<MissionItem> items, LinkIds ids, UploadTiming timing)
    : type_(type), items_(std::move(items)), ids_(ids), timing_(timing) {}

std::vector<std::uint8_t> MissionUpload::countFrame(std::uint8_t& seq) const {
  PayloadWriter w(*findMessage(kMissionCount));
  w.set<std::uint8_t>("target_system", ids_.target_system)
      .set<std::uint8_t>("target_component", ids_.target_component)
      .set<std::uint16_t>("count", static_cast<std::uint16_t>(items_.size()))
      .set<std::uint8_t>("mission_type", static_cast<std::uint8_t>(type_));
  return encodeFrame(w.def(), w.data(), seq++, ids_.own_system, ids_.own_component);
}

std::vector<std::uint8_t> MissionUpload::itemFrame(std::uint16_t index, std::uint8_t& seq) const {
  const MissionItem& m = items_[index];
  PayloadWriter w(*findMessage(kMissionItemInt));
  w.set<std::uint8_t>("target_system", ids_.target_system)
      .set<std::uint8_t>("target_component", ids_.target_component)
      .set<std::uint16_t>("seq", index)
      .set<std::uint8_t>("frame", m.frame)
      .set<std::uint16_t>("command", m.command)
      .set<std::uint8_t>("current", 0)
      .set<std::uint8_t>("autocontinue", 1)
      .set<float>("param1", m.params[0])
      .set<float>("param2", m.params[1])
      .set<float>("param3", m.params[2])
      .set<float>("param4", m.params[3])
      .set<std::int32_t>("x", m.x)
      .set<std::int32_t>("y", m.y)
      .set<float>("z", m.z)
      .set<std::uint8_t>("mission_type", static_cast<std::uint8_t>(type_));
  return encodeFrame(w.def(), w.data(), seq++, ids_.own_system, ids_.own_component);
}

bool MissionUpload::ours(const Frame& fr) const {
  if (fr.sysid != ids_.target_system) return false;
  const MessageDef& d = *fr.def;
  if (fr.get<std::uint8_t>(d.field("target_system")) != ids_.own_system) return false;
  return fr.get<std::uint8_t>(d.field("mission_type")) == static_cast<std::uint8_t>(type_);
}

std::vector<std::vector<std::uint8_t>> MissionUpload::start(double now_s, std::uint8_t& seq) {
  state_ = State::kSending;
  last_frame_ = countFrame(seq);
  last_sent_s_ = now_s;
  retries_ = 0;
  return {last_frame_};
}

std::vector<std::vector<std::uint8_t>> MissionUpload::onFrame(const Frame& fr, double now_s, std::uint8_t& seq) {
  if (state_ != State::kSending) return {};
  const bool request = fr.msgid == kMissionRequestInt || fr.msgid == kMissionRequest;
  if ((!request && fr.msgid != kMissionAck) || !ours(fr)) return {};
  if (fr.msgid == kMissionAck) {
    result_ = fr.get<std::uint8_t>(fr.def->field("type"));
    state_ = result_ == 0 ? State::kAccepted : State::kRefused;
    return {};
  }
  const auto index = fr.get<std::uint16_t>(fr.def->field("seq"));
  if (index >= items_.size()) return {};  // the vehicle's own mistake: it will time out or refuse
  last_frame_ = itemFrame(index, seq);
  last_sent_s_ = now_s;
  retries_ = 0;
  return {last_frame_};
}

std::vector<std::vector<std::uint8_t>> MissionUpload::poll(double now_s, std::uint8_t& seq) {
  if (state_ != State::kSending || now_s - last_sent_s_ < timing_.timeout_s) return {};
  if (retries_ >= timing_.max_retries) {
    state_ = State::kTimedOut;
    return {};
  }
  ++retries_;
  ++resends_;
  last_sent_s_ = now_s;
  (void)seq;  // the same frame again, with its sequence number as first sent
  return {last_frame_};
}

}  // namespace skylane::link::mavlink
