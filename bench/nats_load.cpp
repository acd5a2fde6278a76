// Load generator for skylane on NATS JetStream (docs/scale.md): starts nats-server (JetStream,
// file store, P partitions) on a free loopback port, approves the example mission through an
// approve worker, starts W track workers, starts N flights on that approval, then publishes one
// fix per flight per second for S seconds, spread evenly over each second. It reads the event
// stream as it goes and reports: fixes/s judged per worker, publish→`fix` event latency
// (p50/p99/max), the consumers' lag (fixes published but not yet delivered), and the workers'
// resident memory per 1,000 flights.
// Usage: skylane_nats_load [--flights 10000] [--seconds 60] [--workers 2] [--partitions 8]
//        [--skylane PATH]

#include "maps/time.hpp"
#include "service/nats_client.hpp"
#include "service/nats_layout.hpp"
#include "tests/service/child_process.hpp"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <atomic>
#include <cstdio>
#include <iostream>
#include <map>
#include <mutex>
#include <regex>
#include <sstream>

#include <unistd.h>

namespace {

using nlohmann::json;
using skylane::service::NatsClient;
using skylane::test::ChildProcess;
using skylane::test::NatsServer;
using Clock = std::chrono::steady_clock;
namespace nats = skylane::service::nats;
namespace fs = std::filesystem;

struct Options {
  int flights = 10000, seconds = 60, workers = 2, partitions = 8;
  bool drain = false;  ///< publish everything first, then start the workers: their throughput alone
  std::string skylane = SKYLANE_BINARY;
};

Options parse(int argc, char** argv) {
  Options o;
  for (int i = 1; i + 1 < argc; i += 2) {
    const std::string k = argv[i], v = argv[i + 1];
    if (k == "--flights") o.flights = std::stoi(v);
    else if (k == "--seconds") o.seconds = std::stoi(v);
    else if (k == "--workers") o.workers = std::stoi(v);
    else if (k == "--partitions") o.partitions = std::stoi(v);
    else if (k == "--skylane") o.skylane = v;
    else if (k == "--drain") o.drain = v == "1";
    else throw std::invalid_argument("unknown option " + k);
  }
  return o;
}

double rssMiB(pid_t pid) {
  std::ifstream in("/proc/" + std::to_string(pid) + "/status");
  for (std::string line; std::getline(in, line);) {
    if (line.rfind("VmRSS:", 0) == 0) return std::stod(line.substr(6)) / 1024.0;
  }
  return 0.0;
}

/// User + system CPU seconds a process has used (/proc/PID/stat fields 14 and 15).
double cpuSeconds(pid_t pid) {
  std::ifstream in("/proc/" + std::to_string(pid) + "/stat");
  std::string stat((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  std::istringstream rest(stat.substr(stat.rfind(')') + 2));
  std::string field;
  double ticks = 0;
  for (int i = 3; i <= 15 && rest >> field; ++i) {
    if (i >= 14) ticks += std::stod(field);
  }
  return ticks / static_cast<double>(sysconf(_SC_CLK_TCK));
}

double percentile(std::vector<double> v, double p) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  return v[std::min(v.size() - 1, static_cast<std::size_t>(p * static_cast<double>(v.size())))];
}

/// The route's fixes, one per second from departure (every flight flies the same approval).
std::vector<std::string> routeFixes(const json& rep, int seconds) {
  std::vector<std::string> out;
  const json& pts = rep.at("route");
  const auto dep = skylane::maps::parseRfc3339(rep.at("departure").get<std::string>());
  for (int k = 0; k < seconds; ++k) {
    std::size_t i = 1;
    while (i + 1 < pts.size() && k > pts[i].at("eta_s").get<double>()) ++i;
    const json &a = pts[i - 1], &b = pts[i];
    const double f = std::clamp((k - a.at("eta_s").get<double>()) / (b.at("eta_s").get<double>() - a.at("eta_s").get<double>()), 0.0, 1.0);
    auto mix = [&](const char* key) { return a.at(key).get<double>() + f * (b.at(key).get<double>() - a.at(key).get<double>()); };
    out.push_back(json{{"time", skylane::maps::formatRfc3339(dep->plus(k))}, {"lat", mix("lat")}, {"lon", mix("lon")},
                       {"h_ell_m", mix("h_ell_m")}, {"hpl_m", 0.5}, {"vpl_m", 0.5}}.dump());
  }
  return out;
}

/// Reads `fix` events and records publish→event latencies (the fix's second k from its time).
struct EventReader {
  std::vector<std::vector<Clock::time_point>>* published = nullptr;  ///< [k][flight]
  std::map<std::string, int> flight_index;
  skylane::maps::GpsTime departure;
  std::vector<double> latency_ms;
  std::atomic<std::size_t> fixes{0};
  std::atomic<bool> stop{false};
  std::mutex mutex;

  void run(const std::string& url) {
    NatsClient c(url, "load-events");
    auto pull = c.pullFrom(nats::kEventStream, "load-reader", "skylane.event.>", c.lastSequence(nats::kEventStream) + 1);
    while (!stop.load()) {
      for (const auto& m : pull->fetch(2000, std::chrono::milliseconds(100))) {
        const auto now = Clock::now();
        if (m.data.find("\"event\":\"fix\"") == std::string::npos) continue;
        const json e = json::parse(m.data);
        const int k = static_cast<int>(std::lround(*skylane::maps::parseRfc3339(e.at("time").get<std::string>()) - departure));
        const int f = flight_index.at(e.at("flight").get<std::string>());
        std::lock_guard lock(mutex);
        latency_ms.push_back(std::chrono::duration<double, std::milli>(now - (*published)[static_cast<std::size_t>(k)][static_cast<std::size_t>(f)]).count());
        ++fixes;
      }
    }
  }
};

/// Approves the example mission as load/a1 with an approve worker; the report.
json approveExample(const Options& o, const NatsServer& server, const fs::path& dir, NatsClient& c) {
  ChildProcess approver({o.skylane, "worker", "--nats", server.url(), "--role", "approve", "--work", (dir / "work").string()},
                        (dir / "approve.log").string());
  const std::string cmd = o.skylane + " nats approve " + std::string(SKYLANE_SOURCE_DIR) + "/examples/approve/mission.json --nats " +
                          server.url() + " --operator load --id a1 --wait 300 > /dev/null";
  if (std::system(cmd.c_str()) != 0) throw std::runtime_error("the example mission was not approved: " + approver.log());
  approver.kill(SIGTERM);
  const auto b = c.get(nats::kApprovalBucket, "load.a1.bundle");
  return json::parse(json::parse(b->value).at("report").get<std::string>());
}

/// The last "N fixes judged" a worker logged.
std::string judgedBy(const ChildProcess& w) {
  const std::string log = w.log();
  const std::regex re("([0-9]+) fixes judged");
  std::string last = "?";
  for (auto it = std::sregex_iterator(log.begin(), log.end(), re); it != std::sregex_iterator(); ++it) last = (*it)[1];
  return last;
}

}  // namespace

int main(int argc, char** argv) try {
  const Options o = parse(argc, argv);
  const fs::path dir = fs::temp_directory_path() / ("skylane-nats-load-" + std::to_string(getpid()));
  NatsServer server(dir / "server", o.partitions);
  if (std::system((o.skylane + " nats setup --nats " + server.url() + " --partitions " + std::to_string(o.partitions) + " > /dev/null").c_str()) != 0) {
    throw std::runtime_error("nats setup failed");
  }
  NatsClient c(server.url(), "load");
  const json rep = approveExample(o, server, dir, c);
  const std::vector<std::string> fixes = routeFixes(rep, o.seconds);
  std::vector<std::unique_ptr<ChildProcess>> workers;
  double idle_rss = 0;
  const auto startWorkers = [&] {
    for (int w = 0; w < o.workers; ++w) {
      workers.push_back(std::make_unique<ChildProcess>(
          std::vector<std::string>{o.skylane, "worker", "--nats", server.url(), "--role", "track", "--name", "tr" + std::to_string(w), "--cache",
                                   (dir / ("cache" + std::to_string(w))).string()},
          (dir / ("track" + std::to_string(w) + ".log")).string()));
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(500));
    for (auto& w : workers) idle_rss += rssMiB(w->pid());
  };
  if (!o.drain) startWorkers();
  std::vector<std::vector<Clock::time_point>> published(static_cast<std::size_t>(o.seconds), std::vector<Clock::time_point>(static_cast<std::size_t>(o.flights)));
  EventReader reader;
  reader.published = &published;
  reader.departure = *skylane::maps::parseRfc3339(rep.at("departure").get<std::string>());
  std::vector<std::string> subjects;
  for (int f = 0; f < o.flights; ++f) {
    const std::string id = "f" + std::to_string(f);
    reader.flight_index[id] = f;
    subjects.push_back(nats::fixSubject("load", id));
    c.publishAsync(subjects.back(), R"({"start":{"approval":"a1"}})");
  }
  c.publishesComplete(std::chrono::seconds(60));
  std::thread events([&] { reader.run(server.url()); });
  struct Join {  // the reader stops and is joined however main ends
    EventReader& r;
    std::thread& t;
    ~Join() {
      r.stop = true;
      if (t.joinable()) t.join();
    }
  } join{reader, events};
  std::cerr << "nats_load: " << o.flights << " flights on " << o.partitions << " partitions, " << o.workers << " track workers, " << o.seconds
            << " s at 1 Hz\n";
  std::uint64_t max_lag = 0;
  const double server_cpu0 = cpuSeconds(server.pid());
  const auto t0 = Clock::now();
  for (int k = 0; k < o.seconds; ++k) {
    for (int f = 0; f < o.flights; ++f) {
      if (f % 100 == 0 && !o.drain) std::this_thread::sleep_until(t0 + std::chrono::duration<double>(k + static_cast<double>(f) / o.flights));
      published[static_cast<std::size_t>(k)][static_cast<std::size_t>(f)] = Clock::now();
      c.publishAsync(subjects[static_cast<std::size_t>(f)], fixes[static_cast<std::size_t>(k)]);
    }
    const auto tc = Clock::now();
    c.publishesComplete(std::chrono::seconds(30));
    if (std::getenv("NATS_LOAD_DEBUG")) std::cerr << "  second " << k << ": acknowledged " << std::chrono::duration<double>(Clock::now() - tc).count() << " s after the last publish\n";
    std::uint64_t lag = 0;
    for (int p = 0; p < o.partitions; ++p) {
      try {
        lag += c.pending(nats::kFixStream, "track-p" + std::to_string(p));
      } catch (const skylane::service::NatsError&) {  // a partition changing hands: its consumer is being made anew
      }
    }
    max_lag = std::max(max_lag, lag);
    if (k % 10 == 9) std::cerr << "  t=" << k + 1 << " s: " << reader.fixes.load() << " fix events, lag " << lag << " fixes\n";
  }
  double publish_s = std::chrono::duration<double>(Clock::now() - t0).count();
  auto t_judge = t0;
  if (o.drain) {  // the workers start on a full stream: the time they take is their throughput
    startWorkers();
    t_judge = Clock::now();
  }
  const std::size_t total = static_cast<std::size_t>(o.flights) * static_cast<std::size_t>(o.seconds);
  for (int i = 0; i < 600 && reader.fixes.load() < total; ++i) std::this_thread::sleep_for(std::chrono::milliseconds(100));
  const double all_s = std::chrono::duration<double>(Clock::now() - t_judge).count();
  double rss = 0, worker_cpu = 0;
  for (auto& w : workers) {
    rss += rssMiB(w->pid());
    worker_cpu += cpuSeconds(w->pid());
  }
  const double server_cpu = cpuSeconds(server.pid()) - server_cpu0;
  std::this_thread::sleep_for(std::chrono::seconds(11));  // the workers' next counters line
  reader.stop = true;
  events.join();
  std::lock_guard lock(reader.mutex);
  std::printf("flights %d, seconds %d, workers %d, partitions %d\n", o.flights, o.seconds, o.workers, o.partitions);
  std::printf("fixes published %zu in %.1f s; fix events %zu (all judged after %.1f s)\n", total, publish_s, reader.fixes.load(), all_s);
  for (std::size_t w = 0; w < workers.size(); ++w) {
    std::printf("worker %zu: %s fixes judged (%.0f fixes/s over the run)\n", w, judgedBy(*workers[w]).c_str(),
                std::atof(judgedBy(*workers[w]).c_str()) / all_s);
  }
  std::printf("publish -> fix event latency: p50 %.1f ms, p99 %.1f ms, max %.1f ms\n", percentile(reader.latency_ms, 0.5),
              percentile(reader.latency_ms, 0.99), percentile(reader.latency_ms, 1.0));
  std::printf("consumer lag (sampled each second): max %llu fixes\n", static_cast<unsigned long long>(max_lag));
  std::printf("CPU per fix: workers %.1f us (all their CPU since start), nats-server %.1f us (during the run)\n",
              worker_cpu / static_cast<double>(total) * 1e6, server_cpu / static_cast<double>(total) * 1e6);
  std::printf("worker memory: %.1f MiB idle, %.1f MiB with the flights: %.1f MiB per 1,000 flights\n", idle_rss, rss,
              (rss - idle_rss) / (o.flights / 1000.0));
  for (auto& w : workers) w->kill(SIGTERM);
  server.kill();
  fs::remove_all(dir);
  return reader.fixes.load() == total ? 0 : 1;
} catch (const std::exception& e) {
  std::cerr << "nats_load: " << e.what() << "\n";
  return 2;
}
