#pragma once
// Collision checking of the navigation robot's footprint against walls and furniture, with FCL
// (a dynamic AABB tree over the world's boxes, box-box narrow phase). One checker per thread.

#include <memory>

#include "ontime/domains/navigation_world.hpp"

namespace ontime::domains {

class NavigationCollision {
 public:
  // The footprint is padded by `clearance` on every side (0: the bare footprint).
  NavigationCollision(const NavigationWorld& world, double clearance);
  ~NavigationCollision();
  NavigationCollision(const NavigationCollision&) = delete;
  NavigationCollision& operator=(const NavigationCollision&) = delete;

  // True when the footprint at `pose` overlaps a wall or a piece of furniture.
  bool collides(const Pose& pose) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace ontime::domains
