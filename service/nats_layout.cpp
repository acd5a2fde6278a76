#include "service/nats_layout.hpp"

#include <cstdint>
#include <stdexcept>

namespace skylane::service::nats {

bool validId(std::string_view s) {
  if (s.empty() || s.size() > 64 || s.front() == '_') return false;
  for (char c : s) {
    const bool ok = (c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '-' || c == '_';
    if (!ok) return false;
  }
  return true;
}

std::string fixSubject(const std::string& op, const std::string& flight) { return "skylane.fix." + op + "." + flight; }
std::string partitionFilter(int partition) { return "skylane.fixp." + std::to_string(partition) + ".*.*"; }
std::string eventSubject(const std::string& op, const std::string& flight) { return "skylane.event." + op + "." + flight; }
std::string approvalSubject(const std::string& op, const std::string& id) { return "skylane.approve." + op + "." + id; }

int partitionOf(std::string_view op, std::string_view flight, int partitions) {
  std::uint32_t h = 2166136261u;  // FNV-1a offset basis and prime
  for (std::string_view token : {op, flight}) {
    for (unsigned char c : token) h = (h ^ c) * 16777619u;
  }
  return static_cast<int>(h % static_cast<std::uint32_t>(partitions));
}

std::string serverMappings(int partitions) {
  return "mappings = {\n  \"skylane.fix.*.*\": \"skylane.fixp.{{partition(" + std::to_string(partitions) +
         ",1,2)}}.{{wildcard(1)}}.{{wildcard(2)}}\"\n}\n";
}

void setUp(NatsClient& nats, int partitions) {
  if (partitions < 1 || partitions > 1024) throw std::invalid_argument("--partitions " + std::to_string(partitions) + ": expected 1 to 1024");
  // Duplicate windows of 2 min: a replay after a crash covers seconds (lease, checkpoint period),
  // and the server keeps every id of the window in memory (at 10⁴ events/s, 1.2 M ids).
  nats.ensureStream({kFixStream, {"skylane.fixp.>"}, false, std::chrono::seconds(120), std::chrono::hours(24 * 7), -1});
  nats.ensureStream({kEventStream, {"skylane.event.>"}, false, std::chrono::seconds(120), std::chrono::hours(24 * 7), -1});
  nats.ensureStream({kApprovalStream, {"skylane.approve.>"}, true, std::chrono::seconds(600), std::chrono::seconds(0), -1});
  nats.ensureBucket({kFlightBucket, 1, std::chrono::seconds(0)});
  nats.ensureBucket({kPartitionBucket, 1, std::chrono::seconds(0)});
  nats.ensureBucket({kLeaseBucket, 1, std::chrono::seconds(kLeaseTtl_s)});
  nats.ensureBucket({kApprovalBucket, 1, std::chrono::seconds(0)});
  nats.ensureBucket({kZoneSetBucket, 64, std::chrono::seconds(0)});
  const std::string count = std::to_string(partitions);
  if (!nats.create(kPartitionBucket, "count", count)) {
    const int recorded = partitionCount(nats);
    if (recorded != partitions) {
      throw std::invalid_argument("--partitions " + count + ": this NATS holds skylane's streams for " + std::to_string(recorded) +
                                  " partitions (the server's mapping must match; a new count needs new streams)");
    }
  }
}

int partitionCount(NatsClient& nats) {
  const auto e = nats.get(kPartitionBucket, "count");
  if (!e) throw std::invalid_argument("NATS holds no skylane partition count: run `skylane nats setup --partitions N` first");
  return std::stoi(e->value);
}

std::vector<std::string> subjectTokens(const std::string& subject) {
  std::vector<std::string> out;
  std::size_t i = 0;
  for (std::size_t dot = subject.find('.'); dot != std::string::npos; dot = subject.find('.', i)) {
    out.push_back(subject.substr(i, dot - i));
    i = dot + 1;
  }
  out.push_back(subject.substr(i));
  return out;
}

}  // namespace skylane::service::nats
