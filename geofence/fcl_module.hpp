#pragma once
/// \file
/// \brief The interface between the scene (scene.cpp) and FCL, internal to geofence/.
///
/// FCL is not linked into skylane: libfcl alone brings 29,000 symbol relocations resolved at
/// load (it is linked with BIND_NOW), two thirds of the dynamic loader's work at every start
/// of a command that never checks a fence (`integrity spp`, `--help`). The FCL calls live in
/// libskylane_fcl.so (geofence/fcl_module.cpp), loaded with dlopen (maps/module_loader.hpp)
/// when the first Scene is built. They are the same calls as before: one FCL collision object
/// per piece (a convex prism or a cylinder, placed at its centre), its AABB, and GJK distances
/// from the query volume's cylinder.

#include "airspace/zone_geometry.hpp"

#include <Eigen/Core>

#include <cstddef>
#include <memory>

namespace skylane::geofence::detail {

/// \brief An axis-aligned box as FCL computes it (fcl::AABBd's min_ and max_).
struct FclBox {
  double min[3];
  double max[3];
};

/// \brief The AABB FCL gives an unrotated vertical cylinder (centre p, radius, half height):
/// its local box ±radius, ±half translated by p, the same sums as FCL's, so the same bits as
/// FclPieces::placeCylinder returns — without placing anything.
[[nodiscard]] FclBox cylinderBox(const Eigen::Vector3d& p, double radius_m, double half_m);

/// \brief Which of FCL's GJK solvers (fcl::GJKSolverType).
enum class GjkSolver { kLibccd, kIndep };

/// \brief The scene's pieces as FCL collision objects, and a query cylinder per thread.
class FclPieces {
 public:
  virtual ~FclPieces() = default;
  /// \brief Adds the piece (a convex counter-clockwise ring, or a disk for an empty ring)
  /// between heights z_lo and z_hi as an FCL object; returns its AABB. Pieces are numbered in
  /// the order added.
  virtual FclBox add(const airspace::PlanarPrism& piece, double z_lo, double z_hi) = 0;
  /// \brief Places this thread's query cylinder (centre p, radius, half height) and returns its AABB.
  virtual FclBox placeCylinder(const Eigen::Vector3d& p, double radius_m, double half_m) const = 0;
  /// \brief FCL's distance from this thread's query cylinder to piece i with the given solver
  /// (≤ 0 in contact). FCL's own GJK starts its search along `toward_piece` (a direction from the
  /// volume toward the piece; zero for FCL's default start): where it starts changes how many
  /// iterations it takes, not what it converges to. libccd's takes no start. Throws what FCL
  /// throws.
  [[nodiscard]] virtual double distance(std::size_t i, GjkSolver solver, const Eigen::Vector3d& toward_piece) const = 0;
  /// \brief Asks the processor for what distance(i, …) will read (the object, its shape and its
  /// vertices), so that the scene can ask for several pieces before measuring the first.
  virtual void prefetch(std::size_t i) const = 0;
};

/// \brief The entry points of the FCL module.
struct FclModule {
  std::unique_ptr<FclPieces> (*make)();
};

/// \brief The interface version the module and skylane agree on (in the entry point's name).
inline constexpr int kFclModuleAbi = 3;
/// \brief File name of the module.
inline constexpr const char* kFclModuleFile = "libskylane_fcl.so";

/// \brief The FCL module, loaded on the first call (thread-safe).
/// \throws std::runtime_error naming the places looked at when it is missing.
[[nodiscard]] const FclModule& fclModule();

}  // namespace skylane::geofence::detail
