#pragma once
// A small fully connected network (tanh hidden layers, linear output) with backpropagation and
// the Adam optimiser, on Eigen. Enough for the actor and critic of PPO (paper Appendix B:
// three hidden layers of 64 units).
//
// Written here rather than taken from a deep-learning framework: Debian offers none as a C++
// development package that fits a 4-layer MLP without heavy runtime dependencies, and Eigen
// does the heavy lifting (the matrix products). Samples are columns of a batch matrix.
// Deterministic on every machine: the same seed gives the same weights, and every product sums
// its terms in one fixed order (not Eigen's GEMM, whose blocking follows the CPU's caches: see
// ordered_product in neural_network.cpp), so training is reproducible bit for bit anywhere.

#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "ontime/util/random.hpp"

namespace ontime {

template <class Scalar>
class Mlp {
 public:
  using Matrix = Eigen::Matrix<Scalar, Eigen::Dynamic, Eigen::Dynamic>;
  using Vector = Eigen::Matrix<Scalar, Eigen::Dynamic, 1>;

  Mlp() = default;
  // sizes = {inputs, hidden..., outputs}. Weights and biases drawn uniformly from
  // [-1/sqrt(fan_in), 1/sqrt(fan_in)] with the given generator.
  Mlp(std::vector<int> sizes, SplitMix64& generator);

  const std::vector<int>& sizes() const noexcept { return sizes_; }
  int inputs() const noexcept { return sizes_.front(); }
  int outputs() const noexcept { return sizes_.back(); }

  // Batch forward pass; keeps the activations for `backward`.
  const Matrix& forward(const Matrix& input);
  // Sets the gradients of every parameter from dLoss/dOutput of the last `forward` batch.
  void backward(const Matrix& output_gradient);
  // One sample, without touching the training buffers (no allocation after the first call).
  const Vector& evaluate(const Vector& input) const;

  std::vector<Matrix>& weights() noexcept { return weights_; }
  std::vector<Vector>& biases() noexcept { return biases_; }
  const std::vector<Matrix>& weights() const noexcept { return weights_; }
  const std::vector<Vector>& biases() const noexcept { return biases_; }
  const std::vector<Matrix>& weight_gradients() const noexcept { return weight_gradients_; }
  const std::vector<Vector>& bias_gradients() const noexcept { return bias_gradients_; }
  std::size_t parameter_count() const noexcept;

  // Replaces the parameters (shapes must match `sizes`); for loading saved networks.
  void set_parameters(std::vector<Matrix> weights, std::vector<Vector> biases);

 private:
  std::vector<int> sizes_;
  std::vector<Matrix> weights_;  // weights_[i]: sizes_[i+1] x sizes_[i]
  std::vector<Vector> biases_;
  std::vector<Matrix> weight_gradients_;
  std::vector<Vector> bias_gradients_;
  std::vector<Matrix> activations_;  // activations_[0] = input, then each layer's output
  mutable std::vector<Vector> scratch_;
};

// Adam (Kingma and Ba 2015) over all parameters of one network.
template <class Scalar>
class Adam {
 public:
  Adam() = default;
  Adam(const Mlp<Scalar>& network, double learning_rate, double beta1 = 0.9, double beta2 = 0.999,
       double epsilon = 1e-8);

  // Applies one update from the network's current gradients.
  void step(Mlp<Scalar>& network);

 private:
  double learning_rate_ = 0, beta1_ = 0.9, beta2_ = 0.999, epsilon_ = 1e-8;
  std::int64_t steps_ = 0;
  std::vector<typename Mlp<Scalar>::Matrix> weight_m_, weight_v_;
  std::vector<typename Mlp<Scalar>::Vector> bias_m_, bias_v_;
};

extern template class Mlp<float>;
extern template class Mlp<double>;
extern template class Adam<float>;
extern template class Adam<double>;

}  // namespace ontime
