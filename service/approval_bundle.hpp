#pragma once
/// \file
/// \brief A mission with the files it names, carried as one JSON document over NATS: an approval
/// request (the mission and its zone, orbit, buildings and .plan files) and, once approved, the
/// same with the approval report — what a track worker on another machine needs to track the
/// flight. Files are text (JSON, almanacs, RINEX); a terrain raster is not carried (a mission
/// for the workers gives `ground_amsl_m`).
///
/// Form: {"mission": "<mission.json as text>", "files": {"files/0-zones.json": "<text>", …},
///        "zonesets": {"authority.zurich": {"file": "files/zs-authority.zurich.json", "version": 3}},
///        "report": "<report.json as text>"} — texts kept byte for byte, so the report's SHA-256
/// of the mission still holds where the bundle is unpacked. `zonesets` names the zone sets of the
/// skylane_zonesets bucket the approve worker resolved the mission's `zonesets` to: the file each
/// is in and the version (bucket revision) taken; a track worker follows their later versions.

#include <nlohmann/json_fwd.hpp>

#include <filesystem>
#include <cstdint>
#include <map>
#include <string>

namespace skylane::service {

/// \brief A mission, its files by relative name, and (after approval) the report.
struct ApprovalBundle {
  std::string mission;                       ///< mission.json as text, its file names relative
  std::map<std::string, std::string> files;  ///< relative name → content
  std::string report;                        ///< report.json as text; empty before approval
  struct ZoneSetFile {
    std::string file;
    std::uint64_t version = 0;
  };
  std::map<std::string, ZoneSetFile> zonesets;  ///< zone set name → its file and version
};

/// \brief The zonesets part as JSON text (also kept as zonesets.json beside an unpacked bundle).
[[nodiscard]] std::string zoneSetsText(const std::map<std::string, ApprovalBundle::ZoneSetFile>& sets);
/// \brief The zone sets written beside an unpacked bundle (none when there is no zonesets.json).
[[nodiscard]] std::map<std::string, ApprovalBundle::ZoneSetFile> readZoneSets(const std::filesystem::path& dir);

/// \brief Reads a mission file and every file it names; the names become `files/<i>-<name>`.
/// \throws maps::ParseError naming the mission, the field and what was expected (a terrain
/// raster, an unreadable file).
[[nodiscard]] ApprovalBundle packMission(const std::string& mission_path);
/// \brief The bundle as JSON text.
[[nodiscard]] std::string bundleText(const ApprovalBundle& b);
/// \brief A bundle from JSON text. \throws maps::ParseError naming `source`, the field and what
/// was expected (a file name that is not relative and inside the bundle's folder).
[[nodiscard]] ApprovalBundle parseBundle(const std::string& text, const std::string& source);
/// \brief Writes mission.json, the files, report.json and zonesets.json (when there are) into `dir`.
void unpackBundle(const ApprovalBundle& b, const std::filesystem::path& dir);

}  // namespace skylane::service
