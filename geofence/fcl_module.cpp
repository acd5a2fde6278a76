/// \file
/// \brief libskylane_fcl.so: the FCL side of geofence/fcl_module.hpp, loaded with dlopen when
/// the first Scene is built (the only file of skylane that includes FCL).

#include "geofence/fcl_module.hpp"

#include <fcl/geometry/shape/convex.h>
#include <fcl/geometry/shape/cylinder.h>
#include <fcl/narrowphase/collision_object.h>
#include <fcl/narrowphase/detail/gjk_solver_indep.h>
#include <fcl/narrowphase/distance.h>

#include <limits>
#include <memory>
#include <vector>

namespace skylane::geofence::detail {
namespace {

/// The piece as an FCL shape placed at its centre: a cylinder for a disk; for a ring, the
/// convex prism with its faces listed FCL's way (count, then vertex indices, outward winding).
std::unique_ptr<fcl::CollisionObjectd> fclObject(const airspace::PlanarPrism& q, double z_lo, double z_hi) {
  const double z_mid = 0.5 * (z_lo + z_hi), half = 0.5 * (z_hi - z_lo);
  if (q.ring.empty()) {
    auto shape = std::make_shared<fcl::Cylinderd>(q.radius_m, 2 * half);
    fcl::Transform3d X_WP = fcl::Transform3d::Identity();
    X_WP.translation() = fcl::Vector3d(q.centre.x(), q.centre.y(), z_mid);
    return std::make_unique<fcl::CollisionObjectd>(shape, X_WP);
  }
  const std::size_t n = q.ring.size();
  Eigen::Vector2d p_WP = Eigen::Vector2d::Zero();
  for (const Eigen::Vector2d& v : q.ring) p_WP += v;
  p_WP /= static_cast<double>(n);
  auto vertices = std::make_shared<std::vector<fcl::Vector3d>>();
  vertices->reserve(2 * n);
  for (double z : {-half, half}) {
    for (const Eigen::Vector2d& v : q.ring) vertices->emplace_back(v.x() - p_WP.x(), v.y() - p_WP.y(), z);
  }
  auto faces = std::make_shared<std::vector<int>>();
  faces->reserve(2 * (n + 1) + 5 * n);
  faces->push_back(static_cast<int>(n));  // bottom, clockwise from above = outward (down)
  for (std::size_t k = n; k-- > 0;) faces->push_back(static_cast<int>(k));
  faces->push_back(static_cast<int>(n));  // top, counter-clockwise from above
  for (std::size_t k = 0; k < n; ++k) faces->push_back(static_cast<int>(n + k));
  for (std::size_t k = 0; k < n; ++k) {  // walls
    const int a = static_cast<int>(k), b = static_cast<int>((k + 1) % n);
    faces->insert(faces->end(), {4, a, b, b + static_cast<int>(n), a + static_cast<int>(n)});
  }
  auto shape = std::make_shared<fcl::Convexd>(vertices, static_cast<int>(n + 2), faces);
  fcl::Transform3d X_WP = fcl::Transform3d::Identity();
  X_WP.translation() = fcl::Vector3d(p_WP.x(), p_WP.y(), z_mid);
  return std::make_unique<fcl::CollisionObjectd>(shape, X_WP);
}

FclBox boxOf(const fcl::CollisionObjectd& o) {
  const fcl::AABBd& b = o.getAABB();
  return {{b.min_[0], b.min_[1], b.min_[2]}, {b.max_[0], b.max_[1], b.max_[2]}};
}

/// This thread's query cylinder (one allocation per thread, not per query).
struct QueryCylinder {
  std::shared_ptr<fcl::Cylinderd> shape = std::make_shared<fcl::Cylinderd>(1.0, 1.0);
  fcl::CollisionObjectd object{shape};
};

QueryCylinder& queryCylinder() {
  thread_local QueryCylinder q;
  return q;
}

class Pieces final : public FclPieces {
 public:
  FclBox add(const airspace::PlanarPrism& piece, double z_lo, double z_hi) override {
    objects_.push_back(fclObject(piece, z_lo, z_hi));
    objects_.back()->computeAABB();
    const fcl::CollisionObjectd& o = *objects_.back();
    Hot h{&o, o.collisionGeometry().get(), dynamic_cast<const fcl::Cylinderd*>(o.collisionGeometry().get()),
          dynamic_cast<const fcl::Convexd*>(o.collisionGeometry().get()), nullptr, 0};
    if (h.convex != nullptr) {
      h.vertices = reinterpret_cast<const char*>(h.convex->getVertices().data());
      h.vertex_bytes = h.convex->getVertices().size() * sizeof(fcl::Vector3d);
    }
    hot_.push_back(h);
    return boxOf(o);
  }
  FclBox placeCylinder(const Eigen::Vector3d& p, double radius_m, double half_m) const override {
    QueryCylinder& q = queryCylinder();
    q.shape->radius = radius_m;
    q.shape->lz = 2 * half_m;
    q.shape->computeLocalAABB();
    q.object.setTranslation(p);
    q.object.computeAABB();
    return boxOf(q.object);
  }
  double distance(std::size_t i, GjkSolver solver, const Eigen::Vector3d& toward_piece) const override {
    if (solver == GjkSolver::kIndep) return startedIndepDistance(hot_[i], toward_piece);
    fcl::DistanceRequestd request;
    request.gjk_solver_type = fcl::GST_LIBCCD;
    fcl::DistanceResultd result;
    fcl::distance(&queryCylinder().object, objects_[i].get(), request, result);
    return result.min_distance;
  }
  void prefetch(std::size_t i) const override {
    const Hot& h = hot_[i];
    for (std::size_t b = 0; b < sizeof(fcl::CollisionObjectd); b += 64) __builtin_prefetch(reinterpret_cast<const char*>(h.object) + b);
    __builtin_prefetch(h.shape);
    for (std::size_t b = 0; b < h.vertex_bytes; b += 64) __builtin_prefetch(h.vertices + b);
  }

 private:
  /// Where distance(i, …) reads: the object, its shape (as a cylinder or as a convex prism, one of
  /// them null) and a convex shape's vertices.
  struct Hot {
    const fcl::CollisionObjectd* object;
    const fcl::CollisionGeometryd* shape;
    const fcl::Cylinderd* cylinder;
    const fcl::Convexd* convex;
    const char* vertices;
    std::size_t vertex_bytes;
  };

  /// FCL's own GJK between the piece and this thread's query cylinder, as fcl::distance runs it
  /// for GST_INDEP (the solver's shapeDistance at the request's default tolerance; −1 in contact
  /// or when it fails), but with its search started toward the query (FCL's cached guess: the
  /// first support direction, here −toward_piece) instead of FCL's fixed +x.
  ///
  /// The piece is the solver's first shape. FCL takes the first shape's support in its own frame
  /// and the second's through the pair's rotation, and (as Debian builds libfcl) the convex
  /// support then multiplies the rotation into the direction again for every vertex: a 64-sided
  /// prism second cost 6.6 µs a distance, first 2.7 µs (libccd 3.7 µs). The distance is the
  /// same either way (GJK on B − A is GJK on A − B mirrored, the start mirrored with it).
  static double startedIndepDistance(const Hot& h, const Eigen::Vector3d& toward_piece) {
    fcl::detail::GJKSolver_indep<double> solver;
    solver.gjk_tolerance = fcl::DistanceRequestd().distance_tolerance;
    if (toward_piece.squaredNorm() > 0.0) {
      solver.enable_cached_guess = true;
      solver.cached_guess = -toward_piece;
    }
    const QueryCylinder& q = queryCylinder();
    double d = std::numeric_limits<double>::max();
    const fcl::Transform3d& X_piece = h.object->getTransform();
    if (h.cylinder != nullptr) {
      solver.shapeDistance(*h.cylinder, X_piece, *q.shape, q.object.getTransform(), &d, nullptr, nullptr);
    } else {
      solver.shapeDistance(*h.convex, X_piece, *q.shape, q.object.getTransform(), &d, nullptr, nullptr);
    }
    return d;
  }
  std::vector<std::unique_ptr<fcl::CollisionObjectd>> objects_;
  std::vector<Hot> hot_;
};

std::unique_ptr<FclPieces> makePieces() { return std::make_unique<Pieces>(); }

}  // namespace
}  // namespace skylane::geofence::detail

/// The module's one exported symbol (its name carries kFclModuleAbi).
extern "C" __attribute__((visibility("default"))) const skylane::geofence::detail::FclModule* skylane_fcl_module_v3() {
  static const skylane::geofence::detail::FclModule module{&skylane::geofence::detail::makePieces};
  return &module;
}
