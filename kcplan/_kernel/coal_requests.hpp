// The coal requests every query of the kernel makes: the GJK settings under which coal's
// error was measured (kcplan/_kernel/__init__.py, COAL_CLEARANCE_RTOL).
#pragma once

#include <coal/collision.h>
#include <coal/collision_data.h>

namespace kcplan {

/// GJK settings of every distance query. coal's relative tolerance 1e-6 (its default,
/// fixed here because the error allowance was measured with it): at 1e-4 coal's distances
/// exceeded python-fcl's by up to 7.6e-3 relative on window_wall, above the allowance;
/// Nesterov acceleration was 6x slower against large boxes.
///
/// Every query starts GJK from the pair's warm start (CachedGuess), set per pair.
inline coal::DistanceRequest distance_request(bool nearest_points) {
  // an overlap only needs to be known (clearance 0), not measured: no EPA
  coal::DistanceRequest request(nearest_points, /*enable_signed_distance=*/false);
  request.gjk_tolerance = 1e-6;
  request.gjk_initial_guess = coal::GJKInitialGuess::CachedGuess;
  return request;
}

/// A yes/no collision request: no contact (so no EPA on an overlap), and GJK may stop as
/// soon as it proves a pair apart (distance > 0) instead of converging on the distance,
/// which coal's default (no bound) does.
///
/// Without EPA, coal 3.0.3 reports an overlap found by GJK ("Collision": GJK's distance
/// below its tolerance, 1e-6) with GJK's last distance, and counts it as a contact only
/// below `collision_distance_threshold` (default 1e-12): where GJK's simplex ends a hair
/// off the origin (exactly aligned shapes; a ball of radius 0.25 at the origin deep in
/// the box of half sides (0.25, 0.25, 0.5) at (0.1, -0.2, 0.05) ends at 4e-12) a deep
/// overlap was reported free. The threshold is therefore GJK's own tolerance: an overlap
/// is always a contact, and so is a pair within 1e-6 (a rejection, never a wrong "free";
/// tests/test_primitive_bound.py keeps the case).
inline coal::CollisionRequest collision_request() {
  coal::CollisionRequest request(coal::NO_REQUEST, 1);
  request.enable_contact = false;
  request.collision_distance_threshold =
      request.gjk_tolerance + Eigen::NumTraits<coal::CoalScalar>::dummy_precision();
  request.distance_upper_bound = 0.0;
  request.gjk_initial_guess = coal::GJKInitialGuess::CachedGuess;
  return request;
}

/// How far apart (length units) a second, cold query must prove two shapes to undo a
/// contact the first reported (confirmed_contact): 100 times GJK's tolerance.
constexpr double kContactBand = 1e-4;

/// Whether a contact that a collision_request() query reported is one.
///
/// With `distance_upper_bound = 0` GJK stops at the first plane that separates the two
/// shapes, and coal 3.0.3 takes that plane's margin for their distance: a plane a hair
/// off the origin (below `collision_distance_threshold`) reads as a contact however far
/// apart the shapes are. Seen with two ellipsoids 5.8 mm apart, warm-started from the
/// pair's last query (a bound of 9.2e-7), and not from coal's default guess (2.8e-3): the
/// answer depended on the queries before it (tests/test_arm_kernel.py). An overlap
/// reports a bound of exactly 0 (20,000 random ellipsoid pairs; meshes against
/// ellipsoids, boxes and balls: 0 or below). So a contact with a positive bound is asked
/// again from coal's default guess (`cold()`, the same request otherwise, whose answer
/// depends on the shapes' poses alone), and undone only where that query finds a plane
/// that separates them by more than kContactBand. Closer than that, coal and python-fcl
/// answer by their tolerances (a ball 1.1e-6 from a box of slanted_gap is a contact for
/// python-fcl and the warm query; undone, it made the twins' counters drift apart in
/// tests/test_kernel.py's study), and the contact stands. A wrong "free" is never made:
/// a contact goes only where a separating plane is found.
template <class Cold>
bool confirmed_contact(const coal::CollisionResult& result, Cold&& cold) {
  if (!result.isCollision()) return false;
  if (!(result.distance_lower_bound > 0.0)) return true;
  const coal::CollisionResult again = cold();
  return again.isCollision() || !(again.distance_lower_bound > kContactBand);
}

/// confirmed_contact()'s second query: collision_request() from coal's default guess, of
/// `shapes` (coal::collide's arguments before the request: two objects, or two geometries
/// each followed by its transform).
template <class... Shapes>
coal::CollisionResult cold_collision(const Shapes&... shapes) {
  coal::CollisionRequest request = collision_request();
  request.gjk_initial_guess = coal::GJKInitialGuess::DefaultGuess;
  coal::CollisionResult result;
  coal::collide(shapes..., request, result);
  return result;
}

}  // namespace kcplan
