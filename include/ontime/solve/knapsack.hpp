#pragma once
// Theorem 1 of the paper made executable: the reduction from 0/1 knapsack (optimisation
// version) to effort allocation that shows the latter NP-hard.
//
// Item k becomes a skeleton of one action with zero execution time whose planning CDF is 0
// before w_k, eps * v_k from w_k to W, and 1 after W, with deadline D = W and
// eps = 1 / (H^2 M^3), H the largest value and M = K (the number of items, which only makes eps
// smaller than the proof's M = |optimal set|). An optimal allocation then spends w_k on each
// skeleton of a maximum-value knapsack set S and succeeds with probability 1 - prod(1 - eps v_k),
// which the proof bounds by eps (V(S) - 1) < P(S) <= eps V(S).

#include <cstdint>
#include <filesystem>
#include <string_view>
#include <vector>

#include "ontime/model/problem.hpp"

namespace ontime {

struct KnapsackItem {
  std::int64_t weight;
  std::int64_t value;
};

struct Knapsack {
  std::int64_t capacity = 0;
  std::vector<KnapsackItem> items;
};

// Reads {"capacity": W, "items": [{"weight": w, "value": v}, ...]} with positive integers.
// The reduction's limits apply: at most kMaxExactSkeletons items (it is there to be solved
// exactly) and W <= kMaxDeadline.
// Throws InputError naming the file, the JSON path and the rule.
Knapsack load_knapsack(const std::filesystem::path& path);
Knapsack parse_knapsack(std::string_view text, std::string_view source);

// eps = 1 / (H^2 K^3).
double reduction_epsilon(const Knapsack& knapsack);

// The effort-allocation instance of the proof.
Problem reduce_knapsack(const Knapsack& knapsack, std::string name = "knapsack-reduction");

// 1 - prod over the chosen items of (1 - eps v): the success probability of spending w_k on
// each chosen skeleton (chosen[k] != 0).
double schedule_success(const Knapsack& knapsack, const std::vector<std::uint8_t>& chosen);

}  // namespace ontime
