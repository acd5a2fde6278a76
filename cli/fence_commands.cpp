#include "cli/fence_commands.hpp"

#include "geofence/verdict_json.hpp"

#include "airspace/validation.hpp"
#include "cli/json_numbers.hpp"
#include "cli/skymask_commands.hpp"
#include "geofence/corridor_file.hpp"
#include "maps/text_file.hpp"
#include "geofence/fix.hpp"
#include "geofence/obstruction_files.hpp"
#include "geofence/verdict_json.hpp"
#include "geofence/fix_line.hpp"
#include "geofence/verdict_writer.hpp"
#include "maps/geoid.hpp"
#include "maps/json_node.hpp"
#include "maps/parse_error.hpp"
#include "maps/plane_grid.hpp"

#include <algorithm>
#include <cmath>
#include <deque>
#include <fstream>
#include <future>
#include <iostream>
#include <memory>
#include <optional>
#include <thread>
#include <utility>
#include <vector>

namespace skylane::cli {
namespace {

using maps::ParseError;
using nlohmann::json;

struct FenceCheckOptions {
  std::string corridor;
  std::vector<std::string> zones;
  std::string format = "auto";
  std::string terrain;
  std::string buildings;
  std::optional<double> ground_amsl_m;
  std::vector<std::string> authorise;
  double horizon_m = 100.0;
  double tolerance_m = 1e-6;
  std::string fix;
  std::string fixes;
  unsigned threads = 0;  ///< 0: one per processor for a file, one for stdin
};

json checkFix(const geofence::Fix& f, const geofence::Fence& fence, const maps::PlaneGrid& projection) {
  const Eigen::Vector2d p = projection.toPlane(f.lat_rad, f.lon_rad);
  const geofence::TimedVolume v{f.t0, f.t1, {Eigen::Vector3d(p.x(), p.y(), f.h_ell_m), f.hpl_m, f.vpl_m}};
  json out;
  if (!f.id.is_null()) out["id"] = f.id;
  out["time"] = maps::formatRfc3339(f.t0, 3);
  if (f.t1 - f.t0 > 0) out["until"] = maps::formatRfc3339(f.t1, 3);
  json verdict = geofence::fenceVerdictJson(fence.check(v), fence);
  out.update(verdict);
  return out;
}

void checkStream(const FenceCheckOptions& o, const geofence::Fence& fence, const maps::PlaneFrame& frame);

void runFenceCheck(const FenceCheckOptions& o) {
  if (o.fix.empty() == o.fixes.empty()) throw ParseError("--fix", 0, "--fix|--fixes", "", "exactly one of --fix JSON and --fixes FILE");
  if (!(o.horizon_m >= 0 && std::isfinite(o.horizon_m))) {
    throw ParseError("--horizon", 0, "--horizon", std::to_string(o.horizon_m), "a distance ≥ 0 m");
  }
  if (!(o.tolerance_m >= 0 && std::isfinite(o.tolerance_m))) {
    throw ParseError("--tolerance", 0, "--tolerance", std::to_string(o.tolerance_m), "a distance ≥ 0 m");
  }
  const geofence::CorridorSpec spec = geofence::loadCorridorSpec(o.corridor);
  geofence::CorridorBoxes boxes = geofence::buildBoxes(spec);
  const auto format = airspace::parseZoneFormat(o.format);
  if (!format) throw ParseError("--format", 0, "--format", o.format, "auto, ed269, ed318, geojson or qgc");
  const maps::Terrain terrain = groundModel(o.terrain, o.ground_amsl_m);
  geofence::ZonePolicy policy;
  policy.authorisations = spec.authorisations;
  policy.authorisations.insert(o.authorise.begin(), o.authorise.end());
  geofence::FenceOptions options;
  options.horizon_m = o.horizon_m;
  options.tolerance_m = o.tolerance_m;
  for (const std::string& w : boxes.limits.warnings) std::cerr << "skylane: warning: " << o.corridor << ": " << w << "\n";
  const geofence::Fence fence(std::move(boxes.level1), std::move(boxes.level2),
                              geofence::loadObstructions({o.zones, *format, o.buildings}, boxes.frame, terrain,
                                                         std::move(policy), options));

  if (!o.fix.empty()) {
    const json doc = maps::parseJsonLine(o.fix, "--fix");
    json out = checkFix(geofence::parseFix(doc, "--fix"), fence, maps::PlaneGrid(boxes.frame));
    if (!boxes.limits.warnings.empty()) out["warnings"] = boxes.limits.warnings;
    std::cout << out.dump(2) << "\n";
    return;
  }
  checkStream(o, fence, boxes.frame);
}

/// Where the verdicts go: a buffer written to stdout in blocks (and before any message on stderr,
/// so the two keep their order).
struct VerdictOut {
  static constexpr std::size_t kFlushBytes = 1 << 16;
  std::string buffer;
  void flush() {
    std::cout.write(buffer.data(), static_cast<std::streamsize>(buffer.size()));
    buffer.clear();
  }
};

/// What the stream needs to check a line: the file's name (for messages), the fence, the
/// projection of fixes and the verdict writer. All are safe to share between threads.
struct StreamContext {
  const std::string& fixes;
  const geofence::Fence& fence;
  const maps::PlaneGrid& projection;
  const geofence::VerdictLineWriter& writer;
};

/// One line of the stream appended to `out`: the plain form through the fast reader and writer
/// (no allocation per fix, geofence/fix_line.hpp), anything else through parseFix and nlohmann,
/// which word the errors. Throws what parseFix or the fence throws.
void checkLine(std::string_view text, std::size_t line, const StreamContext& c, std::string& out) {
  geofence::PlainFix f;
  if (geofence::readPlainFixLine(text, f)) {
    const Eigen::Vector2d p = c.projection.toPlane(f.lat_rad, f.lon_rad);
    const geofence::TimedVolume v{f.t0, f.t1, {Eigen::Vector3d(p.x(), p.y(), f.h_ell_m), f.hpl_m, f.vpl_m}};
    thread_local geofence::FenceVerdict verdict;  // this thread's, its storage reused fix after fix
    c.fence.check(v, verdict);
    if (c.writer.append(out, f.id_json, f.t0, f.t1, line, verdict)) return;
  }
  const std::string source = c.fixes + ":" + std::to_string(line);
  json j = checkFix(geofence::parseFix(maps::parseJsonLine(std::string(text), source), source), c.fence, c.projection);
  j["line"] = line;
  out += j.dump();
  out += '\n';
}

/// The event line for a line the stream skips. The message quotes the line, which may hold bytes
/// that are not UTF-8: replaced, not fatal.
std::string rejectedLine(std::size_t line, const std::exception& e) {
  return json{{"event", "rejected_input"}, {"line", line}, {"error", e.what()}}.dump(-1, ' ', false, json::error_handler_t::replace) +
         "\n";
}

/// Lines checked and skipped.
struct StreamCount {
  std::size_t checked = 0, rejected = 0;
};

/// Appends the line's verdict to `out`, or — when the line is refused (a ParseError, or a fix the
/// checker refuses) — its rejected_input event, and returns the refusal's message then.
std::optional<std::string> answerLine(std::string_view text, std::size_t line, const StreamContext& c, std::string& out,
                                      StreamCount& count) {
  try {
    checkLine(text, line, c, out);
    ++count.checked;
    return std::nullopt;
  } catch (const std::exception& e) {
    ++count.rejected;
    out += rejectedLine(line, e);
    return std::string(e.what());
  }
}

/// Opens --fixes (a file, or - for stdin).
std::istream& openFixes(const std::string& fixes, std::ifstream& file) {
  if (fixes == "-") return std::cin;
  maps::requireNotAFolder(fixes, "--fixes");
  file.open(fixes);
  if (!file) throw ParseError(fixes, 0, "--fixes", fixes, "a readable JSON-lines file");
  return file;
}

/// The stream on one thread: each verdict written as its line is read (stdout in 64 kB blocks).
StreamCount checkSequentially(std::istream& in, const StreamContext& c) {
  VerdictOut out;
  out.buffer.reserve(2 * VerdictOut::kFlushBytes);
  StreamCount count;
  std::string text;
  for (std::size_t line = 1; std::getline(in, text); ++line) {
    if (text.find_first_not_of(" \t\r") == std::string::npos) continue;
    if (const std::optional<std::string> message = answerLine(text, line, c, out.buffer, count)) {
      out.flush();
      std::cerr << "skylane: skipped: " << *message << "\n";
    }
    if (out.buffer.size() >= VerdictOut::kFlushBytes) out.flush();
  }
  out.flush();
  return count;
}

/// A block of the stream's lines (blank lines left out) one after the other in one string, with
/// where each ends and its number in the file.
struct LineBlock {
  static constexpr std::size_t kLines = 1024;
  std::string text;
  std::vector<std::size_t> ends;
  std::vector<std::size_t> numbers;
  void add(const std::string& line, std::size_t number) {
    text += line;
    ends.push_back(text.size());
    numbers.push_back(number);
  }
  [[nodiscard]] std::size_t size() const { return ends.size(); }
  [[nodiscard]] std::string_view line(std::size_t k) const {
    const std::size_t begin = k == 0 ? 0 : ends[k - 1];
    return std::string_view(text).substr(begin, ends[k] - begin);
  }
};

/// A block's verdict lines, and the messages of the lines it skipped, each with the length of
/// `out` written before it.
struct CheckedBlock {
  std::string out;
  std::vector<std::pair<std::size_t, std::string>> messages;
  StreamCount count;
};

CheckedBlock checkBlock(const LineBlock& block, const StreamContext& c) {
  CheckedBlock done;
  done.out.reserve(block.size() * 1024);
  for (std::size_t k = 0; k < block.size(); ++k) {
    if (std::optional<std::string> message = answerLine(block.line(k), block.numbers[k], c, done.out, done.count)) {
      done.messages.emplace_back(done.out.size(), std::move(*message));
    }
  }
  return done;
}

/// Writes a checked block as checkSequentially would have: stdout up to each skipped line's
/// event, then its message on stderr.
void writeBlock(const CheckedBlock& b, StreamCount& total) {
  std::size_t written = 0;
  for (const auto& [end, message] : b.messages) {
    std::cout.write(b.out.data() + written, static_cast<std::streamsize>(end - written));
    std::cout.flush();
    std::cerr << "skylane: skipped: " << message << "\n";
    written = end;
  }
  std::cout.write(b.out.data() + written, static_cast<std::streamsize>(b.out.size() - written));
  total.checked += b.count.checked;
  total.rejected += b.count.rejected;
}

/// The stream on `threads` threads: blocks of lines checked in parallel, written in order (the
/// same bytes as checkSequentially).
StreamCount checkInParallel(std::istream& in, const StreamContext& c, unsigned threads) {
  std::deque<std::future<CheckedBlock>> running;
  StreamCount total;
  LineBlock block;
  const auto launch = [&] {
    running.push_back(std::async(std::launch::async, [&c, b = std::move(block)] { return checkBlock(b, c); }));
    block = LineBlock{};
    while (running.size() >= threads) {
      writeBlock(running.front().get(), total);
      running.pop_front();
    }
  };
  std::string text;
  for (std::size_t line = 1; std::getline(in, text); ++line) {
    if (text.find_first_not_of(" \t\r") == std::string::npos) continue;
    block.add(text, line);
    if (block.size() == LineBlock::kLines) launch();
  }
  if (block.size() > 0) launch();
  for (; !running.empty(); running.pop_front()) writeBlock(running.front().get(), total);
  std::cout.flush();
  return total;
}

void checkStream(const FenceCheckOptions& o, const geofence::Fence& fence, const maps::PlaneFrame& frame) {
  // A stream: one verdict line per fix; a bad line is reported (stdout and stderr), skipped,
  // and the stream goes on.
  std::ifstream file;
  std::istream& in = openFixes(o.fixes, file);
  const geofence::VerdictLineWriter writer(fence);
  const maps::PlaneGrid projection(frame);
  const StreamContext context{o.fixes, fence, projection, writer};
  // A live feed on stdin is answered line by line; a file on every processor unless told.
  const unsigned threads = o.threads > 0 ? o.threads : (o.fixes == "-" ? 1u : std::max(1u, std::thread::hardware_concurrency()));
  const StreamCount count = threads == 1 ? checkSequentially(in, context) : checkInParallel(in, context, threads);
  std::cerr << "skylane: fence check: " << count.checked << " fix" << (count.checked == 1 ? "" : "es") << " checked, "
            << count.rejected << " rejected\n";
}

}  // namespace

void addFenceCommands(CLI::App& app) {
  CLI::App* fence = app.add_subcommand("fence", "Protection-volume checks against corridor, airspace boxes, zones and obstacles");
  fence->require_subcommand(1);
  auto o = std::make_shared<FenceCheckOptions>();
  CLI::App* check = fence->add_subcommand(
      "check", "Verdict for one fix (--fix) or each line of a JSON-lines file (--fixes; - for stdin)");
  check->add_option("--corridor", o->corridor, "Corridor file (JSON: path, vehicle, k1, k2, ...; see README)")->required();
  check->add_option("--zones", o->zones, "Zone files (ED-269, ED-318, GeoJSON, QGC .plan)");
  check->add_option("--format", o->format, "Zone file format: auto, ed269, ed318, geojson, qgc");
  check->add_option("--terrain", o->terrain, "Terrain raster for AGL limits and building bases (default: flat at 0 m AMSL)");
  check->add_option("--ground-amsl", o->ground_amsl_m, "Flat ground at this altitude [m AMSL] when no --terrain is given");
  check->add_option("--buildings", o->buildings, "Buildings and obstacles (GeoJSON)");
  check->add_option("--authorise", o->authorise, "Zone identifier the flight is authorised for (repeatable)");
  check->add_option("--horizon", o->horizon_m, "Report zones and obstacles within this clearance [m]");
  check->add_option("--tolerance", o->tolerance_m, "Margins within this of 0 are indeterminate [m]");
  check->add_option("--fix", o->fix, R"(One fix: {"time":"...Z","lat":..,"lon":..,"h_ell_m":..,"hpl_m":..,"vpl_m":..})");
  check->add_option("--fixes", o->fixes, "JSON-lines file of fixes, or - for stdin");
  check->add_option("--threads", o->threads,
                    "Threads checking a --fixes file, in blocks of 1,024 lines written in order (default: one per "
                    "processor for a file, one for stdin)")
      ->check(CLI::Range(1u, 256u));
  check->callback([o] { runFenceCheck(*o); });
}

}  // namespace skylane::cli
