#include "allocators/detail/neural_network.hpp"

#include <cmath>
#include <stdexcept>
#include <utility>

#include "util/portable_math.hpp"

namespace ontime {
namespace {

// dst = lhs * rhs (dst sized by the caller), every coefficient summed over k in increasing order
// from the k = 0 term: dst(i, j) = ((lhs(i, 0) rhs(0, j) + lhs(i, 1) rhs(1, j)) + ...) + ...
//
// Written here rather than with Eigen's operator*: Eigen's matrix product (GEMM) splits the sum
// over k into blocks whose sizes it derives from the CPU's cache sizes at run time, and sends
// rows to micro-kernels that keep several partial sums, so float sums were grouped differently
// on another CPU and the same seed trained another policy. Here each column of dst is a sum of
// whole columns of lhs, vectorised across rows: every coefficient gets the same additions in the
// same order whatever the caches, the SIMD width or the alignment. Four terms per pass over the
// column (one expression, still added left to right) keep it within a small factor of GEMM.
template <class Lhs, class Rhs, class Dst>
void ordered_product(const Lhs& lhs, const Rhs& rhs, Dst& dst) {
  const Eigen::Index depth = lhs.cols();
  for (Eigen::Index j = 0; j < rhs.cols(); ++j) {
    auto column = dst.col(j);
    column = lhs.col(0) * rhs(0, j);
    Eigen::Index k = 1;
    for (; k + 4 <= depth; k += 4) {
      column = column + lhs.col(k) * rhs(k, j) + lhs.col(k + 1) * rhs(k + 1, j) + lhs.col(k + 2) * rhs(k + 2, j) +
               lhs.col(k + 3) * rhs(k + 3, j);
    }
    for (; k < depth; ++k) column += lhs.col(k) * rhs(k, j);
  }
}

}  // namespace

template <class Scalar>
Mlp<Scalar>::Mlp(std::vector<int> sizes, SplitMix64& generator) : sizes_(std::move(sizes)) {
  if (sizes_.size() < 2) throw std::invalid_argument("a network needs at least an input and an output layer");
  for (const int size : sizes_) {
    if (size < 1) throw std::invalid_argument("layer sizes must be positive");
  }
  for (std::size_t layer = 0; layer + 1 < sizes_.size(); ++layer) {
    const int fan_in = sizes_[layer];
    const int fan_out = sizes_[layer + 1];
    const double bound = 1.0 / std::sqrt(static_cast<double>(fan_in));
    Matrix weight(fan_out, fan_in);
    Vector bias(fan_out);
    for (Eigen::Index j = 0; j < weight.cols(); ++j) {
      for (Eigen::Index i = 0; i < weight.rows(); ++i) {
        weight(i, j) = static_cast<Scalar>((2.0 * uniform01(generator) - 1.0) * bound);
      }
    }
    for (Eigen::Index i = 0; i < bias.size(); ++i)
      bias(i) = static_cast<Scalar>((2.0 * uniform01(generator) - 1.0) * bound);
    weights_.push_back(std::move(weight));
    biases_.push_back(std::move(bias));
  }
  weight_gradients_.resize(weights_.size());
  bias_gradients_.resize(biases_.size());
}

template <class Scalar>
void Mlp<Scalar>::set_parameters(std::vector<Matrix> weights, std::vector<Vector> biases) {
  if (weights.size() + 1 != sizes_.size() || biases.size() + 1 != sizes_.size()) {
    throw std::invalid_argument("parameter count does not match the layers");
  }
  for (std::size_t layer = 0; layer < weights.size(); ++layer) {
    if (weights[layer].rows() != sizes_[layer + 1] || weights[layer].cols() != sizes_[layer] ||
        biases[layer].size() != sizes_[layer + 1]) {
      throw std::invalid_argument("parameter shapes do not match the layers");
    }
  }
  weights_ = std::move(weights);
  biases_ = std::move(biases);
  weight_gradients_.assign(weights_.size(), Matrix());
  bias_gradients_.assign(biases_.size(), Vector());
}

template <class Scalar>
std::size_t Mlp<Scalar>::parameter_count() const noexcept {
  std::size_t count = 0;
  for (std::size_t layer = 0; layer < weights_.size(); ++layer) {
    count += static_cast<std::size_t>(weights_[layer].size() + biases_[layer].size());
  }
  return count;
}

template <class Scalar>
const typename Mlp<Scalar>::Matrix& Mlp<Scalar>::forward(const Matrix& input) {
  activations_.resize(weights_.size() + 1);
  activations_[0] = input;
  for (std::size_t layer = 0; layer < weights_.size(); ++layer) {
    Matrix& out = activations_[layer + 1];
    out.resize(weights_[layer].rows(), activations_[layer].cols());
    ordered_product(weights_[layer], activations_[layer], out);
    out.colwise() += biases_[layer];
    if (layer + 1 < weights_.size()) out = out.array().tanh().matrix();
  }
  return activations_.back();
}

template <class Scalar>
void Mlp<Scalar>::backward(const Matrix& output_gradient) {
  Matrix delta = output_gradient;  // dLoss / d(pre-activation) of the current layer
  for (std::size_t layer = weights_.size(); layer-- > 0;) {
    const Matrix& below = activations_[layer];
    weight_gradients_[layer].resize(delta.rows(), below.rows());
    ordered_product(delta, below.transpose(), weight_gradients_[layer]);
    // The batch's sum in the order of its samples (a product with ones: x * 1 is exact).
    bias_gradients_[layer].resize(delta.rows());
    ordered_product(delta, Vector::Ones(delta.cols()), bias_gradients_[layer]);
    if (layer == 0) break;
    // A transposed copy, so that the product runs over its contiguous columns.
    const Matrix transposed = weights_[layer].transpose();
    Matrix upstream(transposed.rows(), delta.cols());
    ordered_product(transposed, delta, upstream);
    // tanh' = 1 - tanh^2, with tanh the stored activation of the layer below.
    delta = upstream.array() * (Scalar(1) - activations_[layer].array().square());
  }
}

template <class Scalar>
const typename Mlp<Scalar>::Vector& Mlp<Scalar>::evaluate(const Vector& input) const {
  scratch_.resize(weights_.size());
  const Vector* current = &input;
  for (std::size_t layer = 0; layer < weights_.size(); ++layer) {
    Vector& out = scratch_[layer];
    // Eigen's matrix-vector product is kept here (it is faster for one sample): unlike GEMM it
    // blocks by the shapes alone, never by the caches, and sums each row in column order.
    out.noalias() = weights_[layer] * (*current);
    out += biases_[layer];
    if (layer + 1 < weights_.size()) out = out.array().tanh().matrix();
    current = &out;
  }
  return scratch_.back();
}

template <class Scalar>
Adam<Scalar>::Adam(const Mlp<Scalar>& network, double learning_rate, double beta1, double beta2, double epsilon)
    : learning_rate_(learning_rate), beta1_(beta1), beta2_(beta2), epsilon_(epsilon) {
  for (const auto& weight : network.weights()) {
    weight_m_.push_back(Mlp<Scalar>::Matrix::Zero(weight.rows(), weight.cols()));
    weight_v_.push_back(Mlp<Scalar>::Matrix::Zero(weight.rows(), weight.cols()));
  }
  for (const auto& bias : network.biases()) {
    bias_m_.push_back(Mlp<Scalar>::Vector::Zero(bias.size()));
    bias_v_.push_back(Mlp<Scalar>::Vector::Zero(bias.size()));
  }
}

template <class Scalar>
void Adam<Scalar>::step(Mlp<Scalar>& network) {
  ++steps_;
  const auto b1 = static_cast<Scalar>(beta1_);
  const auto b2 = static_cast<Scalar>(beta2_);
  const double correction1 = 1.0 - portable_pow(beta1_, static_cast<double>(steps_));
  const double correction2 = 1.0 - portable_pow(beta2_, static_cast<double>(steps_));
  const auto rate = static_cast<Scalar>(learning_rate_ * std::sqrt(correction2) / correction1);
  const auto epsilon = static_cast<Scalar>(epsilon_ * std::sqrt(correction2));
  const auto update = [&](auto& parameter, const auto& gradient, auto& m, auto& v) {
    m = b1 * m + (Scalar(1) - b1) * gradient;
    v = b2 * v + (Scalar(1) - b2) * gradient.cwiseProduct(gradient);
    // Each square root correctly rounded (sqrtss): Eigen's vectorised float sqrt, under its
    // default EIGEN_FAST_MATH, starts from the rsqrtps approximation, whose bits differ between
    // CPU makers (Intel and AMD), and a policy trained with the same seed would differ with them.
    const auto root = [](Scalar x) { return std::sqrt(x); };
    parameter.array() -= rate * m.array() / (v.array().unaryExpr(root) + epsilon);
  };
  for (std::size_t layer = 0; layer < weight_m_.size(); ++layer) {
    update(network.weights()[layer], network.weight_gradients()[layer], weight_m_[layer], weight_v_[layer]);
    update(network.biases()[layer], network.bias_gradients()[layer], bias_m_[layer], bias_v_[layer]);
  }
}

template class Mlp<float>;
template class Mlp<double>;
template class Adam<float>;
template class Adam<double>;

}  // namespace ontime
