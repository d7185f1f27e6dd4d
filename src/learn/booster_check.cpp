#include "learn/booster_check.hpp"

#include <charconv>
#include <cmath>
#include <cstdint>
#include <nlohmann/json.hpp>
#include <utility>
#include <vector>

#include "ontime/util/error.hpp"
#include "ontime/util/json_input.hpp"

namespace ontime::detail {
namespace {

using Json = nlohmann::json;

// A broken rule, thrown from deep in the walk and returned by booster_fault.
struct Fault {
  BoosterFault fault;
};

[[noreturn]] void fail(const std::string& place, const std::string& rule) { throw Fault{{place, rule}}; }

const Json& member(const Json& object, const std::string& path, const std::string& key) {
  if (!object.is_object()) fail(path, "must be an object (got " + describe_json_type(object) + ")");
  const auto found = object.find(key);
  if (found == object.end()) fail(json_member(path, key), "missing");
  return *found;
}

const Json& array_member(const Json& object, const std::string& path, const std::string& key) {
  const Json& value = member(object, path, key);
  if (!value.is_array()) fail(json_member(path, key), "must be an array (got " + describe_json_type(value) + ")");
  return value;
}

// XGBoost writes its counts as text ("num_trees": "10"): a whole number of at most 9 digits.
std::int64_t count_text(const Json& object, const std::string& path, const std::string& key) {
  const Json& value = member(object, path, key);
  const std::string place = json_member(path, key);
  if (!value.is_string()) fail(place, "must be a whole number written as text (got " + quote_json(value) + ")");
  const auto& text = value.get_ref<const std::string&>();
  std::int64_t number = 0;
  const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), number);
  if (text.empty() || text.size() > 9 || text[0] == '-' || error != std::errc() || end != text.data() + text.size()) {
    fail(place, "must be a whole number from 0 to 999999999 written as text (got " + quote_json(value) + ")");
  }
  return number;
}

void expect_count(const Json& object, const std::string& path, const std::string& key, std::int64_t expected,
                  const std::string& why) {
  const std::int64_t got = count_text(object, path, key);
  if (got != expected) {
    fail(json_member(path, key),
         "must be " + std::to_string(expected) + " (" + why + "; got " + std::to_string(got) + ")");
  }
}

std::int64_t whole(const Json& value, const std::string& place) {
  const auto number = json_whole_number(value, -(std::int64_t{1} << 31), (std::int64_t{1} << 31) - 1);
  if (!number) fail(place, "must be a whole number within 32 bits (got " + quote_json(value) + ")");
  return *number;
}

// One of the tree's arrays of one entry per node.
const Json& node_array(const Json& tree, const std::string& path, const std::string& key, std::size_t nodes) {
  const Json& array = array_member(tree, path, key);
  if (array.size() != nodes) {
    fail(json_member(path, key), "must hold one entry per node: " + std::to_string(nodes) +
                                     " (tree_param.num_nodes), " + "not " + std::to_string(array.size()));
  }
  return array;
}

void check_tree(const Json& tree, const std::string& path, std::size_t index, std::size_t features) {
  const Json& id = member(tree, path, "id");
  if (whole(id, json_member(path, "id")) != static_cast<std::int64_t>(index)) {
    fail(json_member(path, "id"),
         "must be the tree's position in trees, " + std::to_string(index) + " (got " + quote_json(id) + ")");
  }
  const std::string param = json_member(path, "tree_param");
  const Json& tree_param = member(tree, path, "tree_param");
  const std::int64_t nodes = count_text(tree_param, param, "num_nodes");
  if (nodes < 1) fail(json_member(param, "num_nodes"), "a tree has at least one node (got 0)");
  // Deleted nodes stay in XGBoost's arrays as holes; a booster OnTime fits has none.
  expect_count(tree_param, param, "num_deleted", 0, "a tree without deleted nodes");
  expect_count(tree_param, param, "num_feature", static_cast<std::int64_t>(features), "the model's feature count");
  expect_count(tree_param, param, "size_leaf_vector", 0, "one value per leaf");

  const auto n = static_cast<std::size_t>(nodes);
  for (const char* key : {"loss_changes", "sum_hessian", "base_weights", "split_conditions"}) {
    const Json& values = node_array(tree, path, key, n);
    for (std::size_t i = 0; i < n; ++i) {
      if (!values[i].is_number() || !std::isfinite(values[i].get<double>())) {
        fail(json_index(json_member(path, key), i), "must be a finite number (got " + quote_json(values[i]) + ")");
      }
    }
  }
  const Json& default_left = node_array(tree, path, "default_left", n);
  const Json& split_type = node_array(tree, path, "split_type", n);
  const Json& split_indices = node_array(tree, path, "split_indices", n);
  const Json& left = node_array(tree, path, "left_children", n);
  const Json& right = node_array(tree, path, "right_children", n);
  const Json& parents = node_array(tree, path, "parents", n);
  for (const char* key : {"categories", "categories_nodes", "categories_segments", "categories_sizes"}) {
    if (!array_member(tree, path, key).empty()) {
      fail(json_member(path, key), "must be empty (OnTime's boosters have no categorical splits)");
    }
  }
  std::vector<std::int64_t> lefts(n), rights(n);
  for (std::size_t i = 0; i < n; ++i) {
    const std::int64_t flag = whole(default_left[i], json_index(json_member(path, "default_left"), i));
    if (flag != 0 && flag != 1) fail(json_index(json_member(path, "default_left"), i), "must be 0 or 1");
    if (whole(split_type[i], json_index(json_member(path, "split_type"), i)) != 0) {
      fail(json_index(json_member(path, "split_type"), i), "must be 0 (a numerical split)");
    }
    const std::int64_t feature = whole(split_indices[i], json_index(json_member(path, "split_indices"), i));
    if (feature < 0 || feature >= static_cast<std::int64_t>(features)) {
      fail(json_index(json_member(path, "split_indices"), i),
           "must be a feature index below " + std::to_string(features) + " (got " + std::to_string(feature) + ")");
    }
    lefts[i] = whole(left[i], json_index(json_member(path, "left_children"), i));
    rights[i] = whole(right[i], json_index(json_member(path, "right_children"), i));
    const bool leaf = lefts[i] == -1 && rights[i] == -1;
    for (const auto& [key, child] : {std::pair{"left_children", lefts[i]}, std::pair{"right_children", rights[i]}}) {
      // The root (node 0) is no node's child.
      if (!leaf && !(child >= 1 && child < nodes)) {
        fail(json_index(json_member(path, key), i), "a child must be a node from 1 to " + std::to_string(nodes - 1) +
                                                        ", or -1 for both children of a leaf" + " (got " +
                                                        std::to_string(child) + ")");
      }
    }
    if (!leaf && lefts[i] == rights[i]) {
      fail(json_index(json_member(path, "right_children"), i), "the two children of a node must differ");
    }
  }
  // XGBoost writes the root's parent as 2^31 - 1 (no node).
  constexpr std::int64_t kNoParent = (std::int64_t{1} << 31) - 1;
  if (whole(parents[0], json_index(json_member(path, "parents"), 0)) != kNoParent) {
    fail(json_index(json_member(path, "parents"), 0), "the root's parent must be " + std::to_string(kNoParent));
  }
  // A tree: every node reached from the root once, through the children (no cycle, no node with
  // two parents, none left out), and each node's parent the node whose child it is.
  std::vector<bool> reached(n, false);
  std::vector<std::size_t> stack{0};
  reached[0] = true;
  while (!stack.empty()) {
    const std::size_t node = stack.back();
    stack.pop_back();
    if (lefts[node] == -1) continue;
    for (const std::int64_t child : {lefts[node], rights[node]}) {
      const auto c = static_cast<std::size_t>(child);
      if (reached[c]) {
        fail(json_index(json_member(path, "left_children"), node),
             "node " + std::to_string(c) + " is reached twice from the root (the children must form a tree)");
      }
      if (whole(parents[c], json_index(json_member(path, "parents"), c)) != static_cast<std::int64_t>(node)) {
        fail(json_index(json_member(path, "parents"), c),
             "must be " + std::to_string(node) + ", the node whose child it is (got " + quote_json(parents[c]) + ")");
      }
      reached[c] = true;
      stack.push_back(c);
    }
  }
  for (std::size_t i = 0; i < n; ++i) {
    if (!reached[i])
      fail(json_index(json_member(path, "parents"), i), "node " + std::to_string(i) + " is not reached from the root");
  }
}

void check_booster(const Json& root, std::size_t features) {
  if (!root.is_object()) fail("top level", "a booster is a JSON object (got " + describe_json_type(root) + ")");
  const Json& version = array_member(root, "", "version");
  if (version.size() != 3) fail("version", "must hold three whole numbers (XGBoost's version)");
  for (std::size_t i = 0; i < 3; ++i) {
    if (whole(version[i], json_index("version", i)) < 0) fail(json_index("version", i), "must be >= 0");
  }
  const Json& learner = member(root, "", "learner");
  if (!learner.is_object()) fail("learner", "must be an object");
  for (const char* key : {"feature_names", "feature_types"}) {
    const Json& names = array_member(learner, "learner", key);
    if (!names.empty() && names.size() != features) {
      fail(json_member("learner", key),
           "must be empty or hold one name per feature (" + std::to_string(features) + ")");
    }
    for (std::size_t i = 0; i < names.size(); ++i) {
      if (!names[i].is_string()) fail(json_index(json_member("learner", key), i), "must be a string");
    }
  }
  const Json& attributes = member(learner, "learner", "attributes");
  if (!attributes.is_object()) fail("learner.attributes", "must be an object");
  for (const auto& [key, value] : attributes.items()) {
    if (!value.is_string()) fail(json_member("learner.attributes", key), "must be a string");
  }
  const Json& objective = member(learner, "learner", "objective");
  if (!member(objective, "learner.objective", "name").is_string()) fail("learner.objective.name", "must be a string");

  const std::string param = "learner.learner_model_param";
  const Json& model_param = member(learner, "learner", "learner_model_param");
  expect_count(model_param, param, "num_feature", static_cast<std::int64_t>(features), "the model's feature count");
  expect_count(model_param, param, "num_class", 0, "a booster of one output");
  if (model_param.contains("num_target")) expect_count(model_param, param, "num_target", 1, "a booster of one output");
  const Json& base_score = member(model_param, param, "base_score");
  double score = 0;
  if (base_score.is_string()) {
    const auto& text = base_score.get_ref<const std::string&>();
    const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), score);
    if (error != std::errc() || end != text.data() + text.size()) score = std::nan("");
  }
  if (!base_score.is_string() || !std::isfinite(score)) {
    fail(json_member(param, "base_score"),
         "must be a finite number written as text (got " + quote_json(base_score) + ")");
  }

  const Json& booster = member(learner, "learner", "gradient_booster");
  const Json& name = member(booster, "learner.gradient_booster", "name");
  if (name != "gbtree") {
    fail("learner.gradient_booster.name", "must be \"gbtree\" (got " + quote_json(name) + ")");
  }
  const std::string path = "learner.gradient_booster.model";
  const Json& model = member(booster, "learner.gradient_booster", "model");
  const Json& trees = array_member(model, path, "trees");
  const std::string tree_param = json_member(path, "gbtree_model_param");
  const Json& gbtree_param = member(model, path, "gbtree_model_param");
  expect_count(gbtree_param, tree_param, "num_trees", static_cast<std::int64_t>(trees.size()), "the trees given");
  expect_count(gbtree_param, tree_param, "num_parallel_tree", 1, "one tree per round");
  if (gbtree_param.contains("size_leaf_vector")) {
    expect_count(gbtree_param, tree_param, "size_leaf_vector", 0, "one value per leaf");
  }
  const Json& tree_info = array_member(model, path, "tree_info");
  if (tree_info.size() != trees.size()) {
    fail(json_member(path, "tree_info"),
         "must hold one entry per tree: " + std::to_string(trees.size()) + ", not " + std::to_string(tree_info.size()));
  }
  for (std::size_t i = 0; i < tree_info.size(); ++i) {
    if (whole(tree_info[i], json_index(json_member(path, "tree_info"), i)) != 0) {
      fail(json_index(json_member(path, "tree_info"), i), "must be 0 (the one output's group)");
    }
  }
  for (std::size_t i = 0; i < trees.size(); ++i) {
    check_tree(trees[i], json_index(json_member(path, "trees"), i), i, features);
  }
}

}  // namespace

std::optional<BoosterFault> booster_fault(std::string_view text, std::size_t features) {
  // XGBoost takes a buffer that does not begin with '{' for its binary format, whose string
  // lengths it trusts (a leading space made it allocate exabytes): the JSON must begin at once.
  if (text.empty() || text.front() != '{') {
    return BoosterFault{"booster", "must begin with '{' (XGBoost reads anything else as its binary format)"};
  }
  try {
    check_booster(parse_json_strict<Json>(text, "booster"), features);
  } catch (const InputError& error) {
    return BoosterFault{error.place(), error.rule()};
  } catch (const Fault& fault) {
    return fault.fault;
  }
  return std::nullopt;
}

}  // namespace ontime::detail
