/// \file
/// \brief Orbit files (YUMA/SEM almanacs, RINEX navigation files) uploaded for missions: an
/// operator's for its own missions, the authority's for everyone's, beside the service's
/// configured orbits folder. A mission names them in "orbits"; an upload is checked by the same
/// loader an approval uses.

#include "integrity/gnss/orbit_source.hpp"
#include "service/service_impl.hpp"

#include <algorithm>

namespace skylane::service {

namespace fs = std::filesystem;
using nlohmann::json;

namespace {

bool plainName(const std::string& n) {
  return !n.empty() && n.size() <= 100 && n.front() != '.' &&
         std::all_of(n.begin(), n.end(), [](char c) { return std::isalnum(static_cast<unsigned char>(c)) || c == '.' || c == '_' || c == '-'; });
}

/// The folder of a caller's uploads ("_authority" for the authority's, which every mission may use).
std::string uploadFolder(const std::string& owner) { return owner.empty() ? "_authority" : "op-" + owner; }

}  // namespace

std::optional<fs::path> ServiceImpl::orbitFile(const Principal& who, const std::string& name) const {
  if (!plainName(name)) return std::nullopt;
  for (const fs::path& p : {files / "orbits" / uploadFolder(who.owner()) / name, files / "orbits" / uploadFolder("") / name}) {
    if (fs::is_regular_file(p)) return p;
  }
  if (!options.orbits_dir.empty() && fs::is_regular_file(fs::path(options.orbits_dir) / name)) return fs::absolute(fs::path(options.orbits_dir) / name);
  return std::nullopt;
}

HttpResponse ServiceImpl::orbitsRoute(const HttpRequest& r, const Principal& who, const Segments& s) {
  if (s.size() == 2) {
    if (r.method != "GET") return methodNotAllowed("GET");
    json list = json::array();
    auto add = [&](const fs::path& dir, const char* from) {
      std::error_code ec;
      for (const auto& e : fs::directory_iterator(dir, ec)) {
        if (e.is_regular_file() && plainName(e.path().filename().string())) list.push_back({{"name", e.path().filename().string()}, {"from", from}});
      }
    };
    add(files / "orbits" / uploadFolder(who.owner()), who.authority ? "authority" : "operator");
    if (!who.authority) add(files / "orbits" / uploadFolder(""), "authority");
    if (!options.orbits_dir.empty()) add(options.orbits_dir, "service");
    return jsonBody(200, {{"orbits", list}});
  }
  if (s.size() != 3) return notFound("route " + r.path);
  if (r.method != "PUT") return methodNotAllowed("PUT");
  if (auto bad = requireContentType(r, {"text/plain", "application/octet-stream"})) return *bad;
  if (!plainName(s[2])) return errorResponse(400, "orbit file name \"" + s[2].substr(0, 64) + "\": expected 1 to 100 letters, digits, '.', '_' or '-', not starting with '.'");
  const fs::path dir = files / "orbits" / uploadFolder(who.owner());
  fs::create_directories(dir);
  const fs::path tmp = dir / ("." + s[2] + ".upload");
  writeFileAtomically(tmp, r.body);
  try {
    (void)integrity::loadOrbitFiles({tmp.string()}, "the request body", "$");
  } catch (const std::exception& e) {
    std::error_code ec;
    fs::remove(tmp, ec);
    std::string msg = e.what();
    for (std::size_t at; (at = msg.find(tmp.string())) != std::string::npos;) msg.replace(at, tmp.string().size(), s[2]);
    return errorResponse(400, msg);
  }
  fs::rename(tmp, dir / s[2]);
  log("orbit file " + s[2] + " uploaded by " + (who.authority ? std::string("the authority") : who.owner()));
  return jsonBody(201, {{"name", s[2]}, {"bytes", r.body.size()}});
}

}  // namespace skylane::service
