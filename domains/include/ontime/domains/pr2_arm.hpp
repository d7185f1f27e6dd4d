#pragma once
// The left arm of a PR2-like mobile manipulator, modelled as a KDL chain: forward kinematics of
// every link and inverse kinematics of the gripper's tool frame (KDL's Newton–Raphson solver
// with joint limits), with the PR2's joint limits.
//
// Kinematics from the public PR2 figures (the pr2_description URDF), docs/domains.md lists them:
//   base_footprint -> torso_lift_link: (-0.05, 0, 0.790675 + torso lift), lift in [0, 0.33] m
//   torso_lift_link -> shoulder pan joint: (0, 0.188, 0)
//   joint                     axis  limits (rad)         velocity limit (rad/s)  then, to the next joint
//   l_shoulder_pan_joint      z     [-0.7146, 2.2854]    2.088                   (0.1, 0, 0)
//   l_shoulder_lift_joint     y     [-0.5236, 1.3963]    2.082                   0
//   l_upper_arm_roll_joint    x     [-0.8, 3.9]          3.27                    (0.4, 0, 0)  upper arm
//   l_elbow_flex_joint        y     [-2.3213, 0]         3.3                     0
//   l_forearm_roll_joint      x     continuous           3.6                     (0.321, 0, 0)  forearm
//   l_wrist_flex_joint        y     [-2.18, 0]           3.078                   0
//   l_wrist_roll_joint        x     continuous           3.6                     (0.18, 0, 0)  to the tool frame
// The tool frame sits between the fingertips: x points out of the gripper (the approach
// direction), the fingers close along y. Continuous joints are kept within [-pi, pi].
//
// Not thread-safe (the IK solver keeps work buffers): one Pr2Arm per thread or refinement.

#include <Eigen/Geometry>
#include <array>
#include <memory>
#include <optional>
#include <string_view>

namespace ontime::domains {

inline constexpr std::size_t kArmJointCount = 7;
using ArmJoints = std::array<double, kArmJointCount>;
using Transform = Eigen::Isometry3d;

struct ArmJointSpec {
  std::string_view name;
  char axis;  // 'x', 'y' or 'z' of the joint's frame
  double lower, upper;
  bool continuous;  // no mechanical limit; kept within [-pi, pi] here
  double velocity;  // rad/s
};

// The seven joints of the PR2's left arm, in chain order.
const std::array<ArmJointSpec, kArmJointCount>& pr2_left_arm_joints();

// Joint-space geometry with the continuous joints on the circle: the difference `to - from` of
// joint j (for a continuous joint the shortest turn, within [-pi, pi]), the Euclidean distance
// over those differences, and the point a fraction `t` of the way from `a` to `b` (continuous
// joints turning the short way, wrapped into [-pi, pi]).
double joint_difference(std::size_t joint, double from, double to);
double joint_distance(const ArmJoints& a, const ArmJoints& b);
ArmJoints interpolate_joints(const ArmJoints& a, const ArmJoints& b, double t);

// Frames along the chain: the shoulder pan joint, then the frame after each joint (the last is
// the tool frame). Index i + 1 is where link i + 1 starts.
inline constexpr std::size_t kArmFrameCount = kArmJointCount + 1;
using ArmFrames = std::array<Transform, kArmFrameCount>;

class Pr2Arm {
 public:
  // Position tolerance (m) and orientation tolerance (rad) that an IK solution meets.
  static constexpr double kPositionTolerance = 1e-4;
  static constexpr double kOrientationTolerance = 1e-3;

  // `torso_lift` in [0, 0.33] m; throws std::invalid_argument outside.
  explicit Pr2Arm(double torso_lift);
  ~Pr2Arm();
  Pr2Arm(const Pr2Arm&) = delete;
  Pr2Arm& operator=(const Pr2Arm&) = delete;

  // The arm's base (torso_lift_link) in the robot base's frame (base_footprint).
  const Transform& torso() const noexcept { return torso_; }

  // Frame k is the joint frame of joint k after its rotation (k < 7); frame 7 is the tool frame.
  // All in the torso frame.
  ArmFrames frames(const ArmJoints& joints) const;
  Transform tool(const ArmJoints& joints) const;

  // Joints that put the tool frame at `target` (torso frame) within the tolerances above,
  // searched from `initial` (at most 30 Newton-Raphson iterations), or nullopt when the solver
  // does not converge or the solution breaks a joint limit.
  std::optional<ArmJoints> inverse(const Transform& target, const ArmJoints& initial) const;

  // False when no joints can put the tool frame at `target` (torso frame): its wrist point lies
  // farther from the shoulder pan joint than the links reach. A necessary condition only, cheap
  // enough to skip hopeless IK solves.
  bool may_reach(const Transform& target) const noexcept;

  // Whether every joint lies within its limits, bounds included (false for NaN).
  static bool within_limits(const ArmJoints& joints) noexcept;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  Transform torso_;
};

}  // namespace ontime::domains
