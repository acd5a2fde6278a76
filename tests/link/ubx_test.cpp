// u-blox UBX (link/ubx/): frames and payloads against gpsd's UBX module (python3-gps), which
// builds the frames (make_pkt, its checksum) from payloads packed field by field as the u-blox
// interface description lays them out, and decodes NAV-PVT frames skylane wrote
// (tests/link/py/ubx_oracle.py); the receiver-PL rule against an independent Q⁻¹; and the fix
// source on a recorded stream.
#include "link/ubx/fix_source.hpp"
#include "link/ubx/ubx.hpp"

#include "tests/test_util.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

namespace skylane::link::ubx {
namespace {

using nlohmann::json;

const std::string kOracle = "/usr/bin/python3 " + std::string(SKYLANE_TEST_DATA) + "/../link/py/ubx_oracle.py";

std::vector<json> oracle(const std::string& args) {
  const test::CommandResult r = test::runCommand(kOracle + " " + args);
  EXPECT_EQ(r.status, 0) << "gpsd's UBX module (python3-gps) failed: " << r.out;
  std::vector<json> out;
  std::istringstream in(r.out);
  for (std::string line; std::getline(in, line);) out.push_back(json::parse(line));
  return out;
}

std::vector<std::uint8_t> fromHex(const std::string& hex) {
  std::vector<std::uint8_t> out;
  for (std::size_t i = 0; i + 1 < hex.size(); i += 2) out.push_back(static_cast<std::uint8_t>(std::stoi(hex.substr(i, 2), nullptr, 16)));
  return out;
}

/// Q⁻¹(p) by bisection on erfc (independent of integrity::normalTailInverse).
double qInverse(double p) {
  double lo = 0.0, hi = 40.0;
  for (int i = 0; i < 200; ++i) {
    const double mid = 0.5 * (lo + hi);
    (0.5 * std::erfc(mid / std::sqrt(2.0)) > p ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

TEST(Ubx, ReadsTheFramesGpsdBuildsFieldByField) {
  const std::vector<json> frames = oracle("encode");
  ASSERT_EQ(frames.size(), 4u);
  FrameParser parser;
  for (const json& f : frames) {
    const auto bytes = fromHex(f.at("hex"));
    parser.push(bytes.data(), bytes.size());
    const auto fr = parser.next();
    ASSERT_TRUE(fr) << f.dump();
    const json& x = f.at("fields");
    if (f.at("kind") == "pvt") {
      const auto v = decodeNavPvt(fr->payload);
      ASSERT_TRUE(v);
      EXPECT_EQ(v->itow_ms, x.at("itow").get<std::uint32_t>());
      EXPECT_EQ(v->year, 2020);
      EXPECT_EQ(v->hour, 14);
      EXPECT_EQ(v->lat_e7, x.at("lat").get<int>());
      EXPECT_EQ(v->lon_e7, x.at("lon").get<int>());
      EXPECT_EQ(v->height_mm, x.at("height").get<int>());
      EXPECT_EQ(v->hmsl_mm, x.at("hmsl").get<int>());
      EXPECT_EQ(v->h_acc_mm, x.at("h_acc").get<std::uint32_t>());
      EXPECT_EQ(v->v_acc_mm, x.at("v_acc").get<std::uint32_t>());
      EXPECT_EQ(v->num_sv, 14);
      EXPECT_EQ(v->fix_type, 3);
    } else {
      const auto v = decodeNavPl(fr->payload);
      ASSERT_TRUE(v);
      EXPECT_EQ(v->itow_ms, x.at("itow").get<std::uint32_t>());
      EXPECT_EQ(v->tmir_coeff, x.at("coeff").get<int>());
      EXPECT_EQ(v->tmir_exp, x.at("exp").get<int>());
      EXPECT_EQ(v->pos_valid, x.at("valid").get<int>());
      EXPECT_EQ(v->pos_frame, x.at("frame").get<int>());
      EXPECT_EQ(v->pl_pos_mm[0], x.at("pl1").get<std::uint32_t>());
      EXPECT_EQ(v->pl_pos_mm[2], x.at("pl3").get<std::uint32_t>());
      EXPECT_EQ(v->pos_invalidity_reason, x.value("reason", 0));
    }
  }
  EXPECT_EQ(parser.stats().frames, 4u);
  EXPECT_EQ(parser.stats().skipped_bytes, 0u);
}

TEST(Ubx, GpsdReadsTheFramesSkylaneWrites) {
  // A NAV-PVT payload laid out by the interface description, framed by skylane.
  std::vector<std::uint8_t> p(92, 0);
  auto put = [&p](std::size_t at, std::int64_t v, int n) {
    for (int k = 0; k < n; ++k) p[at + static_cast<std::size_t>(k)] = static_cast<std::uint8_t>((v >> (8 * k)) & 0xFF);
  };
  put(0, 518418000, 4);
  put(20, 3, 1);
  put(23, 11, 1);
  put(24, 85412345, 4);
  put(28, 473712345, 4);
  put(32, 516000, 4);
  put(36, 468700, 4);
  put(40, 420, 4);
  put(44, 610, 4);
  const std::string file = test::scratchPath("skylane_ubx.hex");
  {
    std::ofstream out(file);
    for (std::uint8_t b : encode(kClassNav, kIdNavPvt, p)) {
      char h[3];
      std::snprintf(h, sizeof h, "%02x", b);
      out << h;
    }
    out << "\n";
  }
  const std::vector<json> read = oracle("decode < " + file);
  ASSERT_EQ(read.size(), 1u);
  EXPECT_EQ(read[0].at("checksum_ok"), true);
  const json& f = read[0].at("fields");
  EXPECT_EQ(f.at("iTOW"), 518418000);
  EXPECT_EQ(f.at("lon"), 85412345);
  EXPECT_EQ(f.at("lat"), 473712345);
  EXPECT_EQ(f.at("height"), 516000);
  EXPECT_EQ(f.at("hMSL"), 468700);
  EXPECT_EQ(f.at("hAcc"), 420);
  EXPECT_EQ(f.at("vAcc"), 610);
  EXPECT_EQ(f.at("numSV"), 11);
}

TEST(UbxReceiverPl, ConvertsTheStatedRiskToTheMissionsAndNeverGoesBelowTheReceiversPl) {
  const planner::NmeaPlRisk risk;  // p_H = 2e-9, p_V = 9.8e-8
  NavPl semi;  // frame 3 (semi-major, semi-minor, vertical), TMIR 1e-5 % = 1e-7 per epoch
  semi.pos_valid = 1;
  semi.pos_frame = 3;
  semi.tmir_coeff = 1;
  semi.tmir_exp = -5;
  semi.pl_pos_mm = {2100, 1400, 3300};
  const ReceiverPl a = receiverProtectionLevels(semi, risk);
  ASSERT_TRUE(a.hpl_vpl_m);
  const double k = qInverse(0.5e-7);
  EXPECT_NEAR(a.hpl_vpl_m->first, std::max(2.1, std::sqrt(-2.0 * std::log(2e-9)) * 2.1 / k), 1e-6);
  EXPECT_NEAR(a.hpl_vpl_m->second, std::max(3.3, qInverse(4.9e-8) * 3.3 / k), 1e-6);
  NavPl ned = semi;  // frame 1 (north, east, down), TMIR 5e-3 % = 5e-5
  ned.pos_frame = 1;
  ned.tmir_coeff = 5;
  ned.tmir_exp = -3;
  ned.pl_pos_mm = {900, 1200, 2500};
  const ReceiverPl b = receiverProtectionLevels(ned, risk);
  ASSERT_TRUE(b.hpl_vpl_m);
  const double k2 = qInverse(2.5e-5);
  EXPECT_NEAR(b.hpl_vpl_m->first, std::sqrt(-2.0 * std::log(2e-9)) * std::hypot(0.9, 1.2) / k2, 1e-6);
  EXPECT_NEAR(b.hpl_vpl_m->second, qInverse(4.9e-8) * 2.5 / k2, 1e-6);
  NavPl loose = semi;  // a TMIR looser than the mission's: the PLs grow
  loose.tmir_coeff = 1;
  loose.tmir_exp = -1;  // 0.1 % = 1e-3
  EXPECT_NEAR(receiverProtectionLevels(loose, risk).hpl_vpl_m->first, std::sqrt(-2.0 * std::log(2e-9)) * 2.1 / qInverse(0.5e-3), 1e-6);
  EXPECT_GT(receiverProtectionLevels(loose, risk).hpl_vpl_m->first, 1.9 * 2.1);
  NavPl invalid = semi;
  invalid.pos_valid = 0;
  invalid.pos_invalidity_reason = 12;
  const ReceiverPl c = receiverProtectionLevels(invalid, risk);
  EXPECT_FALSE(c.hpl_vpl_m);
  EXPECT_NE(c.why_not.find("reason 12"), std::string::npos) << c.why_not;
  NavPl frame0 = semi;
  frame0.pos_frame = 0;
  EXPECT_FALSE(receiverProtectionLevels(frame0, risk).hpl_vpl_m);
}

TEST(UbxFixSource, PairsEachNavPvtWithItsEpochsNavPlAndSaysWhatItCouldNotUse) {
  // GIVEN a recorded stream: PVT + PL of one epoch, PVT + an invalid PL, a PVT alone, garbage
  const std::vector<json> frames = oracle("encode");
  const auto pvt = fromHex(frames[0].at("hex"));
  auto pvtAt = [&](std::uint32_t itow) {
    std::vector<std::uint8_t> payload(pvt.begin() + 6, pvt.end() - 2);
    for (int k = 0; k < 4; ++k) payload[static_cast<std::size_t>(k)] = static_cast<std::uint8_t>((itow >> (8 * k)) & 0xFF);
    payload[10] = static_cast<std::uint8_t>((itow - 518418000) / 1000);  // the second advances with iTOW
    return encode(kClassNav, kIdNavPvt, payload);
  };
  std::vector<std::uint8_t> stream;
  auto add = [&stream](const std::vector<std::uint8_t>& b) { stream.insert(stream.end(), b.begin(), b.end()); };
  add(pvt);
  add(fromHex(frames[1].at("hex")));           // its NAV-PL (frame 3)
  add({0x13, 0x37, 0xB5, 0x00});               // garbage
  add(pvtAt(518420000));
  add(fromHex(frames[3].at("hex")));           // an invalid NAV-PL of that epoch (reason 12)
  add(pvtAt(518421000));                       // no NAV-PL at all
  const std::string file = test::scratchPath("receiver.ubx");
  std::ofstream(file, std::ios::binary).write(reinterpret_cast<const char*>(stream.data()), static_cast<std::streamsize>(stream.size()));
  // WHEN it is read as a fix source
  UbxFixSource source(openByteLink(file), "F1");
  std::vector<planner::SourceRecord> records;
  for (;;) {
    planner::SourceRecord r = source.next(100);
    if (r.kind == planner::SourceRecord::Kind::kEnd) break;
    records.push_back(r);
  }
  // THEN three fixes and one bad record
  std::vector<planner::TrackFix> fixes;
  int bad = 0;
  for (const auto& r : records) {
    if (r.kind == planner::SourceRecord::Kind::kFix) fixes.push_back(r.fix);
    bad += r.kind == planner::SourceRecord::Kind::kBad;
  }
  ASSERT_EQ(fixes.size(), 3u);
  EXPECT_EQ(bad, 1);
  EXPECT_EQ(fixes[0].pl_source, planner::PlSource::kUbxPl);
  EXPECT_NEAR(*fixes[0].hpl_m, std::sqrt(-2.0 * std::log(2e-9)) * 2.1 / qInverse(0.5e-7), 1e-6);
  EXPECT_NEAR(fixes[0].h_ell_m, 515.321, 1e-9);
  const maps::CalendarTime c = maps::utcFromGps(fixes[0].time);
  EXPECT_EQ(c.hour, 14);
  EXPECT_NEAR(c.second, 0.0, 1e-6);
  EXPECT_EQ(fixes[1].pl_source, planner::PlSource::kUbxAccuracy);
  EXPECT_NE(fixes[1].note.find("reason 12"), std::string::npos) << fixes[1].note;
  EXPECT_NEAR(*fixes[1].hpl_m, std::sqrt(-2.0 * std::log(2e-9)) * 0.35, 1e-6);  // hAcc 350 mm
  EXPECT_EQ(fixes[2].pl_source, planner::PlSource::kUbxAccuracy);
  EXPECT_TRUE(fixes[2].note.empty());
  EXPECT_NEAR(fixes[2].time - fixes[0].time, 3.0, 1e-6);
}

}  // namespace
}  // namespace skylane::link::ubx
