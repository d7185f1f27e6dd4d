// Reading and writing trained PPO policies (JSON).

#include <algorithm>
#include <cstdio>
#include <nlohmann/json.hpp>
#include <optional>

#include "allocators/detail/ppo_networks.hpp"
#include "ontime/allocators/ppo.hpp"
#include "ontime/model/instance_io.hpp"
#include "ontime/util/atomic_file.hpp"
#include "ontime/util/error.hpp"
#include "ontime/util/json_input.hpp"

namespace ontime {
namespace {

using Json = nlohmann::ordered_json;
constexpr const char* kFormat = "ontime-ppo-policy";
constexpr int kVersion = 1;

Json network_to_json(const PolicyNetwork& network) {
  Json layers = Json::array();
  for (std::size_t layer = 0; layer < network.weights().size(); ++layer) {
    const PolicyNetwork::Matrix& weight = network.weights()[layer];
    Json rows = Json::array();
    for (Eigen::Index i = 0; i < weight.rows(); ++i) {
      Json row = Json::array();
      for (Eigen::Index j = 0; j < weight.cols(); ++j) row.push_back(weight(i, j));
      rows.push_back(std::move(row));
    }
    Json bias = Json::array();
    for (Eigen::Index i = 0; i < network.biases()[layer].size(); ++i) bias.push_back(network.biases()[layer](i));
    layers.push_back(Json{{"weights", std::move(rows)}, {"biases", std::move(bias)}});
  }
  return Json{{"sizes", network.sizes()}, {"layers", std::move(layers)}};
}

constexpr std::string_view kDigestPrefix = "fnv1a64:";

// FNV-1a, 64 bits. Written here (a few lines) rather than taken from a library: the standard
// library's std::hash may change between builds, and no dependency of the project offers a
// stable hash; the digest only tells instances apart, it is no protection against forgery.
std::uint64_t fnv1a64(std::string_view text) noexcept {
  std::uint64_t hash = 0xcbf29ce484222325ULL;
  for (const char c : text) {
    hash ^= static_cast<unsigned char>(c);
    hash *= 0x100000001b3ULL;
  }
  return hash;
}

bool is_digest(const std::string& text) {
  if (text.size() != kDigestPrefix.size() + 16 || text.compare(0, kDigestPrefix.size(), kDigestPrefix) != 0) {
    return false;
  }
  return std::all_of(text.begin() + static_cast<std::ptrdiff_t>(kDigestPrefix.size()), text.end(),
                     [](char c) { return (c >= '0' && c <= '9') || (c >= 'a' && c <= 'f'); });
}

class PolicyReader {
 public:
  explicit PolicyReader(std::string source) : source_(std::move(source)) {}

  PpoPolicy read(std::string_view text) {
    const Json root = detail::parse_json_strict<Json>(text, source_);
    if (!root.is_object()) fail("top level", "a policy file must be a JSON object");
    if (!root.contains("format") || !root["format"].is_string() || root["format"].get<std::string>() != kFormat) {
      fail("format", std::string("expected \"") + kFormat + "\" (not a policy file of this tool)");
    }
    if (!root.contains("version") || !root["version"].is_number_integer() || root["version"].get<int>() != kVersion) {
      fail("version", "this version of ontime reads policy files of version " + std::to_string(kVersion));
    }
    detail::check_known_keys(root, "",
                             {"format", "version", "acting", "instance", "instance_digest", "skeletons", "chain_inputs",
                              "deadline", "seed", "episodes", "features", "hyperparameters", "actor", "critic"},
                             source_);
    PpoPolicy policy;
    // (Optional: a policy trained acting while planning, SPEC §10; absent means plan-first.)
    if (root.contains("acting")) {
      const std::optional<Acting> acting =
          root["acting"].is_string() ? parse_acting(root["acting"].get<std::string>()) : std::nullopt;
      if (!acting) fail("acting", "must be \"plan-first\" or \"concurrent\"");
      policy.acting = *acting;
    }
    policy.instance = text_at(root, "instance");
    if (root.contains("instance_digest")) {
      policy.instance_digest = text_at(root, "instance_digest");
      if (!is_digest(policy.instance_digest)) {
        fail("instance_digest", "must be \"fnv1a64:\" followed by 16 lower-case hexadecimal digits");
      }
    }
    policy.skeleton_count = static_cast<int>(integer_at(root, "skeletons", 1, Problem::kMaxSkeletons));
    policy.deadline = static_cast<Steps>(integer_at(root, "deadline", 1, Problem::kMaxDeadline));
    // (Optional: a policy of an instance with chains or expiry, SPEC §9; absent means 0.)
    if (root.contains("chain_inputs")) {
      policy.chain_inputs = static_cast<int>(integer_at(root, "chain_inputs", 1, 1 << 20));
    }
    policy.seed = static_cast<std::uint64_t>(integer_at(root, "seed", 0, INT64_MAX));
    policy.episodes = static_cast<std::uint64_t>(integer_at(root, "episodes", 0, INT64_MAX));
    if (!root.contains("hyperparameters") || !root["hyperparameters"].is_object()) {
      fail("hyperparameters", "missing or not an object");
    }
    const Json& hyper = root["hyperparameters"];
    detail::check_known_keys(
        hyper, "hyperparameters",
        {"hidden_layers", "hidden_units", "clip", "gamma", "lambda", "actor_learning_rate", "critic_learning_rate",
         "train_iterations", "steps_per_epoch", "max_episode_steps", "target_kl"},
        source_);
    PpoHyperparameters& h = policy.hyperparameters;
    h.hidden_layers = static_cast<int>(integer_at(hyper, "hidden_layers", 1, 16, "hyperparameters"));
    h.hidden_units = static_cast<int>(integer_at(hyper, "hidden_units", 1, 4096, "hyperparameters"));
    h.clip = number_at(hyper, "clip", "hyperparameters");
    h.gamma = number_at(hyper, "gamma", "hyperparameters");
    h.lambda = number_at(hyper, "lambda", "hyperparameters");
    h.actor_learning_rate = number_at(hyper, "actor_learning_rate", "hyperparameters");
    h.critic_learning_rate = number_at(hyper, "critic_learning_rate", "hyperparameters");
    h.train_iterations = static_cast<int>(integer_at(hyper, "train_iterations", 1, 100000, "hyperparameters"));
    h.steps_per_epoch = static_cast<int>(integer_at(hyper, "steps_per_epoch", 1, 100000000, "hyperparameters"));
    h.max_episode_steps = static_cast<int>(integer_at(hyper, "max_episode_steps", 1, 100000000, "hyperparameters"));
    h.target_kl = number_at(hyper, "target_kl", "hyperparameters");

    const bool concurrent = policy.acting == Acting::concurrent;
    const int inputs = concurrent ? concurrent_feature_count(policy.skeleton_count, policy.chain_inputs)
                                  : feature_count(policy.skeleton_count, policy.chain_inputs);
    const int outputs = concurrent ? concurrent_move_count(policy.skeleton_count) : policy.skeleton_count;
    policy.networks = std::make_shared<const PpoNetworks>(
        PpoNetworks{network_at(root, "actor", inputs, outputs), network_at(root, "critic", inputs, 1)});
    return policy;
  }

 private:
  [[noreturn]] void fail(const std::string& place, const std::string& rule) const {
    throw InputError(source_, place, rule);
  }

  std::string text_at(const Json& object, const char* key) const {
    if (!object.contains(key) || !object[key].is_string()) fail(key, "missing or not a string");
    return object[key].get<std::string>();
  }

  std::int64_t integer_at(const Json& object, const char* key, std::int64_t low, std::int64_t high,
                          const std::string& parent = "") const {
    const std::string path = detail::json_member(parent, key);
    if (!object.contains(key) || !object[key].is_number_integer()) fail(path, "missing or not a whole number");
    const auto value = object[key].get<std::int64_t>();
    if (value < low || value > high) {
      fail(path, "must be between " + std::to_string(low) + " and " + std::to_string(high));
    }
    return value;
  }

  double number_at(const Json& object, const char* key, const std::string& parent) const {
    const std::string path = detail::json_member(parent, key);
    if (!object.contains(key) || !object[key].is_number()) fail(path, "missing or not a number");
    return object[key].get<double>();
  }

  PolicyNetwork network_at(const Json& root, const char* key, int inputs, int outputs) const {
    if (!root.contains(key) || !root[key].is_object()) fail(key, "missing or not an object");
    const Json& network = root[key];
    detail::check_known_keys(network, key, {"sizes", "layers"}, source_);
    const std::string sizes_path = detail::json_member(key, "sizes");
    if (!network.contains("sizes") || !network["sizes"].is_array() || network["sizes"].size() < 2) {
      fail(sizes_path, "must list at least the input and output sizes");
    }
    std::vector<int> sizes;
    for (std::size_t i = 0; i < network["sizes"].size(); ++i) {
      const Json& size = network["sizes"][i];
      if (!size.is_number_integer() || size.get<int>() < 1 || size.get<int>() > 4096) {
        fail(detail::json_index(sizes_path, i), "a layer size must be a whole number between 1 and 4096");
      }
      sizes.push_back(size.get<int>());
    }
    if (sizes.front() != inputs || sizes.back() != outputs) {
      fail(sizes_path, "expected " + std::to_string(inputs) + " inputs and " + std::to_string(outputs) +
                           " outputs for the policy's skeletons, chain inputs and acting mode");
    }
    const std::string layers_path = detail::json_member(key, "layers");
    if (!network.contains("layers") || !network["layers"].is_array() || network["layers"].size() + 1 != sizes.size()) {
      fail(layers_path, "must hold one entry per layer after the input");
    }
    std::vector<PolicyNetwork::Matrix> weights;
    std::vector<PolicyNetwork::Vector> biases;
    for (std::size_t layer = 0; layer + 1 < sizes.size(); ++layer) {
      const std::string layer_path = detail::json_index(layers_path, layer);
      const Json& entry = network["layers"][layer];
      if (!entry.is_object()) fail(layer_path, "must be an object with 'weights' and 'biases'");
      detail::check_known_keys(entry, layer_path, {"weights", "biases"}, source_);
      const auto rows = static_cast<std::size_t>(sizes[layer + 1]);
      const auto columns = static_cast<std::size_t>(sizes[layer]);
      const std::string weights_path = detail::json_member(layer_path, "weights");
      if (!entry.contains("weights") || !entry["weights"].is_array() || entry["weights"].size() != rows) {
        fail(weights_path, "must hold " + std::to_string(rows) + " rows");
      }
      PolicyNetwork::Matrix weight(static_cast<Eigen::Index>(rows), static_cast<Eigen::Index>(columns));
      for (std::size_t i = 0; i < rows; ++i) {
        const Json& row = entry["weights"][i];
        if (!row.is_array() || row.size() != columns) {
          fail(detail::json_index(weights_path, i), "must hold " + std::to_string(columns) + " numbers");
        }
        for (std::size_t j = 0; j < columns; ++j) {
          if (!row[j].is_number()) fail(detail::json_index(detail::json_index(weights_path, i), j), "must be a number");
          weight(static_cast<Eigen::Index>(i), static_cast<Eigen::Index>(j)) = row[j].get<float>();
        }
      }
      const std::string biases_path = detail::json_member(layer_path, "biases");
      if (!entry.contains("biases") || !entry["biases"].is_array() || entry["biases"].size() != rows) {
        fail(biases_path, "must hold " + std::to_string(rows) + " numbers");
      }
      PolicyNetwork::Vector bias(static_cast<Eigen::Index>(rows));
      for (std::size_t i = 0; i < rows; ++i) {
        if (!entry["biases"][i].is_number()) fail(detail::json_index(biases_path, i), "must be a number");
        bias(static_cast<Eigen::Index>(i)) = entry["biases"][i].get<float>();
      }
      weights.push_back(std::move(weight));
      biases.push_back(std::move(bias));
    }
    SplitMix64 unused(0);
    PolicyNetwork result(sizes, unused);
    result.set_parameters(std::move(weights), std::move(biases));
    return result;
  }

  std::string source_;
};

}  // namespace

std::string instance_digest(const Problem& problem) {
  Json content = Json::parse(problem_to_json(problem));
  content.erase("name");
  content.erase("description");
  char hex[17];
  std::snprintf(hex, sizeof hex, "%016llx", static_cast<unsigned long long>(fnv1a64(content.dump())));
  return std::string(kDigestPrefix) + hex;
}

std::string ppo_policy_to_json(const PpoPolicy& policy) {
  const PpoHyperparameters& h = policy.hyperparameters;
  Json root;
  root["format"] = kFormat;
  root["version"] = kVersion;
  if (policy.acting == Acting::concurrent) root["acting"] = acting_name(policy.acting);
  root["instance"] = policy.instance;
  if (!policy.instance_digest.empty()) root["instance_digest"] = policy.instance_digest;
  root["skeletons"] = policy.skeleton_count;
  root["deadline"] = policy.deadline;
  root["seed"] = policy.seed;
  root["episodes"] = policy.episodes;
  if (policy.acting == Acting::concurrent) {
    if (policy.chain_inputs > 0) root["chain_inputs"] = policy.chain_inputs;
    root["features"] =
        "time / D, robot's steps left / D; per skeleton: live, started / length, refined / length, spent / D, "
        "robot's backlog / D, next may start now" +
        std::string(policy.chain_inputs > 0 ? "; per chain: its state one-hot" : "");
  } else if (policy.chain_inputs > 0) {
    root["chain_inputs"] = policy.chain_inputs;
    root["features"] =
        "time / D; per skeleton: refined / length, spent / D, execution / D; per chain: its state one-hot; per timed "
        "slot: execution before the action / D";
  } else {
    root["features"] = "time / D; per skeleton: refined / length, spent / D, execution / D";
  }
  root["hyperparameters"] = {{"hidden_layers", h.hidden_layers},
                             {"hidden_units", h.hidden_units},
                             {"clip", h.clip},
                             {"gamma", h.gamma},
                             {"lambda", h.lambda},
                             {"actor_learning_rate", h.actor_learning_rate},
                             {"critic_learning_rate", h.critic_learning_rate},
                             {"train_iterations", h.train_iterations},
                             {"steps_per_epoch", h.steps_per_epoch},
                             {"max_episode_steps", h.max_episode_steps},
                             {"target_kl", h.target_kl}};
  if (!policy.networks) throw UsageError("a ppo policy without trained networks cannot be written");
  root["actor"] = network_to_json(policy.networks->actor);
  root["critic"] = network_to_json(policy.networks->critic);
  return root.dump(1) + "\n";
}

void save_ppo_policy(const PpoPolicy& policy, const std::filesystem::path& path) {
  write_file_atomically(path, ppo_policy_to_json(policy));
}

PpoPolicy parse_ppo_policy(std::string_view text, std::string_view source) {
  return PolicyReader(std::string(source)).read(text);
}

PpoPolicy load_ppo_policy(const std::filesystem::path& path) {
  return parse_ppo_policy(read_input_file(path, "policy"), path.string());
}

}  // namespace ontime
