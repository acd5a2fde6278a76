// MAVLink decoding speed (link/mavlink/wire.hpp): a telemetry stream as a vehicle sends it —
// per 200 ms a GLOBAL_POSITION_INT and a GPS_RAW_INT with its extensions, a HEARTBEAT per
// second — split into checked frames and the fields a fix needs read out. One core.
// The floor: 1 M messages/s.
#include "link/mavlink/wire.hpp"

#include <benchmark/benchmark.h>

#include <cstdint>
#include <vector>

namespace {

using namespace skylane::link::mavlink;

std::vector<std::uint8_t> telemetryStream(int seconds) {
  std::vector<std::uint8_t> out;
  std::uint8_t seq = 0;
  auto add = [&](const PayloadWriter& w) {
    const std::vector<std::uint8_t> f = encodeFrame(w.def(), w.data(), seq++, 1, 1);
    out.insert(out.end(), f.begin(), f.end());
  };
  for (int k = 0; k < seconds * 5; ++k) {
    if (k % 5 == 0) {
      PayloadWriter hb(*findMessage(kHeartbeat));
      hb.set<std::uint8_t>("type", 2).set<std::uint8_t>("autopilot", 12).set<std::uint8_t>("mavlink_version", 3);
      add(hb);
    }
    PayloadWriter gpi(*findMessage(kGlobalPositionInt));
    gpi.set<std::uint32_t>("time_boot_ms", 200u * static_cast<std::uint32_t>(k)).set<std::int32_t>("lat", 473700000 + k).set<std::int32_t>("lon", 85400000 + k)
        .set<std::int32_t>("alt", 468000).set<std::int32_t>("relative_alt", 60000);
    add(gpi);
    PayloadWriter raw(*findMessage(kGpsRawInt));
    raw.set<std::uint64_t>("time_usec", 1577887200000000ULL + 200000ULL * static_cast<std::uint64_t>(k)).set<std::uint8_t>("fix_type", 3)
        .set<std::int32_t>("lat", 473700000 + k).set<std::int32_t>("lon", 85400000 + k).set<std::int32_t>("alt", 468000)
        .set<std::int32_t>("alt_ellipsoid", 515000).set<std::uint32_t>("h_acc", 150).set<std::uint32_t>("v_acc", 200)
        .set<std::uint8_t>("satellites_visible", 12);
    add(raw);
  }
  return out;
}

void BM_MavlinkDecode(benchmark::State& state) {
  const std::vector<std::uint8_t> stream = telemetryStream(2000);  // 22,000 messages
  const FieldDef& lat = findMessage(kGpsRawInt)->field("lat");
  const FieldDef& h_acc = findMessage(kGpsRawInt)->field("h_acc");
  std::int64_t messages = 0;
  for (auto _ : state) {
    FrameParser parser;
    parser.push(stream.data(), stream.size());
    std::int64_t sum = 0;
    while (const auto fr = parser.next()) {
      if (fr->msgid == kGpsRawInt) sum += fr->get<std::int32_t>(lat) + fr->get<std::uint32_t>(h_acc);
      ++messages;
    }
    benchmark::DoNotOptimize(sum);
  }
  state.SetItemsProcessed(messages);
  state.SetBytesProcessed(static_cast<std::int64_t>(state.iterations()) * static_cast<std::int64_t>(stream.size()));
}
BENCHMARK(BM_MavlinkDecode)->Unit(benchmark::kMillisecond);

}  // namespace
