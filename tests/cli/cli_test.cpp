// End-to-end checks of the skylane command: output shape and the exit-status contract
// (0 success, 2 bad input with one line naming file/field/value/expectation).
#include "maps/geodesy.hpp"
#include "maps/geoid.hpp"
#include "tests/maps/raster_fixture.hpp"
#include "tests/test_util.hpp"

#include <nlohmann/json.hpp>

#include <array>
#include <cmath>
#include <fstream>
#include <random>
#include <algorithm>
#include <iterator>
#include <cstdio>
#include <sstream>
#include <sys/wait.h>
#include <vector>

namespace skylane {
namespace {

using RunResult = test::CommandResult;

/// The skylane command with these arguments, stdout and stderr together.
RunResult run(const std::string& args) { return test::runCommand(std::string(SKYLANE_BINARY) + " " + args + " 2>&1"); }

std::string writeTemp(const std::string& name, const std::string& text) {
  const std::string path = test::scratchPath(name);
  std::ofstream(path) << text;
  return path;
}

TEST(Cli, PlPrintsProtectionLevelsAsJson) {
  const std::string geo = writeTemp("geo.json", R"({"satellites":[
    {"id":"G01","az_deg":0,"el_deg":88},{"id":"G05","az_deg":30,"el_deg":35},{"id":"G08","az_deg":95,"el_deg":20},
    {"id":"G11","az_deg":150,"el_deg":55},{"id":"G17","az_deg":200,"el_deg":15},{"id":"G22","az_deg":260,"el_deg":42},
    {"id":"G28","az_deg":320,"el_deg":25}]})");
  const RunResult r = run("integrity pl --geometry " + geo + " --method raim --verbose");
  ASSERT_EQ(r.status, 0) << r.out;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_TRUE(j["available"].get<bool>());
  EXPECT_GT(j["hpl_m"].get<double>(), 0.0);
  EXPECT_GT(j["vpl_m"].get<double>(), j["hpl_m"].get<double>() * 0.5);
  EXPECT_EQ(j["per_satellite"].size(), 7u);
  EXPECT_EQ(j["dof"].get<int>(), 3);
}

TEST(Cli, PlDefaultsToAraimWithItsFields) {
  const RunResult r = run("integrity pl --verbose --geometry " + std::string(SKYLANE_TEST_DATA) + "/../../examples/predict/geometry.json");
  ASSERT_EQ(r.status, 0) << r.out;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["method"], "araim");
  for (const char* key : {"hpl_m", "vpl_m", "emt_m", "sigma_acc_m", "fault_modes", "hpl_equal_allocation_m",
                          "vpl_equal_allocation_m", "available", "subsets"}) {
    EXPECT_TRUE(j.contains(key)) << key;
  }
  // 12 satellites + Galileo out (P_sat 1e-5). GPS out (P_const 1e-8, below PHMI) is left to
  // P_not_monitored by the default rule: with the singles monitored P_nm is already ≤ P_THRES.
  EXPECT_EQ(j["fault_modes"].get<int>(), 13);
  EXPECT_EQ(j["subsets"].size(), 13u);
  EXPECT_LE(j["p_not_monitored"].get<double>(), 8e-8);
  EXPECT_LE(j["vpl_m"].get<double>(), j["vpl_equal_allocation_m"].get<double>());
}

TEST(Cli, PlPrintsEmtAndSigmaAccWhenThePlIsNotComputable) {
  // GIVEN priors whose unmonitored probability exceeds the integrity budget
  const std::string geo = writeTemp("geo_nopl.json", R"({"satellites":[
    {"id":"G01","az_deg":0,"el_deg":88},{"id":"G05","az_deg":30,"el_deg":35},{"id":"G08","az_deg":95,"el_deg":20},
    {"id":"G11","az_deg":150,"el_deg":55},{"id":"G17","az_deg":200,"el_deg":15},{"id":"E03","az_deg":60,"el_deg":65},
    {"id":"E11","az_deg":120,"el_deg":12},{"id":"E19","az_deg":230,"el_deg":70},{"id":"E24","az_deg":290,"el_deg":10}],
    "ism":{"GPS":{"psat":1e-2,"pconst":1e-2},"Galileo":{"psat":1e-2,"pconst":1e-2}},
    "requirements":{"p_thres":1e-3}})");
  const RunResult r = run("integrity pl --verbose --geometry " + geo);
  ASSERT_EQ(r.status, 0) << r.out;
  const auto j = nlohmann::json::parse(r.out);
  // THEN no PL, but EMT, sigma_acc and the unmonitored probability are printed
  EXPECT_FALSE(j["pl_computed"].get<bool>());
  EXPECT_TRUE(j["vpl_m"].is_null());
  EXPECT_GT(j["emt_m"].get<double>(), 0.0);
  EXPECT_GT(j["sigma_acc_m"].get<double>(), 0.0);
  EXPECT_GT(j["p_not_monitored"].get<double>(), 1e-7);
}

TEST(Cli, PlWithTooFewSatellitesSaysNotAvailable) {
  const std::string geo = writeTemp("geo3.json", R"({"satellites":[{"id":"G01","az_deg":0,"el_deg":88},
    {"id":"G05","az_deg":30,"el_deg":35},{"id":"G08","az_deg":95,"el_deg":20}]})");
  const RunResult r = run("integrity pl --method raim --geometry " + geo);
  ASSERT_EQ(r.status, 0) << r.out;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_FALSE(j["available"].get<bool>());
  EXPECT_TRUE(j["hpl_m"].is_null());
  EXPECT_NE(j["reason"].get<std::string>().find("too few satellites"), std::string::npos);
}

TEST(Cli, BadInputExitsTwoWithOneLineNamingTheProblem) {
  const std::string bad_geo = writeTemp("bad.json", R"({"satellites":[{"id":"G01","az_deg":0,"el_deg":"high"}]})");
  const std::string bad_alm = writeTemp("bad_alm.txt", "******** Week 1 almanac for PRN-01 ********\nID: 1\nHealth: x\n");
  struct Case { std::string args; std::string expected; };
  const Case cases[] = {
      {"integrity pl --geometry " + bad_geo, "satellites[0].el_deg': got '\"high\"'"},
      {"integrity pl --geometry /no/such/file.json", "/no/such/file.json"},
      {"integrity predict --almanac " + bad_alm + " --lat 1 --lon 2 --start 2020-01-01T00:00:00Z", "bad_alm.txt:3: field 'Health'"},
      {"integrity predict --almanac x --lat 1 --lon 2 --start tomorrow", "field '--start': got 'tomorrow'"},
      {"integrity predict --almanac x --lat 100 --lon 2 --start 2020-01-01T00:00:00Z", "field '--lat'"},
      {"integrity predict --almanac x --lat 1 --lon 2 --alt 1e308 --start 2020-01-01T00:00:00Z",
       "field '--alt': got '1e+308', expected an ellipsoidal height in [-1000, 100000] m"},
      {"integrity availability --almanac x --alt=-5000", "field '--alt': got '-5000'"},
      {"integrity spp --obs " + test::dataPath("gnss/30400920.05n") + " --nav " + test::dataPath("gnss/30400920.05n"),
       "field 'file type': got 'N', expected 'O'"},
      {"integrity pl", "--geometry is required"},
  };
  for (const auto& c : cases) {
    const RunResult r = run(c.args);
    EXPECT_EQ(r.status, 2) << c.args << "\n" << r.out;
    EXPECT_NE(r.out.find(c.expected), std::string::npos) << c.args << "\n" << r.out;
  }
}

TEST(Cli, PredictWritesCsvAndSvg) {
  const std::string svg = test::scratchPath("predict.svg");
  const RunResult r = run("integrity predict --method raim --almanac " + test::dataPath("gnss/alm01jan2020.txt") +
                          " --lat 35.13 --lon 139.62 --start 2020-01-01T00:00:00Z --duration 2h --step 30m --plot " + svg);
  ASSERT_EQ(r.status, 0) << r.out;
  EXPECT_EQ(r.out.rfind("time_utc,gps_week,gps_sow,satellites,hdop,vdop,hpl_m,vpl_m,available,emt_m,sigma_acc_m,fault_modes\n", 0), 0u) << r.out;
  EXPECT_EQ(std::count(r.out.begin(), r.out.end(), '\n'), 6);  // header + 5 epochs
  std::ifstream f(svg);
  std::string text((std::istreambuf_iterator<char>(f)), std::istreambuf_iterator<char>());
  EXPECT_NE(text.find("<svg"), std::string::npos);
  EXPECT_NE(text.find("HPL"), std::string::npos);
}

TEST(Cli, PredictChecksTheAlmanacsAgeAgainstStart) {
  const std::string alm = test::dataPath("gnss/alm01jan2020.txt");
  const std::string where = " --lat 35.13 --lon 139.62 --duration 1h --step 30m";
  // GIVEN the almanac of 2020-01-03: WHEN --start is in 2025 THEN exit 2 naming the file, its
  // epoch, --start, the limit and the age
  const RunResult old = run("integrity predict --almanac " + alm + where + " --start 2025-06-01T00:00:00Z");
  EXPECT_EQ(old.status, 2) << old.out;
  EXPECT_NE(old.out.find("skylane: error: " + alm + ": field 'almanac epoch t_oa': got '2020-01-03T19:56:30Z (GPS week 2086"),
            std::string::npos) << old.out;
  EXPECT_NE(old.out.find("within 90.0 days of --start 2025-06-01T00:00:00Z; it is 1975.2 days from it"), std::string::npos) << old.out;
  // WHEN --start is 10 days after its t_oa THEN a warning on stderr, and the prediction runs
  const RunResult stale = run("integrity predict --almanac " + alm + where + " --start 2020-01-14T00:00:00Z");
  EXPECT_EQ(stale.status, 0) << stale.out;
  EXPECT_NE(stale.out.find("skylane: warning: " + alm + ": the almanac's t_oa"), std::string::npos) << stale.out;
  EXPECT_NE(stale.out.find("10.2 days from --start 2020-01-14T00:00:00Z, beyond the 7.0 days warning limit"), std::string::npos)
      << stale.out;
  // AND within the week nothing is said
  const RunResult fresh = run("integrity predict --almanac " + alm + where + " --start 2020-01-01T00:00:00Z");
  EXPECT_EQ(fresh.status, 0) << fresh.out;
  EXPECT_EQ(fresh.out.find("warning"), std::string::npos) << fresh.out;
}

TEST(Cli, PredictAraimWithGpsAndGalileoAlmanacs) {
  const RunResult r = run("integrity predict --almanac " + test::dataPath("gnss/alm_gps_ed259.txt") + " --almanac " +
                          test::dataPath("gnss/alm_gal_ed259.txt") +
                          " --lat 48.1 --lon 11.6 --start 2017-01-01T00:00:00Z --duration 1h --step 20m --format jsonl");
  ASSERT_EQ(r.status, 0) << r.out;
  std::istringstream in(r.out);
  std::string line;
  int n = 0;
  while (std::getline(in, line)) {
    const auto j = nlohmann::json::parse(line);
    EXPECT_EQ(j["method"], "araim");
    EXPECT_TRUE(j["available"].get<bool>()) << line;
    EXPECT_GE(j["satellites"].size(), 14u);
    ++n;
  }
  EXPECT_EQ(n, 4);
}

/// The shared libraries the skylane executable names (its DT_NEEDED entries, as readelf prints them).
std::vector<std::string> neededLibraries() {
  const RunResult r = test::runCommand("readelf -d " + std::string(SKYLANE_BINARY));
  EXPECT_EQ(r.status, 0) << r.out;
  std::vector<std::string> needed;
  std::istringstream lines(r.out);
  for (std::string line; std::getline(lines, line);) {
    const auto open = line.find("(NEEDED)");
    const auto lib = line.find('[');
    if (open != std::string::npos && lib != std::string::npos) needed.push_back(line.substr(lib + 1, line.find(']', lib) - lib - 1));
  }
  return needed;
}

// Start-up: the optional modules' libraries (GDAL, OMPL, FCL, nats.c with libssl) are loaded by
// the commands that use them, and SQLite, GMP, MPFR, GeographicLib and libcrypto are linked
// statically, so every command starts with the C and C++ run-time libraries alone.
TEST(Cli, StartsWithTheRunTimeLibrariesOnly) {
  const std::vector<std::string> needed = neededLibraries();
  ASSERT_FALSE(needed.empty());
  for (const std::string& lib : needed) {
    for (const char* module_lib : {"libgdal", "libompl", "libfcl", "libccd", "libnats", "libssl", "libprotobuf-c"}) {
      EXPECT_EQ(lib.rfind(module_lib, 0), std::string::npos) << lib;
    }
    if (SKYLANE_STATIC_DEPS_LINKED) {
      const bool run_time = lib.rfind("libstdc++.so", 0) == 0 || lib.rfind("libm.so", 0) == 0 || lib.rfind("libgcc_s.so", 0) == 0 ||
                            lib.rfind("libc.so", 0) == 0 || lib.rfind("ld-linux", 0) == 0 ||
                            lib.rfind("libasan.so", 0) == 0 || lib.rfind("libubsan.so", 0) == 0;  // a sanitizer build
      EXPECT_TRUE(run_time) << lib << " is loaded at every start";
    }
  }
}

TEST(Cli, SppPrintsOneJsonLinePerEpoch) {
  const RunResult r = run("integrity spp --obs " + test::dataPath("gnss/30400920.05o") + " --nav " +
                          test::dataPath("gnss/30400920.05n") + " --inject G08:50");
  ASSERT_EQ(r.status, 0) << r.out.substr(0, 500);
  EXPECT_EQ(std::count(r.out.begin(), r.out.end(), '\n'), 120);
  const auto first = nlohmann::json::parse(r.out.substr(0, r.out.find('\n')));
  EXPECT_EQ(first["time"], "2005-04-01T23:59:47.000Z");  // GPS 00:00:00 − 13 leap seconds
  EXPECT_EQ(first["excluded"], nlohmann::json::array({"G08"}));
  EXPECT_TRUE(first["fault_detected"].get<bool>());
  EXPECT_NEAR(first["lat_deg"].get<double>(), 35.13207, 1e-4);
}

TEST(Cli, AvailabilityMapHasCellsColourScaleAndCoastlines) {
  // GIVEN a coarse 30° grid over 1 h (a seconds-long run)
  const std::string svg = test::scratchPath("availability.svg");
  const RunResult r = run("integrity availability --almanac " + test::dataPath("gnss/alm01jan2020.txt") +
                          " --grid-deg 30 --start 2020-01-01T00:00:00Z --duration 1h --step 30m --method raim --map " + svg);
  ASSERT_EQ(r.status, 0) << r.out;
  // THEN the CSV has one row per cell (12 × 6 = 72) and the map draws the cells, the bins' legend
  // and the GSHHG coastlines (117 lines in the embedded crude set).
  // (run() merges stderr, which adds the one-line area summary)
  EXPECT_EQ(std::count(r.out.begin(), r.out.end(), '\n'), 1 + 72 + 1) << r.out;
  EXPECT_NE(r.out.find("% of the Earth's area has >= 99.5 % availability"), std::string::npos) << r.out;
  std::ifstream f(svg);
  const std::string text((std::istreambuf_iterator<char>(f)), std::istreambuf_iterator<char>());
  std::size_t polylines = 0;
  for (std::size_t p = text.find("<polyline"); p != std::string::npos; p = text.find("<polyline", p + 1)) ++polylines;
  EXPECT_EQ(polylines, 117u);
  EXPECT_NE(text.find("availability"), std::string::npos);
}

/// --fde: the predicted PLs of a user who excludes — never below detection only, and above it
/// (the budget is shared among the exclusion outcomes); availability no higher.
TEST(Cli, PredictAndAvailabilityWithExclusionGiveTheLargerPlsOfAUserWhoExcludes) {
  const std::string alm = test::dataPath("gnss/alm01jan2020.txt");
  for (const std::string method : {"raim", "araim"}) {
    const std::string predict = "integrity predict --format jsonl --method " + method + " --almanac " + alm +
                                " --lat 47.4 --lon 8.5 --start 2020-01-01T00:00:00Z --duration 2h --step 20m";
    const RunResult plain = run(predict), fde = run(predict + " --fde");
    ASSERT_EQ(plain.status, 0) << plain.out;
    ASSERT_EQ(fde.status, 0) << fde.out;
    std::istringstream a(plain.out), b(fde.out);
    int epochs = 0, larger = 0;
    for (std::string la, lb; std::getline(a, la) && std::getline(b, lb);) {
      const auto p = nlohmann::json::parse(la), f = nlohmann::json::parse(lb);
      EXPECT_FALSE(p.contains("with_exclusion"));
      EXPECT_EQ(f.at("with_exclusion"), true);
      ASSERT_TRUE(p.at("pl_computed").get<bool>() && f.at("pl_computed").get<bool>()) << lb;
      EXPECT_GE(f.at("vpl_m").get<double>(), p.at("vpl_m").get<double>()) << method << " " << lb;
      EXPECT_GE(f.at("hpl_m").get<double>(), p.at("hpl_m").get<double>()) << method << " " << lb;
      larger += f.at("vpl_m").get<double>() > p.at("vpl_m").get<double>() ? 1 : 0;
      ++epochs;
    }
    EXPECT_EQ(epochs, 7) << method;
    EXPECT_EQ(larger, epochs) << method;
  }
  const std::string availability = "integrity availability --almanac " + alm +
                                   " --grid-deg 30 --start 2020-01-01T00:00:00Z --duration 1h --step 30m --method raim";
  const RunResult plain = run(availability), fde = run(availability + " --fde");
  ASSERT_EQ(plain.status, 0) << plain.out;
  ASSERT_EQ(fde.status, 0) << fde.out;
  std::istringstream a(plain.out), b(fde.out);
  std::string la, lb;
  std::getline(a, la);
  std::getline(b, lb);
  int cells = 0;
  for (; std::getline(a, la) && std::getline(b, lb) && la.find(',') != std::string::npos; ++cells) {
    double pa[7], pb[7];
    ASSERT_EQ(std::sscanf(la.c_str(), "%lf,%lf,%lf,%lf,%lf,%lf,%lf", &pa[0], &pa[1], &pa[2], &pa[3], &pa[4], &pa[5], &pa[6]), 7) << la;
    ASSERT_EQ(std::sscanf(lb.c_str(), "%lf,%lf,%lf,%lf,%lf,%lf,%lf", &pb[0], &pb[1], &pb[2], &pb[3], &pb[4], &pb[5], &pb[6]), 7) << lb;
    EXPECT_LE(pb[3], pa[3]) << lb;  // available epochs
    EXPECT_GT(pb[6], pa[6]) << lb;  // the largest VPL
  }
  EXPECT_EQ(cells, 12 * 6);
}

TEST(Cli, SkymaskPrintsBlockedElevationPerBinAndDrawsASkyPlot) {
  // GIVEN one 20 m building whose near face is 30 m north of a point 1.5 m above flat ground
  const double lat = 47.3769, lon = 8.5417;
  const maps::LocalFrame frame({maps::deg2rad(lat), maps::deg2rad(lon), 0.0});
  std::string ring;
  for (const auto& [e, n] : {std::pair{-15.0, 30.0}, {15.0, 30.0}, {15.0, 40.0}, {-15.0, 40.0}, {-15.0, 30.0}}) {
    const maps::Geodetic g = frame.fromEnu({e, n, 0});
    char buf[64];
    std::snprintf(buf, sizeof buf, "%s[%.10f,%.10f]", ring.empty() ? "" : ",", maps::rad2deg(g.lon_rad), maps::rad2deg(g.lat_rad));
    ring += buf;
  }
  const std::string file = writeTemp("block.geojson", R"({"type":"FeatureCollection","features":[{"type":"Feature","id":"way/1",)"
                                                      R"("properties":{"height":"20 m"},"geometry":{"type":"Polygon","coordinates":[[)" + ring + "]]}}]}");
  const std::string svg = test::scratchPath("sky.svg");
  const RunResult r = run("skymask --lat 47.3769 --lon 8.5417 --height-agl 1.5 --ground-amsl 400 --bin-deg 2 --buildings " + file +
                          " --svg " + svg);
  ASSERT_EQ(r.status, 0) << r.out;
  const auto j = nlohmann::json::parse(r.out);
  ASSERT_EQ(j["azimuth_from_deg"].size(), 180u);
  EXPECT_EQ(j["azimuth_from_deg"][1].get<double>(), 2.0);
  EXPECT_EQ(j["buildings"]["count"].get<int>(), 1);
  // THEN the bin facing it holds atan(18.5 / 30) = 31.66° (the geoid's spread over the
  // footprint raises the top by at most a few decimetres: 0.4° at 30 m)
  const double north = j["blocked_elevation_deg"][0].get<double>();
  EXPECT_GE(north, 31.66 - 0.01);
  EXPECT_LE(north, 31.66 + 0.4);
  // AND half the face's width, atan(15 / 30) = 26.6°, ends the blocked bins (2° bins: 0 … 26)
  EXPECT_GT(j["blocked_elevation_deg"][13].get<double>(), 20.0);
  EXPECT_LT(j["blocked_elevation_deg"][14].get<double>(), 0.0);
  EXPECT_LT(j["blocked_elevation_deg"][90].get<double>(), 0.0) << "south: the flat ground's horizon";
  EXPECT_NEAR(j["position"]["alt_amsl_m"].get<double>(), 401.5, 1e-3);
  std::ifstream in(svg);
  std::stringstream ss;
  ss << in.rdbuf();
  EXPECT_NE(ss.str().find("<svg"), std::string::npos);
  EXPECT_NE(ss.str().find("1 buildings from"), std::string::npos);

  // Bad input: the feature, the field and the value in one line, exit 2.
  const std::string bad = writeTemp("bad_block.geojson", R"({"type":"FeatureCollection","features":[{"type":"Feature","id":"way/9",)"
                                                         R"("properties":{"building:levels":"many"},"geometry":{"type":"Polygon","coordinates":[[)" + ring + "]]}}]}");
  const RunResult e = run("skymask --lat 47.3769 --lon 8.5417 --h-ell 450 --buildings " + bad);
  EXPECT_EQ(e.status, 2);
  EXPECT_NE(e.out.find("bad_block.geojson: field 'features[0](way/9).properties.building:levels': got 'many'"), std::string::npos) << e.out;
  EXPECT_EQ(run("skymask --lat 47.3769 --lon 8.5417 --h-ell 450 --bin-deg 7 --buildings " + file).status, 2);
}

TEST(Cli, ZonesValidateReportsEveryZoneAndExitsTwoWhenInvalid) {
  const RunResult ok = run("zones validate " + test::dataPath("geozones/geo-awareness-che-1.json") + " " +
                           test::dataPath("geozones/cis_source_sample_ed318.json"));
  EXPECT_EQ(ok.status, 0) << ok.out;
  EXPECT_NE(ok.out.find("features[2](Lausanne Airport): ok (3 volumes, PROHIBITED)"), std::string::npos) << ok.out;
  EXPECT_NE(ok.out.find("note: repeated vertex removed (lat 46.53194, lon 6.596603) [volume 1]"), std::string::npos);
  const RunResult bad = run("zones validate " + test::dataPath("geozones/bowtie_ed269.json"));
  EXPECT_EQ(bad.status, 2) << bad.out;
  EXPECT_NE(bad.out.find("UASZoneList[0](BOWTIE): INVALID"), std::string::npos) << bad.out;
  EXPECT_NE(bad.out.find("error: self-intersecting ring: edge from vertex 0"), std::string::npos) << bad.out;
  const RunResult fixed = run("zones validate --repair " + test::dataPath("geozones/bowtie_ed269.json"));
  EXPECT_EQ(fixed.status, 0) << fixed.out;
  EXPECT_NE(fixed.out.find("repaired: self-intersecting ring"), std::string::npos) << fixed.out;
  const RunResult missing = run("zones at --lat 46 --lon 7 --h-ell 100 --time 2026-01-01T00:00:00Z /nonexistent.json");
  EXPECT_EQ(missing.status, 2);
  EXPECT_NE(missing.out.find("/nonexistent.json: field 'file'"), std::string::npos) << missing.out;
}

TEST(Cli, ZonesAtSaysWhichZonesApplyAndWhy) {
  // Montreux concert area (prohibited SAT/SUN 17:00Z–24:00) and the wildlife preserve overlap here.
  const std::string che = test::dataPath("geozones/geo-awareness-che-1.json");
  const RunResult sat = run("zones at " + che + " --lat 46.430758 --lon 6.913146 --height-agl 50 --time 2022-06-18T18:00:00Z");
  ASSERT_EQ(sat.status, 0) << sat.out;
  const nlohmann::json j = nlohmann::json::parse(sat.out);
  ASSERT_EQ(j["applies"].size(), 2u) << sat.out;
  EXPECT_EQ(j["applies"][0]["zone"], "Montreux Concert Area");
  EXPECT_EQ(j["applies"][0]["restriction"], "PROHIBITED");
  EXPECT_EQ(j["applies"][1]["restriction"], "REQ_AUTHORISATION");
  // 50 m AGL over flat terrain at 0 m AMSL = 50 m + N (EGM96 ≈ 49.76 m at Montreux) ellipsoidal.
  EXPECT_NEAR(j["position"]["h_ell_m"].get<double>(), 99.76, 0.05);
  // Monday: the concert area no longer applies, the preserve still does.
  const RunResult mon = run("zones at " + che + " --lat 46.430758 --lon 6.913146 --height-agl 50 --time 2022-06-20T18:00:00Z");
  const nlohmann::json m = nlohmann::json::parse(mon.out);
  ASSERT_EQ(m["applies"].size(), 1u) << mon.out;
  EXPECT_EQ(m["inside_outline_but_not_applying"][0]["why"], "inside the outline, between floor and ceiling; not active at this time");
  // Above the 120 m AGL ceiling of the preserve.
  const RunResult high = run("zones at " + che + " --lat 46.430758 --lon 6.913146 --height-agl 150 --time 2022-06-20T18:00:00Z");
  EXPECT_EQ(nlohmann::json::parse(high.out)["applies"].size(), 0u) << high.out;
}

TEST(Cli, PointQueriesTakeOnlyFiniteHeightsInTheModelledBand) {
  // GIVEN the point queries that take one height (zones at, skymask) at 47.4° N 8.5° E, where
  // the EGM96 geoid lies 47.403 m above the ellipsoid
  const std::string che = test::dataPath("geozones/geo-awareness-che-1.json");
  const std::vector<std::string> commands{"zones at " + che + " --lat 47.4 --lon 8.5 --time 2026-01-01T00:00:00Z",
                                          "skymask --lat 47.4 --lon 8.5 --ground-amsl 400"};
  struct Case {
    std::string option, value, said;
  };
  const std::vector<Case> bad{
      {"--alt-amsl", "1e308", "got '1e+308', expected a height whose ellipsoidal height lies within -2000 … 20000 m"},
      {"--h-ell", "-1e308", "got '-1e+308', expected a height whose ellipsoidal height lies within -2000 … 20000 m"},
      {"--height-agl", "1e300", "got '1e+300', expected a height whose ellipsoidal height lies within"},
      {"--h-ell", "nan", "got 'nan', expected a finite height in metres"},
      {"--h-ell", "inf", "got 'inf', expected a finite height in metres"},
      // 19,960 m AMSL is 20,007.403 m above the ellipsoid here (N = 47.403 m): outside, and the
      // message says so
      {"--alt-amsl", "19960", "this one gives 20007.403 m"},
      {"--h-ell", "20000.0004", "got '20000.0004'"}};
  for (const std::string& command : commands) {
    for (const Case& c : bad) {
      // WHEN a height outside the band, or no number, is given
      const RunResult r = run(command + " " + c.option + " " + c.value);
      // THEN the command exits 2 naming the option, its value and what was expected
      EXPECT_EQ(r.status, 2) << command << " " << c.option << " " << c.value << ": " << r.out;
      EXPECT_NE(r.out.find("field '" + c.option + "'"), std::string::npos) << r.out;
      EXPECT_NE(r.out.find(c.said), std::string::npos) << r.out;
    }
    // AND heights at the band's edges are taken
    for (const char* ok : {"--h-ell 20000", "--h-ell -2000", "--alt-amsl 19900", "--height-agl 50"}) {
      const RunResult r = run(command + " " + ok);
      EXPECT_EQ(r.status, 0) << command << " " << ok << ": " << r.out;
    }
  }
}

TEST(Cli, ZonesAtResolvesAglLimitsOverSlopingTerrain) {
  // GIVEN terrain rising 20 m per 0.01° eastward (700 m AMSL at 7.1°E, 1100 m at 7.3°E) and a
  // prohibited zone from 0 to 120 m AGL over 7.05–7.45°E
  const double gt[6] = {7.0, 0.01, 0.0, 46.6, 0.0, -0.01};
  const std::string dem = test::writeGeoTiff("slope.tif", 50, 20, gt, "EPSG:4326",
                                             [](int, int c) { return 500.0 + 2000.0 * (c + 0.5) * 0.01; });
  const std::string zone = writeTemp("slope_zone.geojson", R"({"type":"FeatureCollection","features":[
    {"type":"Feature","id":"SLOPE","properties":{"restriction":"PROHIBITED","lower":0,"lower_reference":"AGL",
     "upper":120,"upper_reference":"AGL"},"geometry":{"type":"Polygon","coordinates":[[[7.05,46.45],[7.45,46.45],
     [7.45,46.55],[7.05,46.55],[7.05,46.45]]]}}]})");
  const auto applies = [&](double lon, double alt_amsl) {
    std::ostringstream cmd;
    cmd << "zones at " << zone << " --terrain " << dem << " --lat 46.5 --lon " << lon << " --alt-amsl " << alt_amsl
        << " --time 2026-11-23T12:00:00Z";
    const RunResult r = run(cmd.str());
    EXPECT_EQ(r.status, 0) << r.out;
    return nlohmann::json::parse(r.out)["applies"].size() == 1;
  };
  // THEN the zone spans ground … ground + 120 m: 700 … 820 m at 7.1°E, 900 … 1020 m at 7.2°E,
  // 1100 … 1220 m at 7.3°E
  EXPECT_TRUE(applies(7.1, 750.0));
  EXPECT_FALSE(applies(7.1, 850.0));   // above the ceiling here …
  EXPECT_FALSE(applies(7.2, 850.0));   // … and below the floor further east
  EXPECT_TRUE(applies(7.2, 950.0));
  EXPECT_TRUE(applies(7.3, 1200.0));
  EXPECT_FALSE(applies(7.3, 1230.0));
}

TEST(Cli, ZonesExportWritesGeoJsonWithBothHeightReferences) {
  const std::string out = test::scratchPath("zones.geojson");
  const RunResult r = run("zones export " + test::dataPath("geozones/geo-awareness-che-1.json") + " " +
                          test::dataPath("geozones/qgc_fence.plan") + " --to geojson -o " + out);
  ASSERT_EQ(r.status, 0) << r.out;
  std::ifstream f(out);
  const nlohmann::json j = nlohmann::json::parse(f);
  EXPECT_EQ(j["type"], "FeatureCollection");
  ASSERT_EQ(j["features"].size(), 10u + 3u);  // one feature per volume (CHE-1: 1+3+3+1+1+1)
  const nlohmann::json& montreux = j["features"][0]["properties"];
  EXPECT_EQ(montreux["upper"]["as_given"], "6259 M AMSL");
  // The ceiling's ellipsoidal range is 6259 m + the EGM96 undulation's range over the 3 km
  // circle's bounding box (conservative: every grid node the interpolation can use there),
  // so it brackets N = 49.76 m at the centre and equals the geoid's own range for that box
  // (± 3000 m is ± 0.02699° of latitude and ± 0.03917° of longitude at 46.43° N).
  const double lat = maps::deg2rad(46.430758), lon = maps::deg2rad(6.913146);
  const auto [n_min, n_max] = maps::Geoid::egm96().undulationRange_m(
      lat - maps::deg2rad(0.02699), lat + maps::deg2rad(0.02699), lon - maps::deg2rad(0.03917), lon + maps::deg2rad(0.03917));
  const double h_lo = montreux["upper_resolved"]["h_ell_m"][0].get<double>();
  const double h_hi = montreux["upper_resolved"]["h_ell_m"][1].get<double>();
  EXPECT_NEAR(h_lo, 6259.0 + n_min, 1e-3);
  EXPECT_NEAR(h_hi, 6259.0 + n_max, 1e-3);
  EXPECT_LE(h_lo, 6259.0 + 49.76);  // EGM96 undulation at Montreux
  EXPECT_GE(h_hi, 6259.0 + 49.76);
  EXPECT_EQ(montreux["upper_resolved"]["alt_amsl_m"][0], 6259.0);
  // The polygon of Lausanne's second volume: the repeated vertex is gone, the ring closed again.
  EXPECT_EQ(j["features"][5]["geometry"]["coordinates"][0].size(), 4u);
}


// --- fence check ---------------------------------------------------------------------------

std::string fenceArgs() {
  const std::string ex = std::string(SKYLANE_TEST_DATA) + "/../../examples/";
  return "fence check --corridor " + ex + "fence/corridor.json --zones " + ex + "fence/zones_ed269.json --ground-amsl 408 " +
         "--buildings " + ex + "skymask/buildings.geojson";
}

TEST(Cli, FenceCheckGivesTheVerdictOfOneFix) {
  // On the first leg, 0.5 m above the centre line with VPL 1 m: VAL₁ = 1.44 m is exceeded by
  // 0.06 m (level 1 violated); the airspace box and everything else hold.
  const RunResult r = run(fenceArgs() +
                          R"( --fix '{"time":"2026-11-23T12:00:00Z","lat":47.3763,"lon":8.5405,"h_ell_m":515.5,"hpl_m":1.0,"vpl_m":1.0}')");
  ASSERT_EQ(r.status, 0) << r.out;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["verdict"], "outside");
  EXPECT_EQ(j["violated"], "level1");
  EXPECT_EQ(j["checks"][0]["level"], "level1");
  EXPECT_NEAR(j["checks"][0]["margin_v_m"].get<double>(), -0.06, 1e-3);
  EXPECT_EQ(j["checks"][1]["verdict"], "inside");
}

TEST(Cli, FenceCheckStreamsVerdictsAndSkipsBadLines) {
  const std::string fixes = writeTemp("fixes.jsonl",
      R"({"id":"a","time":"2026-11-23T12:00:00Z","lat":47.3763,"lon":8.5405,"h_ell_m":515.0,"hpl_m":1.0,"vpl_m":1.0})" "\n"
      R"({"id":"b","time":"2026-11-23T12:00:01Z","lat":47.3763,"lon":8.5405,"h_ell_m":515.0,"hpl_m":-1,"vpl_m":1.0})" "\n"
      "not json\n"
      R"({"id":"c","time":"2026-11-23T12:00:02Z","lat":47.37995,"lon":8.5452,"h_ell_m":515.0,"hpl_m":5,"vpl_m":5})" "\n"
      R"({"id":"d","time":"2026-11-23T17:00:00Z","lat":47.37995,"lon":8.5452,"h_ell_m":515.0,"hpl_m":5,"vpl_m":5})" "\n");
  const RunResult r = run(fenceArgs() + " --fixes " + fixes);
  ASSERT_EQ(r.status, 0) << r.out;
  std::istringstream in(r.out);
  std::vector<nlohmann::json> lines;
  for (std::string l; std::getline(in, l);) {
    if (l.rfind('{', 0) == 0) lines.push_back(nlohmann::json::parse(l));  // stderr's lines start "skylane:"
  }
  EXPECT_NE(r.out.find("skylane: fence check: 3 fixes checked, 2 rejected"), std::string::npos) << r.out;
  ASSERT_EQ(lines.size(), 5u) << r.out;
  EXPECT_EQ(lines[0]["id"], "a");
  EXPECT_EQ(lines[0]["verdict"], "inside");
  EXPECT_EQ(lines[1]["event"], "rejected_input");
  EXPECT_EQ(lines[1]["line"], 2);
  EXPECT_NE(lines[1]["error"].get<std::string>().find("field '$.hpl_m': got '-1', expected a protection level"), std::string::npos);
  EXPECT_EQ(lines[2]["event"], "rejected_input");
  EXPECT_EQ(lines[2]["line"], 3);
  // In the Christmas market circle while it is active (10:00–16:00 UTC), and not after.
  EXPECT_EQ(lines[3]["id"], "c");
  bool in_event = false;
  for (const auto& c : lines[3]["checks"]) in_event = in_event || (c["subject"] == "EX-ZH-EVENT" && c["verdict"] == "met");
  EXPECT_TRUE(in_event) << lines[3].dump();
  for (const auto& c : lines[4]["checks"]) EXPECT_NE(c["subject"], "EX-ZH-EVENT");
}

TEST(Cli, FenceCheckOnSeveralThreadsWritesTheBytesOfOneThread) {
  // GIVEN 3,500 fixes over the example's corridor, zones and buildings (three blocks and a
  // half), with bad lines and blank lines in every block, at a block's first and last line too
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::ostringstream text;
  for (int k = 1; k <= 3500; ++k) {
    if (k % 997 == 0 || k == 1026 || k == 1027) {  // 1026, 1027: the 1,024th and 1,025th non-blank lines
      text << (k % 2 == 0 ? "not json" : R"({"time":"2026-11-23T12:00:00Z","lat":47.3763,"lon":8.5405,"h_ell_m":515,"hpl_m":-1,"vpl_m":1})") << "\n";
    } else if (k % 501 == 0) {
      text << "  \n";
    } else {
      char line[256];
      std::snprintf(line, sizeof line, R"({"id":%d,"time":"2026-11-23T12:%02d:%02dZ","lat":%.7f,"lon":%.7f,"h_ell_m":%.2f,"hpl_m":%.2f,"vpl_m":%.2f})",
                    k, k / 60 % 60, k % 60, 47.3745 + 0.0045 * u(rng), 8.5385 + 0.0065 * u(rng), 480.0 + 80.0 * u(rng),
                    0.5 + 20.0 * u(rng), 0.5 + 10.0 * u(rng));
      text << line << "\n";
    }
  }
  const std::string fixes = writeTemp("threads.jsonl", text.str());
  // WHEN it is checked on one thread and on three (stdout and stderr together, in their order)
  const RunResult one = run(fenceArgs() + " --fixes " + fixes + " --threads 1");
  const RunResult three = run(fenceArgs() + " --fixes " + fixes + " --threads 3");
  // THEN both say the same, byte for byte, with every line answered and the bad ones skipped
  ASSERT_EQ(one.status, 0) << one.out.substr(0, 2000);
  ASSERT_EQ(three.status, 0);
  EXPECT_TRUE(one.out == three.out) << "the outputs differ (" << one.out.size() << " and " << three.out.size() << " bytes)";
  EXPECT_NE(one.out.find("skylane: fence check: 3489 fixes checked, 5 rejected"), std::string::npos) << one.out.substr(one.out.size() - 300);
  EXPECT_EQ(std::count(one.out.begin(), one.out.end(), '\n'), 3489 + 2 * 5 + 1);  // verdicts, events and messages, the summary
  // AND a thread count of 0 is refused with exit 2
  EXPECT_EQ(run(fenceArgs() + " --fixes " + fixes + " --threads 0").status, 2);
}

TEST(Cli, FenceCheckRefusesABadCorridorFileWithExitTwo) {
  const std::string corridor = writeTemp("bad_corridor.json", R"({"path":[{"lat":47,"lon":8,"h_ell_m":500}],"vehicle":{"lateral_m":1,"longitudinal_m":1}})");
  const RunResult r = run("fence check --corridor " + corridor + R"( --fix '{}')");
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.out.find("bad_corridor.json: field '$.path'"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("at least 2 waypoints"), std::string::npos) << r.out;
}

TEST(Cli, SimulateWritesTheEpochsCurvesAndStanfordDiagrams) {
  const std::string out = test::scratchPath("sim_out");
  const RunResult r = run("simulate " + std::string(SKYLANE_TEST_DATA) +
                          "/../../examples/simulate/gnss_ins_sat_20sigma.json --out " + out);
  ASSERT_EQ(r.status, 0) << r.out;
  EXPECT_NE(r.out.find("752 s of flight, 751 GNSS epochs"), std::string::npos) << r.out;
  for (const char* m : {"fault_mode", "three_hypothesis_ins", "raim", "araim"}) {
    EXPECT_NE(r.out.find(std::string("  ") + m), std::string::npos) << m;
  }
  EXPECT_EQ(r.out.find("NOT bounded"), std::string::npos) << r.out;
  std::ifstream csv(out + "/epochs.csv");
  std::string header;
  std::getline(csv, header);
  EXPECT_EQ(header.rfind("t_s,truth_e_m,truth_n_m,truth_u_m,", 0), 0u) << header;
  int rows = 0, excluded_g19 = 0;
  for (std::string line; std::getline(csv, line); ++rows) excluded_g19 += line.find(",G19,") != std::string::npos ? 1 : 0;
  EXPECT_EQ(rows, 751);
  EXPECT_EQ(excluded_g19, 50);  // 200–250 s: the LSR test excludes the 20σ₀ satellite
  for (const char* svg : {"errors_and_pls.svg", "stanford_horizontal.svg", "stanford_vertical.svg"}) {
    std::ifstream f(out + "/" + svg);
    const std::string text((std::istreambuf_iterator<char>(f)), std::istreambuf_iterator<char>());
    EXPECT_NE(text.find("<svg"), std::string::npos) << svg;
  }
}

TEST(Cli, SimulateRefusesABadScenarioWithExitTwo) {
  const std::string base = R"({"origin":{"lat_deg":47,"lon_deg":8,"h_ell_m":500},"start":"2020-01-01T07:00:00Z",)"
                           R"("trajectory":{"lawnmower":{"lines":2,"line_length_m":100,"spacing_m":50,"height_m":10,"speed_mps":5}},)";
  const std::string unknown = writeTemp("scenario_unknown.json", base + R"("orbits":["x.txt"],"wings":2})");
  RunResult r = run("simulate " + unknown);
  EXPECT_EQ(r.status, 2) << r.out;
  EXPECT_NE(r.out.find("scenario_unknown.json: field '$.wings'"), std::string::npos) << r.out;
  const std::string missing = writeTemp("scenario_orbits.json", base + R"("orbits":["no_such_almanac.txt"]})");
  r = run("simulate " + missing);
  EXPECT_EQ(r.status, 2) << r.out;
  EXPECT_NE(r.out.find("field '$.orbits[0]'"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("no_such_almanac.txt"), std::string::npos) << r.out;
  const std::string fault = writeTemp("scenario_fault.json", base + R"("orbits":["x.txt"],"faults":[{"type":"satellite","sats":["Q7"],"start_s":1,"end_s":2,"bias_m":3}]})");
  r = run("simulate " + fault);
  EXPECT_EQ(r.status, 2) << r.out;
  EXPECT_NE(r.out.find("$.faults[0].sats[0]"), std::string::npos) << r.out;
}

using nlohmann::json;

TEST(Cli, ApproveWritesTheReportAndItsExchangeFormats) {
  const std::string out = test::scratchPath("approve_out");
  const RunResult r = run("approve " + std::string(SKYLANE_TEST_DATA) + "/../../examples/approve/mission.json --out " + out);
  ASSERT_EQ(r.status, 0) << r.out;
  EXPECT_NE(r.out.find("\"decision\": \"approved\""), std::string::npos);
  EXPECT_NE(r.out.find("APPROVED"), std::string::npos);
  std::ifstream report(out + "/report.json");
  const json j = json::parse(report);
  EXPECT_EQ(j["decision"], "approved");
  EXPECT_GE(j["route"].size(), 2u);
  EXPECT_EQ(j["inputs"][0]["role"], "mission");
  EXPECT_EQ(j["inputs"][0]["sha256"].get<std::string>().size(), 64u);
  std::ifstream geo(out + "/route.geojson");
  const json g = json::parse(geo);
  EXPECT_EQ(g["type"], "FeatureCollection");
  EXPECT_EQ(g["features"][0]["geometry"]["type"], "LineString");
  std::ifstream intent(out + "/operational_intent.json");
  const json oi = json::parse(intent);
  const json& v = oi["operational_intent"]["volumes"][0];
  EXPECT_EQ(v["volume"]["altitude_lower"]["reference"], "W84");
  EXPECT_EQ(v["time_start"]["format"], "RFC3339");
  EXPECT_EQ(v["volume"]["outline_polygon"]["vertices"].size(), 4u);
  EXPECT_EQ(oi["operational_intent"]["volumes"].size(), j["route"].size() - 1);
}

TEST(Cli, ApprovePlanAndPlanExportWriteTheSameQgroundcontrolPlan) {
  // GIVEN an approved mission written with --out
  const std::string out = test::scratchPath("approve_plan");
  const std::string example = std::string(SKYLANE_TEST_DATA) + "/../../examples/approve";
  ASSERT_EQ(run("approve " + example + "/mission.json --out " + out).status, 0);
  // WHEN its report is exported again, and a rejected report is offered
  const RunResult r = run("plan export " + out + "/report.json -o " + out + "/export.plan --firmware px4");
  ASSERT_EQ(r.status, 0) << r.out;
  const std::string rejected = test::scratchPath("approve_plan_rejected");
  (void)run("approve " + example + "/mission_rejected.json --out " + rejected);
  const RunResult refused = run("plan export " + rejected + "/report.json");
  // THEN both plans are the same file but for the firmware type, and the rejected route has none
  std::ifstream a(out + "/mission.plan"), b(out + "/export.plan");
  json pa = json::parse(a), pb = json::parse(b);
  EXPECT_EQ(pa["fileType"], "Plan");
  EXPECT_EQ(pb["mission"]["firmwareType"], 12);  // MAV_AUTOPILOT_PX4
  pb["mission"]["firmwareType"] = pa["mission"]["firmwareType"];
  EXPECT_EQ(pa, pb);
  EXPECT_FALSE(std::filesystem::exists(rejected + "/mission.plan"));
  EXPECT_EQ(refused.status, 2) << refused.out;
  EXPECT_NE(refused.out.find("'$.decision'"), std::string::npos) << refused.out;
}

/// Where a line labelled `label` starts in a time-series SVG, as a fraction of its panel's height
/// above the panel's bottom (NaN when the line is not there).
double lineHeightInPanel(const std::string& svg, const std::string& label) {
  const std::size_t title = svg.find("<title>" + label + "</title>");
  if (title == std::string::npos) return std::nan("");
  const std::size_t path = svg.rfind("<path d=\"", title);
  const std::size_t rect = svg.rfind("<rect x=\"70\" y=\"", path);
  if (path == std::string::npos || rect == std::string::npos) return std::nan("");
  const double y = std::stod(svg.substr(svg.find(',', path) + 1));
  const double top = std::stod(svg.substr(rect + 16));
  const double height = std::stod(svg.substr(svg.find("height=\"", rect) + 8));
  return (top + height - y) / height;
}

TEST(Cli, ApproveSaysHowMuchOfTheRouteHoldsTheCorridorAndDrawsBothLevelsReadably) {
  // GIVEN a 1.5 m drone (HAL₁ = VAL₁ = 1.8 m) on GNSS alone, whose HPL is metres
  const std::string mission = writeTemp("mission_level1.json",
                                        R"({"name":"level-1 truth","vehicle":{"lateral_m":1.5,"longitudinal_m":1.5,"cruise_speed_mps":12},)"
                                        R"("k1":1.2,"k2":150,"start":{"lat":47.3712,"lon":8.532},"goal":{"lat":47.3712,"lon":8.5518},)"
                                        R"("departure":"2020-01-01T14:00:00Z","ground_amsl_m":408,"integrity":{"cost_weight":0},)"
                                        R"("planner":{"iterations":600,"seed":3},)"
                                        R"("orbits":[")" + test::dataPath("gnss/alm01jan2020.txt") + R"("]})");
  const std::string out = test::scratchPath("approve_level1");
  const RunResult r = run("approve " + mission + " --out " + out);
  // THEN the summary line says the corridor is held nowhere and what that means in flight
  ASSERT_EQ(r.status, 0) << r.out;
  EXPECT_NE(r.out.find("skylane: approve: APPROVED — corridor ±1.8 m / ±1.8 m held at 0 % of samples: expect a "
                       "monitoring rerun at every fix (in "),
            std::string::npos)
      << r.out;
  std::ifstream report(out + "/report.json");
  const json j = json::parse(report);
  EXPECT_EQ(j["availability"]["level1"]["fraction"], 0.0);
  EXPECT_EQ(j["availability"]["level2"]["fraction"], 1.0);
  // AND pl.svg draws each level's limits well above its panel's floor, under the mission's departure
  std::ifstream svg_file(out + "/pl.svg");
  const std::string svg((std::istreambuf_iterator<char>(svg_file)), std::istreambuf_iterator<char>());
  EXPECT_NE(svg.find("level-1 truth — approved, departure 2020-01-01T14:00:00Z"), std::string::npos);
  for (const char* label : {"HAL₁ (level 1)", "VAL₁ (level 1)", "HAL₂ (level 2)", "VAL₂ (level 2)"}) {
    const double h = lineHeightInPanel(svg, label);
    EXPECT_GT(h, 0.2) << label;
    EXPECT_LE(h, 1.0) << label;
  }
  EXPECT_LT(lineHeightInPanel(svg, "HAL₁ (level 1)"), 0.5);  // the PLs above it still fit the panel
}

TEST(Cli, ApproveRejectsAGoalInAProhibitedZoneWithExitOne) {
  const RunResult r = run("approve " + std::string(SKYLANE_TEST_DATA) + "/../../examples/approve/mission_rejected.json");
  EXPECT_EQ(r.status, 1) << r.out;
  EXPECT_NE(r.out.find("\"decision\": \"rejected\""), std::string::npos);
  EXPECT_NE(r.out.find("EX-ZH-HOSPITAL"), std::string::npos);
  // rejected before any route was timed, the report still names the mission's departure
  EXPECT_NE(r.out.find("\"departure\": \"2020-01-01T14:00:00Z\""), std::string::npos) << r.out;
}

TEST(Cli, AMissingZoneFileNamesTheMissionsFieldAndTheResolvedPath) {
  const std::string mission = writeTemp("mission_missing_zones.json",
                                        R"({"vehicle":{"lateral_m":1,"longitudinal_m":1,"cruise_speed_mps":10},)"
                                        R"("start":{"lat":47.37,"lon":8.54},"goal":{"lat":47.38,"lon":8.54},)"
                                        R"("departure":"2020-01-01T14:00:00Z","zones":["no_such_zones.json"],)"
                                        R"("orbits":[")" + test::dataPath("gnss/alm01jan2020.txt") + R"("]})");
  const RunResult r = run("approve " + mission);
  EXPECT_EQ(r.status, 2) << r.out;
  EXPECT_NE(r.out.find("mission_missing_zones.json: field '$.zones[0]'"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("no_such_zones.json"), std::string::npos) << r.out;
}

TEST(Cli, ApproveChecksTheOrbitFilesAgeAgainstTheDeparture) {
  const std::string alm = test::dataPath("gnss/alm01jan2020.txt");
  auto mission = [&](const std::string& name, const std::string& departure) {
    return writeTemp(name, R"({"vehicle":{"lateral_m":1.2,"longitudinal_m":1,"cruise_speed_mps":12},)"
                           R"("start":{"lat":47.3712,"lon":8.532},"goal":{"lat":47.3712,"lon":8.545},"ground_amsl_m":408,)"
                           R"("planner":{"iterations":300,"seed":3},"integrity":{"cost_weight":0},)"
                           R"("departure":")" + departure + R"(","orbits":[")" + alm + R"("]})");
  };
  // GIVEN the almanac of 2020-01-03: WHEN the departure is in 2025 THEN exit 2 naming the file,
  // its epoch, the departure, the limit and the age
  const RunResult old = run("approve " + mission("mission_2025.json", "2025-06-01T14:00:00Z"));
  EXPECT_EQ(old.status, 2) << old.out;
  EXPECT_NE(old.out.find("skylane: error: " + alm + ": field 'almanac epoch t_oa': got '2020-01-03T19:56:30Z"), std::string::npos)
      << old.out;
  EXPECT_NE(old.out.find("within 90.0 days of the departure 2025-06-01T14:00:00Z; it is 1975.8 days from it"), std::string::npos)
      << old.out;
  // WHEN the departure is 10.8 days after t_oa THEN the approval runs, with a warning on stderr
  // and in the report
  const RunResult stale = run("approve " + mission("mission_stale.json", "2020-01-14T14:00:00Z"));
  EXPECT_EQ(stale.status, 0) << stale.out;
  EXPECT_NE(stale.out.find("skylane: warning: " + alm + ": the almanac's t_oa 2020-01-03T19:56:30Z"), std::string::npos) << stale.out;
  EXPECT_NE(stale.out.find("\"warnings\": ["), std::string::npos) << stale.out;
}

TEST(Cli, ApproveRefusesABadMissionWithExitTwo) {
  const std::string bad = writeTemp("bad_mission.json", R"({"vehicle":{"lateral_m":1,"longitudinal_m":1,"cruise_speed_mps":10},)"
                                                       R"("start":{"lat":47,"lon":8},"goal":{"lat":47.01,"lon":8},)"
                                                       R"("departure":"2020-01-01T14:00:00Z","orbits":["x.txt"],"planner":{"algorithm":"dijkstra"}})");
  const RunResult r = run("approve " + bad);
  EXPECT_EQ(r.status, 2) << r.out;
  EXPECT_NE(r.out.find("bad_mission.json: field '$.planner.algorithm'"), std::string::npos) << r.out;
}

}  // namespace
}  // namespace skylane
