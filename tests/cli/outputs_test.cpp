// Outputs end to end (issue 23, items 3, 8 and 10): every command that writes files writes
// them whole or not at all — a write error (a missing folder, a file in the way, a full disk,
// standard output on /dev/full) exits 2 with one line naming the file, and a failing command
// leaves the outputs of an earlier run as they were.
#include "tests/test_util.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <filesystem>
#include <fstream>
#include <string>

namespace skylane {
namespace {

using RunResult = test::CommandResult;

const std::string kBin = SKYLANE_BINARY;
const std::string kExamples = std::string(SKYLANE_TEST_DATA) + "/../../examples";

/// The skylane command with these arguments, stdout and stderr together.
RunResult run(const std::string& args) { return test::runCommand(kBin + " " + args + " 2>&1"); }

/// A line-count of text (the error contract: one line).
std::size_t lines(const std::string& text) { return static_cast<std::size_t>(std::count(text.begin(), text.end(), '\n')); }

/// The example mission approved once for the suite (its report feeds fly, track and plan export).
class CliOutputs : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new std::string(test::scratchPath("cli-outputs"));
    std::filesystem::create_directories(*dir_);
    const RunResult r = test::runCommand(kBin + " approve " + kExamples + "/approve/mission.json --out " + *dir_ +
                                         "/approve > /dev/null 2>&1");
    ASSERT_EQ(r.status, 0) << r.out;
    std::ofstream(*dir_ + "/plain") << "a regular file where a folder is expected\n";
  }
  static void TearDownTestSuite() { delete dir_; }
  static std::string report() { return *dir_ + "/approve/report.json"; }
  /// A file holding `text` from "an earlier run".
  static std::string earlier(const std::string& name, const std::string& text = "earlier run\n") {
    const std::string path = *dir_ + "/" + name;
    std::ofstream(path) << text;
    return path;
  }
  static std::string* dir_;
};
std::string* CliOutputs::dir_ = nullptr;

TEST_F(CliOutputs, TrackMapIntoAMissingFolderExitsTwoBeforeTheRun) {
  const std::string fixes = *dir_ + "/fixes.jsonl";
  ASSERT_EQ(run("fly " + report() + " --out " + fixes).status, 0);
  const RunResult r = run("track --approval " + report() + " --input " + fixes + " --no-replan --map /nonexistent/m.svg");
  EXPECT_EQ(r.status, 2) << r.out;
  EXPECT_EQ(r.out, "skylane: error: /nonexistent/m.svg: cannot write (--map): its folder /nonexistent does not exist\n");
}

TEST_F(CliOutputs, FlyWithATruthFileItCannotWriteLeavesTheEarlierFixes) {
  const std::string fixes = earlier("fly_fixes.jsonl");
  const RunResult r = run("fly " + report() + " --out " + fixes + " --truth /nonexistent/t.csv");
  EXPECT_EQ(r.status, 2) << r.out;
  EXPECT_NE(r.out.find("/nonexistent/t.csv: cannot write (--truth)"), std::string::npos) << r.out;
  EXPECT_EQ(lines(r.out), 1u) << r.out;
  EXPECT_EQ(test::readFile(fixes), "earlier run\n");
}

TEST_F(CliOutputs, PredictWithAPlotItCannotWriteLeavesTheEarlierOutput) {
  const std::string csv = earlier("predict.csv");
  const RunResult r = run("integrity predict --almanac " + test::dataPath("gnss/alm01jan2020.txt") +
                          " --lat 47 --lon 8 --start 2020-01-01T00:00:00Z --duration 1h --output " + csv +
                          " --plot /nonexistent/p.svg");
  EXPECT_EQ(r.status, 2) << r.out;
  EXPECT_EQ(r.out, "skylane: error: /nonexistent/p.svg: cannot write (--plot): its folder /nonexistent does not exist\n");
  EXPECT_EQ(test::readFile(csv), "earlier run\n");
}

TEST_F(CliOutputs, AFailingCommandLeavesEveryEarlierOutputIntact) {
  // GIVEN outputs of an earlier run WHEN the same command fails on its input THEN they stay
  const std::string plan = earlier("export.plan"), zones = earlier("zones.geojson");
  const std::string bad = earlier("bad.json", "{\"not\": \"a report\"}\n");
  EXPECT_EQ(run("plan export " + bad + " --out " + plan).status, 2);
  EXPECT_EQ(run("zones export " + bad + " --output " + zones).status, 2);
  EXPECT_EQ(test::readFile(plan), "earlier run\n");
  EXPECT_EQ(test::readFile(zones), "earlier run\n");
  // AND the same commands on good input replace them whole
  EXPECT_EQ(run("plan export " + report() + " --out " + plan).status, 0);
  EXPECT_EQ(nlohmann::json::parse(test::readFile(plan)).at("fileType"), "Plan");
  EXPECT_TRUE(test::hiddenFiles(*dir_).empty());
}

TEST_F(CliOutputs, AnOutputUnderARegularFileExitsTwoNamingIt) {
  const std::string under = *dir_ + "/plain/";
  struct Case {
    std::string args, expected;
  };
  const Case cases[] = {
      {"zones export " + kExamples + "/zones/geo-awareness-che-1.json --output " + under + "z.geojson",
       under + "z.geojson: cannot write (--output): its folder"},
      {"approve " + kExamples + "/approve/mission.json --out " + under + "approve",
       under + "approve: cannot write (--out): cannot make the folder: "},
      {"simulate " + kExamples + "/simulate/gnss_ins_no_fault.json --out " + under + "sim",
       under + "sim: cannot write (--out): cannot make the folder: "},
      {"track --approval " + report() + " --input /dev/null --out " + under + "events.jsonl",
       under + "events.jsonl: cannot write (--out): Not a directory"},
      {"plan export " + report() + " --out " + under + "x.plan", under + "x.plan: cannot write (--out): its folder"},
  };
  for (const Case& c : cases) {
    const RunResult r = run(c.args);
    EXPECT_EQ(r.status, 2) << c.args << "\n" << r.out;
    EXPECT_NE(r.out.find("skylane: error: " + c.expected), std::string::npos) << c.args << "\n" << r.out;
    EXPECT_EQ(lines(r.out), 1u) << c.args << "\n" << r.out;
  }
}

TEST_F(CliOutputs, DatabaseProblemsExitTwoNamingTheFile) {
  const std::string folder = *dir_ + "/db_folder";
  std::filesystem::create_directories(folder);
  struct Case {
    std::string db, expected;
  };
  const Case cases[] = {
      {report(), report() + ": field '(tracker database)': got 'file is not a database'"},
      {folder, folder + ": field '(tracker database)': got 'a folder'"},
      {*dir_ + "/plain/track.sqlite", *dir_ + "/plain/track.sqlite: cannot write: tracker database: cannot open"},
  };
  for (const Case& c : cases) {
    const RunResult r = run("track --approval " + report() + " --input /dev/null --db " + c.db);
    EXPECT_EQ(r.status, 2) << c.db << "\n" << r.out;
    EXPECT_NE(r.out.find("skylane: error: " + c.expected), std::string::npos) << r.out;
    EXPECT_EQ(lines(r.out), 1u) << r.out;
  }
}

TEST_F(CliOutputs, AFolderGivenAsAnInputFileIsAnErrorNamingIt) {
  const std::string folder = *dir_ + "/input_folder";
  std::filesystem::create_directories(folder);
  struct Case {
    std::string args, expected;
  };
  const Case cases[] = {
      {"fence check --corridor " + kExamples + "/fence/corridor.json --fixes " + folder, folder + ": field '--fixes': got 'a folder', expected a file"},
      {"track --approval " + report() + " --input " + folder, folder + ": field '--input': got 'a folder', expected a file"},
      {"zones validate " + folder, folder + ": field 'file': got 'a folder', expected a file"},
      {"integrity predict --almanac " + folder + " --lat 1 --lon 2 --start 2020-01-01T00:00:00Z",
       folder + ": field 'file': got 'a folder', expected a file"},
  };
  for (const Case& c : cases) {
    const RunResult r = run(c.args);
    EXPECT_EQ(r.status, 2) << c.args << "\n" << r.out;
    EXPECT_NE(r.out.find(c.expected), std::string::npos) << c.args << "\n" << r.out;
  }
}

TEST_F(CliOutputs, RawBytesOfABadInputAreQuotedOnOneLine) {
  // GIVEN a YUMA almanac whose health field holds a newline-free run of terminal escapes and a NUL
  const std::string alm = *dir_ + "/escapes_alm.txt";
  {
    std::ofstream f(alm, std::ios::binary);
    f << "******** Week 1 almanac for PRN-01 ********\nID:                         01\nHealth:  \x1b[2J\x1b]0;x\x07";
    f.put('\0');
    f << "tail\n";
  }
  const RunResult r = run("integrity predict --almanac " + alm + " --lat 1 --lon 2 --start 2020-01-01T00:00:00Z");
  EXPECT_EQ(r.status, 2) << r.out;
  EXPECT_EQ(lines(r.out), 1u) << r.out;
  EXPECT_EQ(r.out.find('\x1b'), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("\\x1b[2J\\x1b]0;x\\x07\\x00tail"), std::string::npos) << r.out;
}

TEST_F(CliOutputs, NumbersBeyondTheirRangeNameTheOptionOrTheField) {
  const std::string corridor = *dir_ + "/huge_vehicle.json";
  nlohmann::json c = nlohmann::json::parse(test::readFile(kExamples + "/fence/corridor.json"));
  c["vehicle"]["lateral_m"] = 1e308;
  std::ofstream(corridor) << c.dump();
  const std::string mission = *dir_ + "/huge_margin.json";
  nlohmann::json m = nlohmann::json::parse(test::readFile(kExamples + "/approve/mission.json"));
  m["planner"]["margin_m"] = 1e308;
  std::ofstream(mission) << m.dump();
  struct Case {
    std::string args, expected;
  };
  const Case cases[] = {
      {"track --approval " + report() + " --input /dev/null --stale-after 0",
       "--stale-after: field '--stale-after': got '0', expected seconds in (0, 86400]"},
      {"track --approval " + report() + " --input /dev/null --horizon 1e300", "field '--horizon': got '1e+300'"},
      {"fence check --corridor " + corridor + " --fix '{}'", corridor + ": field '$.vehicle.lateral_m': got '1e+308'"},
      {"approve " + mission, mission + ": field '$.planner.margin_m': got '1e+308', expected a number > 0 and ≤ 10000 m"},
  };
  for (const Case& k : cases) {
    const RunResult r = run(k.args);
    EXPECT_EQ(r.status, 2) << k.args << "\n" << r.out;
    EXPECT_NE(r.out.find(k.expected), std::string::npos) << k.args << "\n" << r.out;
    EXPECT_EQ(lines(r.out), 1u) << k.args << "\n" << r.out;
  }
}

TEST_F(CliOutputs, AStoredPositionBeyondTheInputIsRefusedNotSkippedForGood) {
  const std::string fixes = *dir_ + "/resume_fixes.jsonl", db = *dir_ + "/resume.sqlite";
  std::filesystem::remove(db);
  ASSERT_EQ(run("fly " + report() + " --out " + fixes).status, 0);
  const std::string track = "track --approval " + report() + " --input " + fixes + " --no-replan --db " + db + " --out /dev/null";
  ASSERT_EQ(run(track).status, 0);
  // GIVEN the stored position damaged to INT64_MAX
  test::runCommand("sqlite3 " + db + " 'UPDATE inputs SET line = 9223372036854775807'");
  const std::string shown = test::runCommand("sqlite3 " + db + " 'SELECT line FROM inputs'").out;
  if (shown != "9223372036854775807\n") GTEST_SKIP() << "needs the sqlite3 shell: " << shown;
  // THEN a restart says so naming the database, the input and the value, and exits 2
  const RunResult r = run(track);
  EXPECT_EQ(r.status, 2) << r.out;
  EXPECT_NE(r.out.find("skylane: error: " + db + ": field '(tracker database) inputs[" + fixes +
                       "].line': got '9223372036854775807', expected a line within " + fixes + " (which has "),
            std::string::npos)
      << r.out;
}

TEST_F(CliOutputs, AWriteErrorOnStandardOutputExitsTwo) {
  const RunResult r = test::runCommand(kBin + " integrity pl --geometry " + kExamples + "/predict/geometry.json 2>&1 > /dev/full");
  EXPECT_EQ(r.status, 2) << r.out;
  EXPECT_EQ(r.out, "skylane: error: standard output: cannot write: No space left on device\n");
  // A rejected approval (exit 1) with its report lost is a write error too.
  const RunResult rejected =
      test::runCommand(kBin + " approve " + kExamples + "/approve/mission_rejected.json 2>&1 > /dev/full | tail -n 1");
  EXPECT_EQ(rejected.out, "skylane: error: standard output: cannot write: No space left on device\n");
}

TEST_F(CliOutputs, ApproveOnAFullDiskExitsTwoAndKeepsTheEarlierReport) {
  test::SmallDisk disk("approve-full");
  if (!disk.mounted()) GTEST_SKIP() << "mounting a tmpfs needs root";
  const std::string out = disk.path() + "/approve";
  std::filesystem::create_directories(out);
  std::ofstream(out + "/report.json") << "earlier run\n";
  const RunResult r = run("approve " + kExamples + "/approve/mission.json --out " + out);
  EXPECT_EQ(r.status, 2) << r.out;
  EXPECT_NE(r.out.find("skylane: error: " + out + "/"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find(": cannot write (--out): No space left on device\n"), std::string::npos) << r.out;
  EXPECT_EQ(r.out.find("APPROVED"), std::string::npos) << r.out;
  EXPECT_EQ(test::readFile(out + "/report.json"), "earlier run\n");
  EXPECT_TRUE(test::hiddenFiles(out).empty());
}

TEST_F(CliOutputs, PredictAndTrackOnAFullDiskExitTwoNamingTheFile) {
  test::SmallDisk disk("stream-full");
  if (!disk.mounted()) GTEST_SKIP() << "mounting a tmpfs needs root";
  const std::string csv = disk.path() + "/predict.csv";
  const RunResult p = run("integrity predict --almanac " + test::dataPath("gnss/alm01jan2020.txt") +
                          " --lat 47 --lon 8 --start 2020-01-01T00:00:00Z --duration 24h --step 30s --output " + csv);
  EXPECT_EQ(p.status, 2) << p.out;
  EXPECT_EQ(p.out, "skylane: error: " + csv + ": cannot write (--output): No space left on device\n");
  EXPECT_FALSE(std::filesystem::exists(csv));
  // The tracker's event stream is appended as it goes (not atomic); a full disk stops it with exit 2.
  const std::string fixes = *dir_ + "/full_fixes.jsonl", events = disk.path() + "/events.jsonl";
  ASSERT_EQ(run("fly " + report() + " --out " + fixes).status, 0);
  const RunResult t = run("track --approval " + report() + " --input " + fixes + " --no-replan --out " + events);
  EXPECT_EQ(t.status, 2) << t.out;
  EXPECT_NE(t.out.find("skylane: error: " + events + ": cannot write (--out): No space left on device\n"), std::string::npos)
      << t.out;
}

// fuzz/run_fuzzers.sh (issue 23 item 13): a target without seed files runs from an empty corpus
// and never stops the targets after it; a missing target is reported and the others run.
TEST(FuzzScript, AMissingSeedFolderOrTargetStopsNoOtherTarget) {
  // GIVEN a copy of the script in a tree with one seed folder (fence) and no tests/data, and
  // stand-in targets that print libFuzzer's final statistics
  const std::string tree = test::scratchPath("fuzz-tree");
  std::filesystem::remove_all(tree);
  std::filesystem::create_directories(tree + "/fuzz/corpus/fence");
  std::filesystem::create_directories(tree + "/build/fuzz");
  std::filesystem::copy_file(std::string(SKYLANE_TEST_DATA) + "/../../fuzz/run_fuzzers.sh", tree + "/fuzz/run_fuzzers.sh");
  std::ofstream(tree + "/fuzz/corpus/fence/seed.json") << "{}\n";
  const std::string targets[] = {"buildings", "zones", "fence", "scenario", "mission", "nmea", "track"};
  for (const std::string& t : targets) {
    const std::string exe = tree + "/build/fuzz/fuzz_" + t;
    std::ofstream(exe) << "#!/bin/sh\necho 'stat::number_of_executed_units: 7'\n";
    std::filesystem::permissions(exe, std::filesystem::perms::owner_all);
  }
  std::string list;
  for (const std::string& t : targets) list += " " + t;
  // WHEN it runs all of them THEN every target ran, and the exit status is 0
  const RunResult r = test::runCommand("SKYLANE_FUZZ_WORK=" + tree + "/work bash " + tree + "/fuzz/run_fuzzers.sh " + tree +
                                       "/build 1" + list + " 2>&1; echo status=$?");
  for (const std::string& t : targets) EXPECT_NE(r.out.find("== fuzz_" + t + ":"), std::string::npos) << t << "\n" << r.out;
  EXPECT_NE(r.out.find("no seed files for buildings"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("status=0"), std::string::npos) << r.out;
  // AND a target that is not built is reported, the ones after it still run, the status is 1
  const RunResult missing = test::runCommand("SKYLANE_FUZZ_WORK=" + tree + "/work bash " + tree + "/fuzz/run_fuzzers.sh " +
                                             tree + "/build 1 ubx fence 2>&1; echo status=$?");
  EXPECT_NE(missing.out.find("== fuzz_ubx: missing"), std::string::npos) << missing.out;
  EXPECT_NE(missing.out.find("== fuzz_fence: 1 s, 1 seeds"), std::string::npos) << missing.out;
  EXPECT_NE(missing.out.find("status=1"), std::string::npos) << missing.out;
}

}  // namespace
}  // namespace skylane
