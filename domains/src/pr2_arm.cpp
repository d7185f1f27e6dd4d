#include "ontime/domains/pr2_arm.hpp"

#include <cmath>
#include <kdl/chain.hpp>
#include <kdl/chainfksolverpos_recursive.hpp>
#include <kdl/chainiksolverpos_nr_jl.hpp>
#include <kdl/chainiksolvervel_wdls.hpp>
#include <kdl/frames.hpp>
#include <kdl/jntarray.hpp>
#include <numbers>
#include <stdexcept>

namespace ontime::domains {
namespace {

using std::numbers::pi;
constexpr double kTorsoHeight = 0.790675;  // base_footprint -> torso_lift_link at zero lift
constexpr double kTorsoBack = -0.05;
constexpr double kMaxTorsoLift = 0.33;
constexpr double kUnwrapped = 100.0;  // solver limits of the continuous joints (rad)
constexpr unsigned kIkIterations = 30;

// From each joint to the next one (the last: to the tool frame), along the joint's x axis.
constexpr std::array<double, kArmJointCount> kOffsets{0.1, 0.0, 0.4, 0.0, 0.321, 0.0, 0.18};
constexpr double kShoulderLeft = 0.188;  // torso_lift_link -> shoulder pan joint, along y

const std::array<ArmJointSpec, kArmJointCount> kJoints{{
    {"l_shoulder_pan_joint", 'z', -0.714601836603, 2.2853981634, false, 2.088},
    {"l_shoulder_lift_joint", 'y', -0.5236, 1.3963, false, 2.082},
    {"l_upper_arm_roll_joint", 'x', -0.8, 3.9, false, 3.27},
    {"l_elbow_flex_joint", 'y', -2.3213, 0.0, false, 3.3},
    {"l_forearm_roll_joint", 'x', -pi, pi, true, 3.6},
    {"l_wrist_flex_joint", 'y', -2.18, 0.0, false, 3.078},
    {"l_wrist_roll_joint", 'x', -pi, pi, true, 3.6},
}};

KDL::Joint::JointType joint_type(char axis) {
  switch (axis) {
    case 'x':
      return KDL::Joint::RotX;
    case 'y':
      return KDL::Joint::RotY;
    default:
      return KDL::Joint::RotZ;
  }
}

Transform to_eigen(const KDL::Frame& frame) {
  Transform result = Transform::Identity();
  for (int row = 0; row < 3; ++row) {
    for (int column = 0; column < 3; ++column) result.linear()(row, column) = frame.M(row, column);
    result.translation()(row) = frame.p(row);
  }
  return result;
}

KDL::Frame to_kdl(const Transform& transform) {
  const Eigen::Matrix3d& r = transform.linear();
  const Eigen::Vector3d& p = transform.translation();
  return KDL::Frame(KDL::Rotation(r(0, 0), r(0, 1), r(0, 2), r(1, 0), r(1, 1), r(1, 2), r(2, 0), r(2, 1), r(2, 2)),
                    KDL::Vector(p.x(), p.y(), p.z()));
}

}  // namespace

const std::array<ArmJointSpec, kArmJointCount>& pr2_left_arm_joints() { return kJoints; }

double joint_difference(std::size_t joint, double from, double to) {
  const double difference = to - from;
  return kJoints.at(joint).continuous ? std::remainder(difference, 2 * pi) : difference;
}

double joint_distance(const ArmJoints& a, const ArmJoints& b) {
  double sum = 0;
  for (std::size_t j = 0; j < kArmJointCount; ++j) sum += std::pow(joint_difference(j, a[j], b[j]), 2);
  return std::sqrt(sum);
}

ArmJoints interpolate_joints(const ArmJoints& a, const ArmJoints& b, double t) {
  ArmJoints result{};
  for (std::size_t j = 0; j < kArmJointCount; ++j) {
    result[j] = a[j] + t * joint_difference(j, a[j], b[j]);
    if (kJoints[j].continuous) result[j] = std::remainder(result[j], 2 * pi);
  }
  return result;
}

// KDL's Newton-Raphson position solver with joint limits, on its weighted damped least-squares
// velocity solver (KDL's own SVD). Not KDL's Levenberg-Marquardt solver: that one runs on Eigen's JacobiSVD, whose
// template code Debian's libompl exports too, built against another Eigen; with both libraries
// loaded the solver's calls land in OMPL's copy and its SVD state is corrupted.
struct Pr2Arm::Impl {
  KDL::Chain chain;
  std::unique_ptr<KDL::ChainFkSolverPos_recursive> forward;
  std::unique_ptr<KDL::ChainIkSolverVel_wdls> velocity;
  std::unique_ptr<KDL::ChainIkSolverPos_NR_JL> solver;
};

Pr2Arm::Pr2Arm(double torso_lift) : impl_(std::make_unique<Impl>()) {
  if (!(torso_lift >= 0 && torso_lift <= kMaxTorsoLift)) {
    throw std::invalid_argument("the PR2's torso lift lies within [0, 0.33] m");
  }
  torso_ = Transform::Identity();
  torso_.translation() = Eigen::Vector3d(kTorsoBack, 0, kTorsoHeight + torso_lift);
  impl_->chain.addSegment(KDL::Segment(KDL::Joint(KDL::Joint::None), KDL::Frame(KDL::Vector(0, kShoulderLeft, 0))));
  for (std::size_t j = 0; j < kArmJointCount; ++j) {
    impl_->chain.addSegment(
        KDL::Segment(KDL::Joint(joint_type(kJoints[j].axis)), KDL::Frame(KDL::Vector(kOffsets[j], 0, 0))));
  }
  // Continuous joints get wide limits in the solver (it clamps at its limits) and are wrapped after.
  KDL::JntArray lower(kArmJointCount), upper(kArmJointCount);
  for (std::size_t j = 0; j < kArmJointCount; ++j) {
    lower(static_cast<unsigned>(j)) = kJoints[j].continuous ? -kUnwrapped : kJoints[j].lower;
    upper(static_cast<unsigned>(j)) = kJoints[j].continuous ? kUnwrapped : kJoints[j].upper;
  }
  impl_->forward = std::make_unique<KDL::ChainFkSolverPos_recursive>(impl_->chain);
  impl_->velocity = std::make_unique<KDL::ChainIkSolverVel_wdls>(impl_->chain);
  impl_->solver = std::make_unique<KDL::ChainIkSolverPos_NR_JL>(impl_->chain, lower, upper, *impl_->forward,
                                                                *impl_->velocity, kIkIterations, 1e-6);
}

Pr2Arm::~Pr2Arm() = default;

ArmFrames Pr2Arm::frames(const ArmJoints& joints) const {
  ArmFrames result;
  KDL::Frame along = KDL::Frame::Identity();
  std::size_t j = 0;
  for (unsigned s = 0; s < impl_->chain.getNrOfSegments(); ++s) {
    const KDL::Segment& segment = impl_->chain.getSegment(s);
    if (segment.getJoint().getType() == KDL::Joint::None) {
      along = along * segment.pose(0.0);
      continue;
    }
    result[j] = to_eigen(along * segment.getJoint().pose(joints[j]));
    along = along * segment.pose(joints[j]);
    ++j;
  }
  result[kArmJointCount] = to_eigen(along);
  return result;
}

Transform Pr2Arm::tool(const ArmJoints& joints) const { return frames(joints)[kArmJointCount]; }

// (A member though it reads only the PR2's constants: whether this arm may reach.)
// NOLINTNEXTLINE(readability-convert-member-functions-to-static)
bool Pr2Arm::may_reach(const Transform& target) const noexcept {
  // The wrist (flex and roll joints) lies 0.18 m behind the tool frame, and at most
  // 0.1 + 0.4 + 0.321 m from the shoulder pan joint.
  const Eigen::Vector3d wrist = target * Eigen::Vector3d(-kOffsets[6], 0, 0);
  const double reach = kOffsets[0] + kOffsets[2] + kOffsets[4];
  return (wrist - Eigen::Vector3d(0, kShoulderLeft, 0)).norm() <= reach;
}

bool Pr2Arm::within_limits(const ArmJoints& joints) noexcept {
  for (std::size_t j = 0; j < kArmJointCount; ++j) {
    if (!(joints[j] >= kJoints[j].lower && joints[j] <= kJoints[j].upper)) return false;
  }
  return true;
}

std::optional<ArmJoints> Pr2Arm::inverse(const Transform& target, const ArmJoints& initial) const {
  KDL::JntArray start(kArmJointCount), solution(kArmJointCount);
  for (std::size_t j = 0; j < kArmJointCount; ++j) start(static_cast<unsigned>(j)) = initial[j];
  const int status = impl_->solver->CartToJnt(start, to_kdl(target), solution);
  if (status != KDL::SolverI::E_NOERROR) return std::nullopt;
  ArmJoints joints{};
  for (std::size_t j = 0; j < kArmJointCount; ++j) {
    double value = solution(static_cast<unsigned>(j));
    if (kJoints[j].continuous) value = std::remainder(value, 2 * pi);
    joints[j] = value;
  }
  if (!within_limits(joints)) return std::nullopt;
  const Transform reached = tool(joints);
  const double position_error = (reached.translation() - target.translation()).norm();
  const double orientation_error = Eigen::AngleAxisd(reached.linear().transpose() * target.linear()).angle();
  if (position_error > kPositionTolerance || orientation_error > kOrientationTolerance) return std::nullopt;
  return joints;
}

}  // namespace ontime::domains
