// `fence check`'s fast path (geofence/fix_line.hpp, geofence/verdict_writer.hpp) against the
// general one it stands in for: parseFix on nlohmann's parse, and nlohmann's dump of
// fenceVerdictJson with the fix's id, line and times — byte for byte.
#include "geofence/fix_line.hpp"
#include "geofence/verdict_writer.hpp"

#include "geofence/corridor_file.hpp"
#include "geofence/fix.hpp"
#include "geofence/obstruction_files.hpp"
#include "geofence/verdict_json.hpp"
#include "maps/geodesy.hpp"
#include "maps/json_node.hpp"
#include "maps/terrain.hpp"

#include <gtest/gtest.h>

#include <cstdio>
#include <random>
#include <string>

namespace skylane::geofence {
namespace {

using nlohmann::json;

const std::string kExample = std::string(SKYLANE_TEST_DATA) + "/../../examples/fence/";

/// The bundled fence example: its corridor, zones and buildings, as scripts/run_example.sh checks it.
struct ExampleFence {
  CorridorBoxes boxes = buildBoxes(loadCorridorSpec(kExample + "corridor.json"));
  maps::PlaneFrame frame = boxes.frame;
  Fence fence{Corridor(boxes.level1), Corridor(boxes.level2),
              loadObstructions({{kExample + "zones_ed269.json"}, airspace::ZoneFormat::kAuto,
                                kExample + "../skymask/buildings.geojson"},
                               boxes.frame, maps::Terrain::flat(408.0), ZonePolicy{}, FenceOptions{})};
};

/// The general path's line: nlohmann's dump of fenceVerdictJson with id, time, until and line.
std::string referenceLine(const Fix& f, std::size_t line, const FenceVerdict& v, const Fence& fence) {
  json out;
  if (!f.id.is_null()) out["id"] = f.id;
  out["time"] = maps::formatRfc3339(f.t0, 3);
  if (f.t1 - f.t0 > 0) out["until"] = maps::formatRfc3339(f.t1, 3);
  out.update(fenceVerdictJson(v, fence));
  out["line"] = line;
  return out.dump() + "\n";
}

/// A random fix line near the example corridor (47.376 N, 8.541 E), some with "until" and ids.
std::string randomLine(std::mt19937_64& rng, int k) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  char buf[512];
  std::snprintf(buf, sizeof buf,
                R"({"time":"2026-11-23T12:%02d:%02d.%03dZ",%s"lat":%.8f, "lon" : %.7f,"h_ell_m":%.3f,"hpl_m":%.3f,"vpl_m":%g%s})",
                k / 60 % 60, k % 60, k % 1000, k % 3 == 0 ? "" : k % 3 == 1 ? R"("id":"fix-7",)" : R"("id":-12345,)",
                47.3745 + 0.0045 * u(rng), 8.5385 + 0.0065 * u(rng), 470.0 + 100.0 * u(rng), 60.0 * u(rng) * u(rng),
                30.0 * u(rng), k % 4 == 0 ? R"(,"until":"2026-11-23T13:00:00Z")" : "");
  return buf;
}

TEST(FixStream, PlainLinesReadAsParseFixReadsThemAndVerdictsWriteAsNlohmannDoes) {
  const ExampleFence ex;
  const VerdictLineWriter writer(ex.fence);
  std::mt19937_64 rng(22);
  int zone_checks = 0, obstacle_checks = 0;
  for (int k = 0; k < 3000; ++k) {
    const std::string text = randomLine(rng, k);
    PlainFix p;
    ASSERT_TRUE(readPlainFixLine(text, p)) << text;
    const Fix f = parseFix(maps::parseJsonLine(text, "test"), "test");
    ASSERT_EQ(p.id_json, f.id.is_null() ? std::string() : f.id.dump()) << text;
    ASSERT_EQ(p.t0.totalSeconds(), f.t0.totalSeconds());
    ASSERT_EQ(p.t1.totalSeconds(), f.t1.totalSeconds());
    ASSERT_EQ(p.lat_rad, f.lat_rad);
    ASSERT_EQ(p.lon_rad, f.lon_rad);
    ASSERT_EQ(p.h_ell_m, f.h_ell_m);
    ASSERT_EQ(p.hpl_m, f.hpl_m);
    ASSERT_EQ(p.vpl_m, f.vpl_m);
    const Eigen::Vector2d xy = ex.frame.toPlane(f.lat_rad, f.lon_rad);
    const FenceVerdict v = ex.fence.check({f.t0, f.t1, {Eigen::Vector3d(xy.x(), xy.y(), f.h_ell_m), f.hpl_m, f.vpl_m}});
    for (const Check& c : v.checks) {
      zone_checks += c.level == Level::kZone;
      obstacle_checks += c.level == Level::kObstacle;
    }
    std::string out = "previous line\n";
    ASSERT_TRUE(writer.append(out, p.id_json, p.t0, p.t1, static_cast<std::size_t>(k + 1), v));
    ASSERT_EQ(out, "previous line\n" + referenceLine(f, static_cast<std::size_t>(k + 1), v, ex.fence)) << text;
  }
  EXPECT_GT(zone_checks, 300) << "the fixes reach the example's zones";
  EXPECT_GT(obstacle_checks, 300) << "and its buildings";
}

TEST(FixStream, StringsAreEscapedAsNlohmannEscapesThemAndInvalidUtf8IsLeftToIt) {
  const ExampleFence ex;
  ASSERT_FALSE(ex.fence.zones().empty());
  const VerdictLineWriter writer(ex.fence);
  Check c;
  c.level = Level::kZone;
  c.subject = "a\"b\\c\b\f\n\r\t\x01\x1f\x7f é ü € 𝄞";
  c.name = "Zürich \"CTR\"";
  c.restriction = "PROHIBITED";
  c.margin_h_m = -0.0004;
  c.margin_v_m = 1e21;
  c.clearance_m = 123456789.0125;
  FenceVerdict v;
  v.verdict = Verdict::kOutside;
  v.violated = Level::kZone;
  v.checks = {c};
  Fix f;
  f.id = "x";
  std::string out;
  ASSERT_TRUE(writer.append(out, "\"x\"", f.t0, f.t1, 9, v));
  EXPECT_EQ(out, referenceLine(f, 9, v, ex.fence));
  for (const char* bad : {"\xc3", "\xe0\x80\x80", "\xed\xa0\x80", "\xf4\x90\x80\x80", "\xff"}) {
    v.checks[0].name = std::string("ok ") + bad;
    std::string kept = "kept";
    EXPECT_FALSE(writer.append(kept, "", f.t0, f.t1, 1, v)) << "a byte nlohmann refuses";
    EXPECT_EQ(kept, "kept");
    EXPECT_THROW((void)fenceVerdictJson(v, ex.fence).dump(), json::type_error);
  }
}

TEST(FixStream, LinesOutsideThePlainFormAreLeftToParseFix) {
  const std::string ok = R"("time":"2026-11-23T12:00:00Z","lat":47.3763,"lon":8.5405,"h_ell_m":515,"hpl_m":1,"vpl_m":1)";
  PlainFix p;
  EXPECT_TRUE(readPlainFixLine("{" + ok + "}", p));
  EXPECT_TRUE(readPlainFixLine(" \t{ " + ok + " }\r", p));
  for (const std::string& text :
       {"{" + ok + ",\"extra\":1}", "{" + ok + ",\"lat\":47}", "{" + ok + "} x", "{" + ok, "[" + ok + "]", std::string("{}"),
        "{" + ok + ",\"id\":\"caf\\u00e9\"}", "{" + ok + ",\"id\":\"café\"}", "{" + ok + ",\"id\":1.5}",
        "{" + ok + ",\"id\":-0}", "{" + ok + ",\"id\":null}", "{" + ok + ",\"id\":1234567890123456789}",
        "{" + ok + ",\"until\":\"2026-11-23T11:59:59Z\"}", "{" + ok + ",\"until\":\"yesterday\"}",
        std::string(R"({"time":"2026-11-23T12:00:00Z","lat":91,"lon":8.5,"h_ell_m":515,"hpl_m":1,"vpl_m":1})"),
        std::string(R"({"time":"2026-11-23T12:00:00Z","lat":47,"lon":8.5,"h_ell_m":515,"hpl_m":-1,"vpl_m":1})"),
        std::string(R"({"time":"2026-11-23T12:00:00Z","lat":047,"lon":8.5,"h_ell_m":515,"hpl_m":1,"vpl_m":1})"),
        std::string(R"({"time":"2026-11-23T12:00:00Z","lat":47.,"lon":8.5,"h_ell_m":515,"hpl_m":1,"vpl_m":1})"),
        std::string(R"({"time":"2026-11-23T12:00:00Z","lat":47,"lon":8.5,"h_ell_m":1e400,"hpl_m":1,"vpl_m":1})"),
        std::string(R"({"time":"2026-11-23T12:00:00Z","lat":47,"lon":8.5,"h_ell_m":"515","hpl_m":1,"vpl_m":1})"),
        std::string(R"({"time":"2026-11-23T12:00:00Z","lat":47,"lon":8.5,"hpl_m":1,"vpl_m":1})")}) {
    EXPECT_FALSE(readPlainFixLine(text, p)) << text;
  }
}

}  // namespace
}  // namespace skylane::geofence
