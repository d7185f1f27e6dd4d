// The files of a training (ppo_training.hpp): the policy and its learning curve, as one set.

#include <fmt/format.h>

#include "ontime/learn/ppo_training.hpp"

namespace ontime {

std::string learning_curve_csv(const std::vector<LearningCurvePoint>& curve) {
  std::string csv = "epoch,episodes,steps,success_rate,mean_episode_length,actor_steps,seconds\n";
  for (const LearningCurvePoint& point : curve) {
    csv += fmt::format("{},{},{},{},{},{},{:.6f}\n", point.epoch, point.episodes, point.steps, point.success_rate,
                       point.mean_episode_length, point.actor_steps, point.seconds);
  }
  return csv;
}

std::filesystem::path learning_curve_path(const std::filesystem::path& policy, const char* extension) {
  std::filesystem::path path = policy;
  path.replace_extension(extension);
  return path;
}

std::filesystem::path stage_ppo_training(OutputSet& files, const PpoTraining& training,
                                         const std::filesystem::path& policy) {
  files.write(policy, ppo_policy_to_json(training.policy));
  return files.write(learning_curve_path(policy), learning_curve_csv(training.curve));
}

}  // namespace ontime
