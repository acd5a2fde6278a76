/// \file
/// \brief libFuzzer target for what the NATS workers read from the wire besides fixes (those are
/// fuzz_track's): an approval bundle (service/approval_bundle.hpp) under a subject.
///
/// The input's first line is a subject, the rest a bundle's JSON text.
///
/// Checks: the subject's tokens joined again give the subject, and an id validId() accepts is a
/// single NATS token with no wildcard or space; parseBundle returns or throws maps::ParseError
/// only; a parsed bundle written out and parsed again is the same; unpacking it writes only
/// inside its folder.

#include "fuzz/fuzz_common.hpp"
#include "maps/parse_error.hpp"
#include "service/approval_bundle.hpp"
#include "service/nats_layout.hpp"

#include <unistd.h>

#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <string>

namespace {

namespace fs = std::filesystem;
using namespace skylane;

void checkSubject(const std::string& subject) {
  const std::vector<std::string> t = service::nats::subjectTokens(subject);
  std::string joined;
  for (std::size_t i = 0; i < t.size(); ++i) joined += (i ? "." : "") + t[i];
  if (joined != subject) std::abort();
  for (const std::string& id : t) {
    if (!service::nats::validId(id)) continue;
    if (id.find_first_of(".*> \t\r\n") != std::string::npos || id.empty() || id.size() > 64) std::abort();
  }
}

/// Every file under `dir` (resolved) lies inside it.
void checkInside(const fs::path& dir) {
  const fs::path root = fs::weakly_canonical(dir);
  for (const auto& e : fs::recursive_directory_iterator(dir)) {
    const std::string p = fs::weakly_canonical(e.path()).string();
    if (p.rfind(root.string() + "/", 0) != 0) std::abort();
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  const std::size_t nl = text.find('\n');
  checkSubject(text.substr(0, nl));
  if (nl == std::string::npos) return 0;
  service::ApprovalBundle b;
  try {
    b = service::parseBundle(text.substr(nl + 1), "fuzz bundle");
  } catch (const maps::ParseError&) {
    return 0;
  }
  const service::ApprovalBundle again = service::parseBundle(service::bundleText(b), "fuzz bundle again");
  if (again.mission != b.mission || again.files != b.files || again.report != b.report || again.zonesets.size() != b.zonesets.size()) std::abort();
  static const fs::path dir = fs::temp_directory_path() / ("skylane-fuzz-nats-" + std::to_string(getpid()));
  std::error_code ec;
  fs::remove_all(dir, ec);
  try {
    service::unpackBundle(b, dir / "bundle");
  } catch (const std::exception&) {  // a name the file system refuses (too long, a file in the way)
  }
  if (fs::exists(dir / "bundle")) checkInside(dir / "bundle");
  fs::remove_all(dir, ec);
  return 0;
}
