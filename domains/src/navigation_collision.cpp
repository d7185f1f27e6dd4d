#include "ontime/domains/navigation_collision.hpp"

#include <fcl/broadphase/broadphase_dynamic_AABB_tree.h>
#include <fcl/broadphase/default_broadphase_callbacks.h>
#include <fcl/geometry/shape/box.h>
#include <fcl/narrowphase/collision_object.h>

#include <vector>

namespace ontime::domains {
namespace {

// Everything is planar: boxes one metre tall, all centred at z = 0, so heights always overlap.
constexpr double kHeight = 1.0;

fcl::Transform3d planar_transform(double x, double y, double angle) {
  fcl::Transform3d transform = fcl::Transform3d::Identity();
  transform.translation() = fcl::Vector3d(x, y, 0.0);
  transform.linear() = fcl::AngleAxisd(angle, fcl::Vector3d::UnitZ()).toRotationMatrix();
  return transform;
}

}  // namespace

struct NavigationCollision::Impl {
  std::vector<std::unique_ptr<fcl::CollisionObjectd>> obstacles;
  fcl::DynamicAABBTreeCollisionManagerd manager;
  std::unique_ptr<fcl::CollisionObjectd> robot;
};

NavigationCollision::NavigationCollision(const NavigationWorld& world, double clearance)
    : impl_(std::make_unique<Impl>()) {
  const auto add = [this](const Rectangle& shape) {
    auto box = std::make_shared<fcl::Boxd>(shape.length, shape.width, kHeight);
    impl_->obstacles.push_back(
        std::make_unique<fcl::CollisionObjectd>(box, planar_transform(shape.x, shape.y, shape.angle)));
    impl_->obstacles.back()->computeAABB();
    impl_->manager.registerObject(impl_->obstacles.back().get());
  };
  for (const Rectangle& wall : world.walls) add(wall);
  for (const Obstacle& obstacle : world.obstacles) add(obstacle.shape);
  impl_->manager.setup();
  auto footprint =
      std::make_shared<fcl::Boxd>(world.robot.length + 2 * clearance, world.robot.width + 2 * clearance, kHeight);
  impl_->robot = std::make_unique<fcl::CollisionObjectd>(footprint, fcl::Transform3d::Identity());
}

NavigationCollision::~NavigationCollision() = default;

bool NavigationCollision::collides(const Pose& pose) const {
  impl_->robot->setTransform(planar_transform(pose.x, pose.y, pose.theta));
  impl_->robot->computeAABB();
  fcl::DefaultCollisionData<double> data;
  impl_->manager.collide(impl_->robot.get(), &data, fcl::DefaultCollisionFunction<double>);
  return data.result.isCollision();
}

}  // namespace ontime::domains
