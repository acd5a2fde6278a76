// Load generator for `skylane serve`: starts the service on a free loopback port (or uses
// --port), publishes the example zones, approves the example mission, starts N flights, opens one
// event stream per flight, then
//   1. throughput: posts fixes as fast as it can in batches of B per request from two client
//      threads (fixes/s through HTTP);
//   2. live: every flight posts one fix per second for S seconds while `--approvals` approvals run
//      at once; for each fix, the time from the start of its POST to its `fix` event on the
//      flight's stream (p50/p99), and each approval's time from submission to its end.
// Usage: skylane_service_load [--flights 1000] [--batch 100] [--throughput-fixes 200000]
//        [--seconds 20] [--approvals 10] [--skylane PATH]

#include "tests/service/http_client.hpp"

#include <nlohmann/json.hpp>

#include <poll.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/wait.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <mutex>
#include <thread>
#include <vector>

namespace {

using nlohmann::json;
using skylane::test::HttpClient;
using Clock = std::chrono::steady_clock;
namespace fs = std::filesystem;

const std::string kAuthority = "Authorization: Bearer load-authority";
const std::string kOperator = "Authorization: Bearer load-operator";

struct Options {
  int flights = 1000, batch = 100, seconds = 20, approvals = 10;
  long throughput_fixes = 200000;
  std::string skylane = SKYLANE_BINARY;
};

std::string slurp(const std::string& p) {
  std::ifstream in(p);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

std::string sha256(const std::string& s) {
  FILE* p = popen(("printf '%s' '" + s + "' | sha256sum").c_str(), "r");
  char buf[80] = {};
  if (!p || !fgets(buf, sizeof buf, p)) throw std::runtime_error("sha256sum");
  pclose(p);
  return std::string(buf, 64);
}

/// Starts the service; its pid and port.
std::pair<pid_t, int> startService(const Options& o, const fs::path& dir) {
  fs::create_directories(dir / "orbits");
  fs::copy_file(std::string(SKYLANE_SOURCE_DIR) + "/tests/data/gnss/alm01jan2020.txt", dir / "orbits/alm.txt", fs::copy_options::overwrite_existing);
  std::ofstream(dir / "tokens.json") << R"({"tokens": [{"sha256": ")" << sha256("load-authority") << R"(", "role": "authority"}, {"sha256": ")"
                                     << sha256("load-operator") << R"(", "operator": "load"}]})";
  std::vector<std::string> args = {o.skylane, "serve", "--db", (dir / "s.sqlite").string(), "--tokens", (dir / "tokens.json").string(),
                                   "--orbits", (dir / "orbits").string(), "--port", "0", "--web", "none", "--quiet",
                                   "--rate", "1000000", "--burst", "1000000", "--approval-queue", "100"};
  int fds[2];
  if (pipe(fds) != 0) throw std::runtime_error("pipe");
  const pid_t pid = fork();
  if (pid == 0) {
    dup2(fds[1], 1);
    std::vector<char*> argv;
    for (std::string& a : args) argv.push_back(a.data());
    argv.push_back(nullptr);
    execv(argv[0], argv.data());
    _exit(127);
  }
  close(fds[1]);
  std::string line;
  char c;
  while (read(fds[0], &c, 1) == 1 && c != '\n') line += c;
  close(fds[0]);
  return {pid, std::stoi(line.substr(line.rfind(':') + 1))};
}

double percentile(std::vector<double> v, double p) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  return v[std::min(v.size() - 1, static_cast<std::size_t>(p * double(v.size())))];
}

/// The example mission with the zone set; approved; its id.
std::string approveOnce(HttpClient& c, const std::string& zs, Clock::duration* took = nullptr) {
  json m = json::parse(slurp(std::string(SKYLANE_SOURCE_DIR) + "/examples/approve/mission.json"));
  m.erase("zones"), m.erase("buildings"), m.erase("orbits");
  m["zonesets"] = {zs};
  const auto t0 = Clock::now();
  const std::string id = json::parse(c.request("POST", "/v1/approvals", m.dump(), {kOperator, "Content-Type: application/json"}).body).at("id");
  for (;;) {
    const std::string st = json::parse(c.request("GET", "/v1/approvals/" + id, {}, {kOperator}).body).at("status");
    if (st != "queued" && st != "running") break;
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  if (took) *took = Clock::now() - t0;
  return id;
}

/// Fix k seconds after departure on the route `pts` (lat/lon/h linear between points).
std::string fixLine(const json& pts, int k) {
  std::size_t i = 1;
  while (i + 1 < pts.size() && k > pts[i].at("eta_s").get<double>()) ++i;
  const json &a = pts[i - 1], &b = pts[i];
  const double f = std::clamp((k - a["eta_s"].get<double>()) / (b["eta_s"].get<double>() - a["eta_s"].get<double>()), 0.0, 1.0);
  auto mix = [&](const char* key) { return a[key].get<double>() + f * (b[key].get<double>() - a[key].get<double>()); };
  char buf[256];
  std::snprintf(buf, sizeof buf, R"({"time":"2020-01-01T%02d:%02d:%02dZ","lat":%.9f,"lon":%.9f,"h_ell_m":%.3f,"hpl_m":0.5,"vpl_m":0.5})",
                14 + k / 3600, (k / 60) % 60, k % 60, mix("lat"), mix("lon"), mix("h_ell_m"));
  return buf;
}

/// Reads every flight's stream; records the arrival of each fix event by (flight index, second).
class StreamReader {
 public:
  StreamReader(int port, const std::vector<std::string>& flights) : flights_(flights) {
    for (std::size_t i = 0; i < flights.size(); ++i) {
      streams_.push_back(std::make_unique<HttpClient>(port));
      streams_.back()->openStream("/v1/flights/" + flights[i] + "/events", {kOperator});
      index_[flights[i]] = i;
    }
  }
  void run(const std::atomic<bool>& stop) {
    std::vector<std::size_t> seen(streams_.size(), 0);
    while (!stop) {
      for (std::size_t i = 0; i < streams_.size(); ++i) {
        const std::string& s = streams_[i]->readAvailable();
        for (std::size_t at; (at = s.find("event: fix\ndata: ", seen[i])) != std::string::npos;) {
          const std::size_t t = s.find("\"time\":\"2020-01-01T", at);
          const std::size_t end = s.find('\n', at + 17);
          if (t == std::string::npos || end == std::string::npos || t > end) break;
          const int k = (std::stoi(s.substr(t + 19, 2)) - 14) * 3600 + std::stoi(s.substr(t + 22, 2)) * 60 + std::stoi(s.substr(t + 25, 2));
          {
            std::lock_guard lock(mutex);
            arrived[{i, k}] = Clock::now();
          }
          seen[i] = end;
        }
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
    }
  }
  std::mutex mutex;
  std::map<std::pair<std::size_t, int>, Clock::time_point> arrived;

 private:
  std::vector<std::string> flights_;
  std::vector<std::unique_ptr<HttpClient>> streams_;
  std::map<std::string, std::size_t> index_;
};

Options parse(int argc, char** argv) {
  Options o;
  for (int i = 1; i + 1 < argc; i += 2) {
    const std::string k = argv[i], v = argv[i + 1];
    if (k == "--flights") o.flights = std::stoi(v);
    else if (k == "--batch") o.batch = std::stoi(v);
    else if (k == "--seconds") o.seconds = std::stoi(v);
    else if (k == "--approvals") o.approvals = std::stoi(v);
    else if (k == "--throughput-fixes") o.throughput_fixes = std::stol(v);
    else if (k == "--skylane") o.skylane = v;
    else throw std::invalid_argument("unknown option " + k);
  }
  return o;
}

/// Phase 1: batches of `batch` consecutive fixes of one flight per request, two posting threads.
double throughput(int port, const Options& o, const std::vector<std::string>& flights, const json& pts, int& next_k) {
  const int rounds = std::max<int>(1, static_cast<int>(o.throughput_fixes / (long(o.batch) * long(flights.size()))));
  const auto t0 = Clock::now();
  std::atomic<long> posted{0};
  auto work = [&](std::size_t first) {
    HttpClient c(port);
    for (int r = 0; r < rounds; ++r) {
      std::string body;
      for (int b = 0; b < o.batch; ++b) body += fixLine(pts, next_k + r * o.batch + b) + "\n";
      for (std::size_t f = first; f < flights.size(); f += 2) {
        const auto rep = c.request("POST", "/v1/flights/" + flights[f] + "/fixes", body, {kOperator, "Content-Type: application/x-ndjson"});
        if (rep.status != 200) throw std::runtime_error("fixes: " + std::to_string(rep.status) + " " + rep.body);
        posted += o.batch;
      }
    }
  };
  std::thread a(work, 0), b(work, 1);
  a.join(), b.join();
  next_k += rounds * o.batch;
  return double(posted) / std::chrono::duration<double>(Clock::now() - t0).count();
}

}  // namespace

int main(int argc, char** argv) {
  const Options o = parse(argc, argv);
  rlimit r{};
  getrlimit(RLIMIT_NOFILE, &r);
  r.rlim_cur = r.rlim_max;
  setrlimit(RLIMIT_NOFILE, &r);
  const fs::path dir = fs::temp_directory_path() / ("skylane-load-" + std::to_string(getpid()));
  const auto [pid, port] = startService(o, dir);
  HttpClient c(port);
  const std::string zs = json::parse(c.request("POST", "/v1/zonesets?name=zurich", slurp(std::string(SKYLANE_SOURCE_DIR) + "/examples/approve/zones_ed269.json"),
                                               {kAuthority, "Content-Type: application/json"}).body).at("id");
  const std::string ap = approveOnce(c, zs);
  std::vector<std::string> flights;
  for (int i = 0; i < o.flights; ++i) {
    flights.push_back(json::parse(c.request("POST", "/v1/flights", json{{"approval", ap}}.dump(), {kOperator, "Content-Type: application/json"}).body).at("id"));
  }
  const json pts = json::parse(c.request("GET", "/v1/approvals/" + ap + "/report.json", {}, {kOperator}).body).at("route");
  StreamReader reader(port, flights);
  std::atomic<bool> stop{false};
  std::thread reading([&] { reader.run(stop); });
  int k = 0;
  const double fixes_per_s = throughput(port, o, flights, pts, k);
  std::cerr << "throughput: " << fixes_per_s << " fixes/s (batches of " << o.batch << ", " << flights.size() << " flights, "
            << flights.size() << " event streams open)\n";
  // Phase 2: 1 Hz per flight, with approvals running beside.
  std::vector<double> approval_s(static_cast<std::size_t>(o.approvals));
  std::vector<std::thread> approvers;
  for (int i = 0; i < o.approvals; ++i) {
    approvers.emplace_back([&, i] {
      HttpClient a(port);
      Clock::duration took{};
      approveOnce(a, zs, &took);
      approval_s[static_cast<std::size_t>(i)] = std::chrono::duration<double>(took).count();
    });
  }
  std::map<std::pair<std::size_t, int>, Clock::time_point> sent;
  const auto start = Clock::now();
  for (int s = 0; s < o.seconds; ++s, ++k) {
    for (std::size_t f = 0; f < flights.size(); ++f) {
      sent[{f, k}] = Clock::now();
      c.request("POST", "/v1/flights/" + flights[f] + "/fixes", fixLine(pts, k), {kOperator, "Content-Type: application/x-ndjson"});
    }
    std::this_thread::sleep_until(start + std::chrono::seconds(s + 1));
  }
  for (std::thread& t : approvers) t.join();
  std::this_thread::sleep_for(std::chrono::milliseconds(500));
  stop = true;
  reading.join();
  std::vector<double> latency_ms;
  std::size_t missing = 0;
  {
    std::lock_guard lock(reader.mutex);
    for (const auto& [key, t] : sent) {
      const auto it = reader.arrived.find(key);
      if (it == reader.arrived.end()) {
        ++missing;
      } else {
        latency_ms.push_back(std::chrono::duration<double, std::milli>(it->second - t).count());
      }
    }
  }
  std::printf("flights %d, event streams %d, machine %u cores\n", o.flights, o.flights, std::thread::hardware_concurrency());
  std::printf("throughput (HTTP batches of %d): %.0f fixes/s\n", o.batch, fixes_per_s);
  std::printf("live 1 Hz x %d flights for %d s: %zu fixes, post->event p50 %.2f ms, p99 %.2f ms, max %.2f ms, %zu events missing\n",
              o.flights, o.seconds, sent.size(), percentile(latency_ms, 0.5), percentile(latency_ms, 0.99),
              percentile(latency_ms, 1.0), missing);
  std::printf("%d approvals at once: p50 %.2f s, max %.2f s\n", o.approvals, percentile(approval_s, 0.5), percentile(approval_s, 1.0));
  kill(pid, SIGTERM);
  waitpid(pid, nullptr, 0);
  fs::remove_all(dir);
  return missing == 0 ? 0 : 1;
}
