// The bad-input sweep as a test (issue 23): every command's input files replaced, one at a time,
// by bad ones — missing, empty, a folder, truncated, binary, another format, numbers that
// overflow or are far out of range, NaN, nesting 100,000 deep, unreadable (when not root) — and
// every output sent into a missing folder or onto a full disk (a 64 kB tmpfs, when this process
// may mount one). Each case must end within 20 s with exit 2 and one line on stderr naming the
// file or the option, no "internal error", and leave an earlier output untouched. The cases run
// two at a time; the case list and what each printed are in the failure messages.
#include "tests/test_util.hpp"

#include <gtest/gtest.h>

#include <sys/stat.h>
#include <unistd.h>

#include <atomic>
#include <filesystem>
#include <fstream>
#include <functional>
#include <mutex>
#include <random>
#include <regex>
#include <sstream>
#include <thread>

namespace skylane {
namespace {

namespace fs = std::filesystem;

const std::string kBin = SKYLANE_BINARY;
const std::string kExamples = std::string(SKYLANE_SOURCE_DIR) + "/examples";
const std::string kSentinel = "earlier output: must survive a failed run\n";

/// The kind of an input slot: which bad variants make sense for it.
enum class Format {
  kJson,    ///< a JSON document
  kYuma,    ///< "key: value" lines (a YUMA almanac)
  kText,    ///< another text format (RINEX): structural variants only
  kStream,  ///< a record stream (bad records are reported and skipped): only missing / folder
};

/// One input slot: a command line with {F} where the file goes and {OUT} a folder for outputs
/// (holding `outputs`, each pre-filled with the sentinel); `valid` a good file for it.
struct Slot {
  std::string name;
  std::string command;
  std::string valid;
  Format format;
  std::vector<std::string> outputs;
  /// The command's result is a verdict per file on standard output (`zones validate`: "F:
  /// INVALID: why"): the one line is looked for there.
  bool verdict_on_stdout = false;
};

/// One case: the command and what must hold.
struct Case {
  std::string name, command, out_dir, names;  ///< names: what the message must contain (any of, '|'-separated)
  std::vector<std::string> outputs;            ///< files under out_dir holding the sentinel
  bool verdict_on_stdout = false;              ///< Slot::verdict_on_stdout
  bool append = false;                         ///< the output is appended to: the earlier text must stay its start
  std::string fill;                            ///< a disk to fill up (a filler file) after the sentinels are written
};

/// Fills the file system of `path` with a filler file until a write fails.
void fillDisk(const std::string& path) {
  std::ofstream f(path + "/.filler", std::ios::binary);
  const std::string block(4096, 'x');
  for (int i = 0; i < 1 << 16 && f; ++i) f.write(block.data(), block.size()), f.flush();
  f.close();
  std::ofstream g(path + "/.filler2", std::ios::binary);  // the last partial block
  for (int i = 0; i < 4096 && g; ++i) g.put('x'), g.flush();
}

std::string replaceAll(std::string s, const std::string& from, const std::string& to) {
  for (std::size_t at = s.find(from); at != std::string::npos; at = s.find(from, at + to.size())) s.replace(at, from.size(), to);
  return s;
}

void writeFile(const std::string& path, const std::string& text) { std::ofstream(path, std::ios::binary) << text; }

/// The bad variants of a valid file for a format: name → content (written beside a copy of
/// the valid file's folder, so that relative references in it still resolve).
std::vector<std::pair<std::string, std::string>> badContents(const std::string& valid, Format format) {
  const std::string text = test::readFile(valid);
  std::vector<std::pair<std::string, std::string>> out;
  if (format == Format::kStream) return out;
  out.emplace_back("empty", "");
  out.emplace_back("truncated", text.substr(0, text.size() / 2));
  std::mt19937 rng(7);
  std::string binary(4096, '\0');
  for (char& c : binary) c = static_cast<char>(rng() & 0xff);
  out.emplace_back("binary", binary);
  if (format == Format::kJson) {
    out.emplace_back("wrong_format", test::readFile(kExamples + "/predict/alm01jan2020.txt"));
    const std::regex number(R"((:\s*)-?[0-9]+(\.[0-9]+)?([eE][-+]?[0-9]+)?)");
    if (std::regex_search(text, number)) {  // a file with numbers: each replaced
      out.emplace_back("overflow_1e400", std::regex_replace(text, number, "$011e400"));
      out.emplace_back("far_out_of_range", std::regex_replace(text, number, "$01-1e308"));
      out.emplace_back("nan_token", std::regex_replace(text, number, "$01NaN"));
    }
    out.emplace_back("deep_nesting", std::string(100000, '[') + std::string(100000, ']'));
  } else {
    out.emplace_back("wrong_format", test::readFile(kExamples + "/predict/geometry.json"));
  }
  if (format == Format::kYuma) {
    const std::regex value(R"((:\s+)[-+0-9.eE]+)");
    out.emplace_back("overflow_1e999", std::regex_replace(text, value, "$011e999"));
    out.emplace_back("nan_values", std::regex_replace(text, value, "$01nan"));
  }
  return out;
}

class Sweep : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new std::string(test::scratchPath("sweep"));
    fs::remove_all(*dir_);
    fs::create_directories(given() + "/report");
    fs::create_directories(*dir_ + "/logs");
    // A report and fixes to feed the commands that take them.
    const auto a = test::runCommand(kBin + " approve " + kExamples + "/approve/mission.json --out " + given() + "/report > /dev/null 2>&1");
    ASSERT_EQ(a.status, 0);
    const auto f = test::runCommand(kBin + " fly " + report() + " --out " + given() + "/fixes.jsonl 2>&1");
    ASSERT_EQ(f.status, 0) << f.out;
    writeFile(given() + "/faults.json", R"({"faults": [{"type": "satellite", "sats": ["G20"], "start_s": 20, "end_s": 40, "bias_m": 60}]})");
    writeFile(given() + "/tokens.json", R"({"tokens": [{"sha256": ")" + std::string(64, 'a') + R"(", "operator": "op"}]})");
  }
  /// The good files the suite makes (a report, fixes, faults, tokens).
  static std::string given() { return *dir_ + "/given"; }
  static void TearDownTestSuite() { delete dir_; }
  static std::string report() { return given() + "/report/report.json"; }
  static std::string gnss(const std::string& f) { return test::dataPath("gnss/" + f); }

  /// Every command's input slots.
  static std::vector<Slot> slots() {
    const std::string ex = kExamples, r = report(), fixes = given() + "/fixes.jsonl";
    const std::string predict = " --lat 47 --lon 8 --start 2020-01-01T00:00:00Z --duration 1h --step 10m";
    return {
        {"pl_geometry", "integrity pl --geometry {F}", ex + "/predict/geometry.json", Format::kJson, {}},
        {"predict_almanac", "integrity predict --almanac {F}" + predict + " --output {OUT}/p.csv", ex + "/predict/alm01jan2020.txt",
         Format::kYuma, {"p.csv"}},
        {"availability_almanac",
         "integrity availability --almanac {F} --grid-deg 30 --start 2020-01-01T00:00:00Z --duration 10m --output {OUT}/a.csv",
         ex + "/predict/alm01jan2020.txt", Format::kYuma, {"a.csv"}},
        {"spp_obs", "integrity spp --obs {F} --nav " + gnss("30400920.05n") + " --output {OUT}/s.jsonl", gnss("30400920.05o"),
         Format::kText, {"s.jsonl"}},
        {"spp_nav", "integrity spp --obs " + gnss("30400920.05o") + " --nav {F} --output {OUT}/s.jsonl", gnss("30400920.05n"),
         Format::kText, {"s.jsonl"}},
        {"skymask_buildings", "skymask --lat 47.3769 --lon 8.5417 --h-ell 500 --ground-amsl 400 --buildings {F} --svg {OUT}/m.svg",
         ex + "/skymask/buildings.geojson", Format::kJson, {"m.svg"}},
        {"fence_corridor", "fence check --corridor {F} --zones " + ex + "/fence/zones_ed269.json --fixes " + ex + "/fence/fixes.jsonl",
         ex + "/fence/corridor.json", Format::kJson, {}},
        {"fence_zones", "fence check --corridor " + ex + "/fence/corridor.json --zones {F} --fixes " + ex + "/fence/fixes.jsonl",
         ex + "/fence/zones_ed269.json", Format::kJson, {}},
        {"fence_fixes", "fence check --corridor " + ex + "/fence/corridor.json --fixes {F}", ex + "/fence/fixes.jsonl",
         Format::kStream, {}},
        {"simulate_scenario", "simulate {F} --out {OUT} --no-plots", ex + "/simulate/gnss_ins_no_fault.json", Format::kJson,
         {"summary.json"}},
        {"approve_mission", "approve {F} --out {OUT}", ex + "/approve/mission.json", Format::kJson, {"report.json"}},
        {"track_approval", "track --approval {F} --input " + fixes + " --no-replan --map {OUT}/t.svg", r, Format::kJson, {"t.svg"}},
        {"track_input", "track --approval " + r + " --input {F} --no-replan --map {OUT}/t.svg", fixes, Format::kStream, {"t.svg"}},
        {"plan_export", "plan export {F} -o {OUT}/m.plan", r, Format::kJson, {"m.plan"}},
        {"zones_validate", "zones validate {F}", ex + "/zones/geo-awareness-che-1.json", Format::kJson, {}, true},
        {"zones_at", "zones at {F} --lat 47.4 --lon 8.5 --alt-amsl 500 --time 2026-01-01T12:00:00Z",
         ex + "/zones/geo-awareness-che-1.json", Format::kJson, {}},
        {"zones_export", "zones export {F} --to geojson -o {OUT}/z.geojson", ex + "/zones/geo-awareness-che-1.json", Format::kJson,
         {"z.geojson"}},
        {"fly_report", "fly {F} --out {OUT}/f.jsonl", r, Format::kJson, {"f.jsonl"}},
        {"fly_faults", "fly " + r + " --out {OUT}/f.jsonl --imu tactical --faults {F}", given() + "/faults.json", Format::kJson,
         {"f.jsonl"}},
        {"serve_tokens", "serve --db {OUT}/s.sqlite --tokens {F} --port 0 --web none", given() + "/tokens.json", Format::kJson, {}},
        // The NATS clients check what they send before they connect (no server at this address).
        {"nats_approve_mission", "nats approve {F} --nats nats://127.0.0.1:9 --operator acme --id a1", ex + "/approve/mission.json",
         Format::kJson, {}},
        {"nats_zones_file", "nats zones {F} --nats nats://127.0.0.1:9 --owner authority --set zurich", ex + "/approve/zones_ed269.json",
         Format::kJson, {}},
        {"nats_publish_fixes", "nats publish {F} --nats nats://127.0.0.1:9 --operator acme --flight f1", fixes, Format::kStream, {}},
        {"serve_nats_tokens", "serve --db {OUT}/s.sqlite --tokens {F} --port 0 --web none --nats nats://127.0.0.1:9",
         given() + "/tokens.json", Format::kJson, {}},
    };
  }

  /// The cases of one slot: each bad variant of its file, plus missing, a folder, unreadable.
  static std::vector<Case> inputCases(const Slot& s) {
    std::vector<Case> cases;
    const std::string base = *dir_ + "/cases/" + s.name;
    const std::string copy = base + "/in";  // a copy of the valid file's folder (relative references)
    fs::create_directories(copy);
    fs::copy(fs::path(s.valid).parent_path(), copy, fs::copy_options::overwrite_existing | fs::copy_options::recursive);
    const std::string ext = fs::path(s.valid).extension().string();
    auto add = [&](const std::string& variant, const std::string& file) {
      Case c;
      c.name = s.name + "/" + variant;
      c.out_dir = base + "/out_" + variant;
      c.outputs = s.outputs;
      c.command = replaceAll(replaceAll(s.command, "{F}", file), "{OUT}", c.out_dir);
      c.names = file;
      c.verdict_on_stdout = s.verdict_on_stdout;
      cases.push_back(c);
    };
    for (const auto& [variant, content] : badContents(s.valid, s.format)) {
      const std::string file = copy + "/" + variant + ext;
      writeFile(file, content);
      add(variant, file);
    }
    add("missing", copy + "/missing" + ext);
    fs::create_directories(copy + "/folder" + ext);
    add("folder", copy + "/folder" + ext);
    if (::geteuid() != 0) {  // root reads a file whatever its mode
      const std::string file = copy + "/unreadable" + ext;
      fs::copy_file(s.valid, file, fs::copy_options::overwrite_existing);
      ::chmod(file.c_str(), 0);
      add("unreadable", file);
    }
    return cases;
  }

  /// Runs `c`; the failures it shows, "" when it held.
  static std::string check(const Case& c) {
    fs::create_directories(c.out_dir);
    for (const std::string& o : c.outputs) writeFile(c.out_dir + "/" + o, kSentinel);
    if (!c.fill.empty()) fillDisk(c.fill);
    // The logs live outside the case's folder (which may be on the full disk).
    const std::string log = *dir_ + "/logs/" + replaceAll(c.name, "/", "-");
    const std::string err = log + ".stderr", out = log + ".stdout";
    const auto r = test::runCommand("timeout -k 5 20 " + kBin + " " + c.command + " > " + out + " 2> " + err + " < /dev/null");
    const std::string said = test::readFile(c.verdict_on_stdout ? out : err);
    std::ostringstream bad;
    if (r.status == 124 || r.status == 137) bad << "did not end within 20 s; ";
    else if (r.status != 2) bad << "exit " << r.status << " (expected 2); ";
    const auto lines = std::count(said.begin(), said.end(), '\n');
    if (lines != 1 || said.empty() || said.back() != '\n' || (c.verdict_on_stdout && !test::readFile(err).empty())) bad << lines << " lines on stderr (expected 1); ";
    bool named = false;
    std::stringstream names(c.names);
    for (std::string n; std::getline(names, n, '|');) named = named || said.find(n) != std::string::npos;
    if (!named) bad << "names none of " << c.names << "; ";
    if (said.find("internal error") != std::string::npos) bad << "an internal error; ";
    for (const std::string& o : c.outputs) {
      const std::string now = test::readFile(c.out_dir + "/" + o);
      if (c.append ? now.rfind(kSentinel, 0) != 0 : now != kSentinel) bad << o << " changed; ";
    }
    if (bad.str().empty()) return "";
    return c.name + ": " + bad.str() + "\n  skylane " + c.command + "\n  stderr: " + said.substr(0, 600) + "\n";
  }

  /// Runs the cases two at a time; every failure's text.
  static std::vector<std::string> runAll(const std::vector<Case>& cases) {
    std::vector<std::string> failures;
    std::mutex m;
    std::atomic<std::size_t> next{0};
    auto worker = [&] {
      for (std::size_t i = next++; i < cases.size(); i = next++) {
        std::string f = check(cases[i]);
        if (f.empty()) continue;
        const std::lock_guard<std::mutex> lock(m);
        failures.push_back(std::move(f));
      }
    };
    std::thread a(worker), b(worker);
    a.join();
    b.join();
    return failures;
  }
  static std::string* dir_;
};
std::string* Sweep::dir_ = nullptr;

TEST_F(Sweep, EveryBadInputFileExitsTwoWithOneLineNamingItAndKeepsEarlierOutputs) {
  std::vector<Case> cases;
  for (const Slot& s : slots()) {
    for (Case& c : inputCases(s)) cases.push_back(std::move(c));
  }
  const std::vector<std::string> failures = runAll(cases);
  std::string all;
  for (const std::string& f : failures) all += f;
  EXPECT_TRUE(failures.empty()) << failures.size() << " of " << cases.size() << " cases failed:\n" << all;
  EXPECT_GT(cases.size(), 150u);
}

TEST_F(Sweep, EveryOutputIntoAMissingFolderOrOntoAFullDiskExitsTwoNamingIt) {
  const std::string ex = kExamples, r = report(), fixes = given() + "/fixes.jsonl";
  const std::string almanac = ex + "/predict/alm01jan2020.txt";
  const std::string predict = "integrity predict --almanac " + almanac + " --lat 47 --lon 8 --start 2020-01-01T00:00:00Z --duration 1h";
  const std::string availability = "integrity availability --almanac " + almanac + " --grid-deg 30 --start 2020-01-01T00:00:00Z --duration 10m";
  struct Output {
    std::string name, command, file, option;  ///< command with {OUT}: the folder the output goes in
    bool folder = false;                      ///< {OUT} is the output (made when missing): a path under a file instead
    bool append = false;
  };
  const std::vector<Output> outputs{
      {"predict", predict + " --output {OUT}/p.csv", "p.csv", "--output"},
      {"predict_plot", predict + " --plot {OUT}/p.svg", "p.svg", "--plot"},
      {"availability", availability + " --output {OUT}/a.csv", "a.csv", "--output"},
      {"availability_map", availability + " --map {OUT}/a.svg", "a.svg", "--map"},
      {"spp", "integrity spp --obs " + gnss("30400920.05o") + " --nav " + gnss("30400920.05n") + " --output {OUT}/s.jsonl", "s.jsonl",
       "--output"},
      {"skymask", "skymask --lat 47.3769 --lon 8.5417 --h-ell 500 --ground-amsl 400 --buildings " + ex +
                      "/skymask/buildings.geojson --svg {OUT}/m.svg", "m.svg", "--svg"},
      {"approve", "approve " + ex + "/approve/mission.json --out {OUT}", "report.json", "--out", true},
      {"simulate", "simulate " + ex + "/simulate/gnss_ins_no_fault.json --out {OUT}", "summary.json", "--out", true},
      {"zones_export", "zones export " + ex + "/zones/geo-awareness-che-1.json --to geojson -o {OUT}/z.geojson", "z.geojson", "--output"},
      {"plan_export", "plan export " + r + " -o {OUT}/m.plan", "m.plan", "--out"},
      {"fly", "fly " + r + " --out {OUT}/f.jsonl", "f.jsonl", "--out"},
      {"fly_truth", "fly " + r + " --out /dev/null --truth {OUT}/t.csv", "t.csv", "--truth"},
      {"track_out", "track --approval " + r + " --input " + fixes + " --no-replan --out {OUT}/e.jsonl", "e.jsonl", "--out", false, true},
      {"track_map", "track --approval " + r + " --input " + fixes + " --no-replan --out /dev/null --map {OUT}/t.svg", "t.svg", "--map"},
  };
  writeFile(*dir_ + "/a_file", "a file, not a folder\n");
  std::vector<Case> cases;
  test::SmallDisk disk("sweep-full", "64k");
  for (const Output& o : outputs) {
    Case missing;
    missing.name = o.name + "/missing_folder";
    missing.out_dir = *dir_ + "/outputs/" + o.name;
    const std::string nowhere = o.folder ? *dir_ + "/a_file/sub" : *dir_ + "/no/such/folder";
    missing.command = replaceAll(o.command, "{OUT}", nowhere);
    missing.names = nowhere;
    cases.push_back(missing);
    if (!disk.mounted()) continue;
    Case full;
    full.name = o.name + "/full_disk";
    full.out_dir = disk.path() + "/" + o.name;
    full.command = replaceAll(o.command, "{OUT}", full.out_dir);
    full.names = full.out_dir;
    full.outputs = {o.file};
    full.append = o.append;
    full.fill = disk.path();
    cases.push_back(full);
  }
  // The full-disk cases share one small tmpfs: one at a time, the disk emptied after each.
  std::vector<std::string> failures;
  for (const Case& c : cases) {
    std::string f = check(c);
    if (!f.empty()) failures.push_back(f);
    if (!c.fill.empty()) {
      fs::remove_all(c.out_dir);
      fs::remove(c.fill + "/.filler");
      fs::remove(c.fill + "/.filler2");
    }
  }
  std::string all;
  for (const std::string& f : failures) all += f;
  EXPECT_TRUE(failures.empty()) << failures.size() << " of " << cases.size() << " cases failed:\n" << all;
  if (!disk.mounted()) GTEST_SKIP() << "the full-disk cases need a tmpfs (root); the missing-folder cases ran";
}

}  // namespace
}  // namespace skylane
