#include "ontime/domains/world_types.hpp"

#include <cmath>
#include <numbers>

namespace ontime::domains {

double drive_seconds(const std::vector<Pose>& poses, double linear_speed, double angular_speed) {
  double length = 0, rotation = 0;
  for (std::size_t i = 1; i < poses.size(); ++i) {
    length += std::hypot(poses[i].x - poses[i - 1].x, poses[i].y - poses[i - 1].y);
    rotation += std::abs(std::remainder(poses[i].theta - poses[i - 1].theta, 2 * std::numbers::pi));
  }
  return length / linear_speed + rotation / angular_speed;
}

std::array<std::array<double, 2>, 4> Rectangle::corners() const {
  const double c = std::cos(angle), s = std::sin(angle);
  std::array<std::array<double, 2>, 4> result{};
  const double signs[4][2] = {{-1, -1}, {1, -1}, {1, 1}, {-1, 1}};
  for (std::size_t i = 0; i < 4; ++i) {
    const double dx = signs[i][0] * length / 2, dy = signs[i][1] * width / 2;
    result[i] = {x + c * dx - s * dy, y + s * dx + c * dy};
  }
  return result;
}

}  // namespace ontime::domains
