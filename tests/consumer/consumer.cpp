// A program of another project: ARAIM protection levels of a geometry (integrity), the
// protection volume at the middle of a corridor (geofence), and a preflight approval (planner),
// through the installed skylane package. Prints one JSON object.
#include "geofence/corridor.hpp"
#include "integrity/geometry_file.hpp"
#include "integrity/pl_summary.hpp"
#include "integrity/raim/wls.hpp"
#include "planner/approval.hpp"

#include <cstdio>
#include <exception>

int main(int argc, char** argv) try {
  if (argc != 3) {
    std::fprintf(stderr, "usage: consumer GEOMETRY.json MISSION.json\n");
    return 2;
  }
  using namespace skylane;
  const integrity::GeometryInput in = integrity::loadGeometryFile(argv[1]);
  const integrity::Geometry g = integrity::buildGeometry(in.satellites, in.model, in.tau_vert_m);
  const integrity::PlSummary pl = integrity::protectionLevels(g, integrity::IntegrityMethod::kAraim, in.model, in.raim, in.araim);
  const geofence::Corridor corridor({Eigen::Vector3d(0, 0, 100), Eigen::Vector3d(1000, 0, 100)}, {50.0, 50.0});
  const geofence::Containment c = corridor.contains({Eigen::Vector3d(500, 0, 100), pl.hpl_m, pl.vpl_m});
  planner::Approver approver(planner::loadMission(argv[2]));
  const planner::ApprovalReport report = approver.approve();
  std::printf("{\"hpl_m\": %.6f, \"vpl_m\": %.6f, \"corridor\": \"%s\", \"margin_h_m\": %.6f, \"approved\": %s}\n", pl.hpl_m,
              pl.vpl_m, geofence::verdictName(c.verdict), c.margin_h_m, report.approved ? "true" : "false");
  return 0;
} catch (const std::exception& e) {
  std::fprintf(stderr, "consumer: %s\n", e.what());
  return 1;
}
