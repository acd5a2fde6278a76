// skylane's ARAIM under its default rule against Stanford's MAAST for ARAIM (J. Blanch, 2024;
// mhss_raim_baseline_v5, the ADD v4.2 PL computation) on random GPS + Galileo geometries.
// tests/data/araim/maast_reference.json holds the inputs (look angles, σ_int, σ_acc, b_nom,
// priors, requirements, fc_thres) and MAAST's outputs, computed under GNU Octave 7.3 with the
// settings listed in the file (no position optimisation, no "fast" bounds, no exposure time,
// no exclusion allocation). MAAST's code is not in this repository.
#include "integrity/araim/mhss.hpp"

#include "tests/test_util.hpp"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace skylane::integrity {
namespace {

using nlohmann::json;

/// MAAST prints its numbers here with 12 significant digits.
constexpr double kPrintedRel = 1e-10;
/// Subset σ's come from different but exact formulas (MAAST: the residual-matrix down-date for
/// ≤ 2 removed satellites, a fresh normal matrix otherwise; skylane: the normal matrix down-date);
/// they agree to round-off, far below this.
constexpr double kNumericAbs_m = 1e-6;
/// P_not_monitored is 1 − Σ priors in both, in double precision: absolute round-off ~1e-16.
constexpr double kPnmAbs = 1e-14;
/// skylane solves the PL to this here, so its own bracket is negligible against MAAST's.
constexpr double kSkylaneTol_m = 1e-5;

struct MaastCase {
  std::string name;
  Geometry geometry;
  ErrorModel model;
  AraimConfig cfg;
  json maast;
};

Constellation constellationNamed(const std::string& s) {
  if (s == "GPS") return Constellation::kGps;
  if (s == "Galileo") return Constellation::kGalileo;
  throw std::logic_error("maast_reference.json: unknown constellation " + s);
}

MaastCase readCase(const json& c) {
  MaastCase mc;
  mc.name = c.at("name").get<std::string>();
  mc.maast = c.at("maast");
  const json& sats = c.at("satellites");
  const int n = static_cast<int>(sats.size());
  Geometry& g = mc.geometry;
  g.clocks = {Constellation::kGps, Constellation::kGalileo};
  g.G = Eigen::MatrixXd::Zero(n, 5);
  g.sigma_int.resize(n);
  g.sigma_acc.resize(n);
  g.bnom.resize(n);
  for (int i = 0; i < n; ++i) {
    const json& s = sats[static_cast<std::size_t>(i)];
    const Constellation con = constellationNamed(s.at("constellation").get<std::string>());
    const double az = maps::deg2rad(s.at("az_deg").get<double>()), el = maps::deg2rad(s.at("el_deg").get<double>());
    g.G.row(i).head<3>() << -std::cos(el) * std::sin(az), -std::cos(el) * std::cos(az), -std::sin(el);
    g.G(i, con == Constellation::kGps ? 3 : 4) = 1.0;
    g.sigma_int[i] = s.at("sigma_int_m").get<double>();
    g.sigma_acc[i] = s.at("sigma_acc_m").get<double>();
    g.bnom[i] = s.at("bnom_m").get<double>();
    g.sats.push_back({con, i + 1});
    g.elevation_rad.push_back(el);
    mc.model.of(con).psat = s.at("p_sat").get<double>();  // one P_sat per constellation in the data
  }
  for (const char* con : {"GPS", "Galileo"}) mc.model.of(constellationNamed(con)).pconst = c.at("p_const").at(con).get<double>();
  const json& q = c.at("requirements");
  Requirements& r = mc.cfg.requirements;
  r.phmi_vert = q.at("phmi_vert").get<double>();
  r.phmi_hor = q.at("phmi_hor").get<double>();
  r.p_thres = q.at("p_thres").get<double>();
  r.pfa_vert = q.at("pfa_vert").get<double>();
  r.pfa_hor = q.at("pfa_hor").get<double>();
  r.p_emt = q.at("p_emt").get<double>();
  r.tol_pl_m = kSkylaneTol_m;
  mc.cfg.fc_thres = c.at("fc_thres").get<double>();
  return mc;
}

struct Reference {
  std::vector<MaastCase> cases;
  double pl_tol_m = 0;
  int max_halvings = 0;
};

const Reference& reference() {
  static const Reference ref = [] {
    Reference r;
    const json doc = json::parse(test::readData("araim/maast_reference.json"));
    r.pl_tol_m = doc.at("maast_settings").at("pl_tol_m").get<double>();
    r.max_halvings = doc.at("maast_settings").at("pl_max_halvings").get<int>();
    for (const json& c : doc.at("cases")) r.cases.push_back(readCase(c));
    return r;
  }();
  return ref;
}

/// Width of MAAST's final bracket on one axis: it halves [low, high] while it is wider than
/// pl_tol, at most `max_halvings` times, and returns the upper end. The root lies in
/// [MAAST − width, MAAST].
double maastFinalWidth(const PlBracket& b, double pl_tol, int max_halvings) {
  double w = b.high_m - b.low_m;
  for (int k = 0; k < max_halvings && w > pl_tol; ++k) w *= 0.5;
  return w;
}

TEST(AraimMaast, TheReferenceHasFiniteAndInfiniteCases) {
  const Reference& ref = reference();
  int finite = 0;
  for (const MaastCase& c : ref.cases) finite += !c.maast.at("vpl_m").is_null();
  EXPECT_GE(ref.cases.size(), 30u);
  EXPECT_GE(finite, 20);
  EXPECT_GE(static_cast<int>(ref.cases.size()) - finite, 5);
}

// GIVEN each reference geometry WHEN skylane runs its default rule
// THEN the same modes are selected (count), the same probability is left unmonitored, σ_acc
// agrees, and the EMT agrees where every selected mode is monitorable (where one is not,
// MAAST's compute_emt pairs the unfiltered priors with the filtered thresholds — not compared).
TEST(AraimMaast, ModesUnmonitoredProbabilitySigmaAccAndEmtMatch) {
  for (const MaastCase& c : reference().cases) {
    const AraimResult r = araimProtectionLevels(c.geometry, c.model, c.cfg);
    ASSERT_TRUE(r.accuracy_computed) << c.name << ": " << r.reason;
    EXPECT_EQ(r.fault_modes + r.unmonitorable_modes, c.maast.at("fault_modes").get<int>()) << c.name;
    EXPECT_NEAR(r.p_not_monitored, c.maast.at("p_not_monitored").get<double>(), kPnmAbs) << c.name;
    const double sacc = c.maast.at("sigma_acc_m").get<double>();
    EXPECT_NEAR(r.sigma_acc_v_m, sacc, sacc * kPrintedRel + kNumericAbs_m * 1e-3) << c.name;
    if (r.unmonitorable_modes == 0) {
      EXPECT_NEAR(r.emt_m, c.maast.at("emt_m").get<double>(), kNumericAbs_m) << c.name;
    }
  }
}

TEST(AraimMaast, PlIsFiniteExactlyWhenMaastsIs) {
  for (const MaastCase& c : reference().cases) {
    const AraimResult r = araimProtectionLevels(c.geometry, c.model, c.cfg);
    EXPECT_EQ(r.pl_computed, !c.maast.at("vpl_m").is_null()) << c.name << ": " << r.reason;
    EXPECT_EQ(r.pl_computed, !c.maast.at("hpl_m").is_null()) << c.name;
  }
}

// Tolerance: MAAST stops its bisection after 10 halvings (or at pl_tol = 0.01 m) and returns
// the upper end, so its PL is the root plus up to its final bracket width W (0.0001 … 0.5 m
// here). skylane solves the same equation to 1e-5 m: its PL must be ≤ MAAST's (+ its own
// tolerance) and ≥ MAAST's − W. For the HPL the per-axis widths combine as √(W_E² + W_N²).
TEST(AraimMaast, ProtectionLevelsLieInMaastsFinalBracket) {
  const Reference& ref = reference();
  int compared = 0;
  double max_gap_v = 0, max_gap_h = 0, max_w = 0;
  for (const MaastCase& c : ref.cases) {
    if (c.maast.at("vpl_m").is_null()) continue;
    const AraimResult r = araimProtectionLevels(c.geometry, c.model, c.cfg);
    ASSERT_TRUE(r.pl_computed) << c.name << ": " << r.reason;
    std::array<double, 3> w{};
    for (int q = 0; q < 3; ++q) {
      w[static_cast<std::size_t>(q)] = maastFinalWidth(r.initial_bracket[static_cast<std::size_t>(q)], ref.pl_tol_m, ref.max_halvings);
    }
    const double maast_v = c.maast.at("vpl_m").get<double>(), maast_h = c.maast.at("hpl_m").get<double>();
    const double slack = kSkylaneTol_m + kNumericAbs_m;
    EXPECT_LE(r.vpl_m, maast_v + slack) << c.name;
    EXPECT_GE(r.vpl_m, maast_v - w[2] - slack) << c.name;
    EXPECT_LE(r.hpl_m, maast_h + slack) << c.name;
    EXPECT_GE(r.hpl_m, maast_h - std::hypot(w[0], w[1]) - slack) << c.name;
    ++compared;
    max_gap_v = std::max(max_gap_v, maast_v - r.vpl_m);
    max_gap_h = std::max(max_gap_h, maast_h - r.hpl_m);
    max_w = std::max({max_w, w[2], std::hypot(w[0], w[1])});
  }
  std::printf("%d finite cases: MAAST − skylane up to %.4f m (VPL), %.4f m (HPL); MAAST's final bracket up to %.4f m\n",
              compared, max_gap_v, max_gap_h, max_w);
}

TEST(AraimMaast, TheDefaultRuleLeavesAtMostPThresUnmonitoredOnEveryReferenceCase) {
  for (const MaastCase& c : reference().cases) {
    std::vector<Constellation> cons;
    std::vector<double> p_sat;
    for (const SatId& s : c.geometry.sats) {
      cons.push_back(s.constellation);
      p_sat.push_back(c.model.of(s.constellation).psat);
    }
    std::vector<double> p_const(kNumConstellations);
    for (Constellation k : kAllConstellations) p_const[static_cast<std::size_t>(k)] = c.model.of(k).pconst;
    FaultModeOptions o;
    o.p_thres = c.cfg.requirements.p_thres;
    o.phmi = c.cfg.requirements.phmi_vert + c.cfg.requirements.phmi_hor;
    o.fc_thres = c.cfg.fc_thres;
    EXPECT_LE(determineFaultModes(cons, p_sat, p_const, o).p_not_monitored, o.p_thres) << c.name;
  }
}

}  // namespace
}  // namespace skylane::integrity
