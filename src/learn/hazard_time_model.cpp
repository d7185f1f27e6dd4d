#include "ontime/learn/hazard_time_model.hpp"

#include <nlopt.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <numbers>
#include <set>
#include <stdexcept>

#include "learn/conditional_kinds.hpp"
#include "ontime/learn/fitting.hpp"
#include "ontime/util/error.hpp"
#include "util/portable_math.hpp"

namespace ontime {
namespace {

// log(1 + e^x) without overflow.
double softplus(double x) { return std::max(x, 0.0) + portable_log1p(portable_exp(-std::abs(x))); }
// log(e^a + e^b).
double log_add(double a, double b) {
  const double high = std::max(a, b);
  if (high == -std::numeric_limits<double>::infinity()) return high;
  return high + portable_log1p(portable_exp(std::min(a, b) - high));
}
double normal_cdf(double x) { return 0.5 * portable_erfc(-x / std::numbers::sqrt2); }

// The bins of the baseline: `bins` log-spaced ends over 1..horizon, strictly increasing (0: one
// bin per step).
std::vector<int> bin_ends(Steps horizon, int bins) {
  std::vector<int> ends;
  if (bins == 0 || bins >= horizon) {
    for (int t = 1; t <= horizon; ++t) ends.push_back(t);
    return ends;
  }
  for (int j = 1; j <= bins; ++j) {
    const double end = portable_pow(static_cast<double>(horizon), static_cast<double>(j) / bins);
    int value = static_cast<int>(std::lround(end));
    value = std::max(value, ends.empty() ? 1 : ends.back() + 1);
    ends.push_back(std::min(value, static_cast<int>(horizon)));
  }
  ends.back() = static_cast<int>(horizon);
  ends.erase(std::unique(ends.begin(), ends.end()), ends.end());
  return ends;
}

// Rows with the same features (every trial of one action in one world), their counts by step.
struct Group {
  std::vector<double> z;        // standardised features
  std::vector<double> found;    // found[t], t = 1..H (index 0 unused)
  std::vector<double> cut_off;  // cut_off[c], survived c = 0..H steps
};

struct HazardFit {
  std::vector<Group> groups;
  std::vector<int> bin_of;  // bin_of[t], t = 1..H
  std::size_t bins = 0, features = 0;
  Steps horizon = 1;
  double rows = 0, ridge = 0;
  int evaluations = 0;
  double log_likelihood = 0;  // at the last evaluation, per row
};

// Parameters: a (bins), b (features), g0, g (features).
double objective(unsigned n, const double* theta, double* gradient, void* data) {
  auto& p = *static_cast<HazardFit*>(data);
  ++p.evaluations;
  const std::size_t B = p.bins, F = p.features;
  const double* a = theta;
  const double* b = theta + B;
  const double g0 = theta[B + F];
  const double* g = theta + B + F + 1;
  std::vector<double> grad(n, 0.0);
  const auto H = static_cast<std::size_t>(p.horizon);
  std::vector<double> h(H + 1), log_survival(H + 1), d_eta(H + 1), suffix_found(H + 2), suffix_cut(H + 2);
  double total = 0;
  for (const Group& group : p.groups) {
    double linear = 0, kappa = g0;
    for (std::size_t f = 0; f < F; ++f) {
      linear += b[f] * group.z[f];
      kappa += g[f] * group.z[f];
    }
    const double cure = portable_logistic(kappa);
    const double log_cure = -softplus(-kappa), log_not_cure = -softplus(kappa);
    log_survival[0] = 0;
    for (std::size_t t = 1; t <= H; ++t) {
      const double eta = a[p.bin_of[t]] + linear;
      h[t] = portable_logistic(eta);
      log_survival[t] = log_survival[t - 1] - softplus(eta);
    }
    double d_kappa = 0;
    // Found at t: log(1 - cure) + log h(t) + log S(t - 1).
    double found_total = 0;
    for (std::size_t t = 1; t <= H; ++t) {
      if (group.found[t] == 0) continue;
      const double eta = a[p.bin_of[t]] + linear;
      total += group.found[t] * (log_not_cure - softplus(-eta) + log_survival[t - 1]);
      found_total += group.found[t];
    }
    d_kappa -= found_total * cure;
    // Cut off after c: log(cure + (1 - cure) S(c)).
    std::fill(suffix_cut.begin(), suffix_cut.end(), 0.0);
    for (std::size_t c = 0; c <= H; ++c) {
      if (group.cut_off[c] == 0) continue;
      const double log_l = log_add(log_cure, log_not_cure + log_survival[c]);
      total += group.cut_off[c] * log_l;
      // d/dkappa: cure (1 - cure)(1 - S) / L; d/deta_u (u <= c): -(1 - cure) S h(u) / L.
      const double survival = portable_exp(log_survival[c]);
      d_kappa += group.cut_off[c] * portable_exp(log_cure + log_not_cure - log_l) * (1 - survival);
      suffix_cut[c] += group.cut_off[c] * portable_exp(log_not_cure + log_survival[c] - log_l);
    }
    // Suffix sums: found later than u, and cut-off weights at c >= u.
    suffix_found[H + 1] = 0;
    for (std::size_t u = H; u >= 1; --u) suffix_found[u] = suffix_found[u + 1] + (u + 1 <= H ? group.found[u + 1] : 0);
    for (std::size_t u = H; u >= 1; --u) suffix_cut[u - 1] += suffix_cut[u];
    double d_linear = 0;
    for (std::size_t u = 1; u <= H; ++u) {
      d_eta[u] = group.found[u] * (1 - h[u]) - h[u] * suffix_found[u] - h[u] * suffix_cut[u];
      grad[static_cast<std::size_t>(p.bin_of[u])] += d_eta[u];
      d_linear += d_eta[u];
    }
    for (std::size_t f = 0; f < F; ++f) {
      grad[B + f] += d_linear * group.z[f];
      grad[B + F + 1 + f] += d_kappa * group.z[f];
    }
    grad[B + F] += d_kappa;
  }
  p.log_likelihood = total / p.rows;
  double penalty = 0;
  for (std::size_t f = 0; f < F; ++f) penalty += b[f] * b[f] + g[f] * g[f];
  if (gradient != nullptr) {
    for (unsigned i = 0; i < n; ++i) gradient[i] = -grad[i] / p.rows;
    for (std::size_t f = 0; f < F; ++f) {
      gradient[B + f] += p.ridge * b[f];
      gradient[B + F + 1 + f] += p.ridge * g[f];
    }
  }
  return -total / p.rows + p.ridge / 2 * penalty;
}

}  // namespace

const std::string& HazardTimeModel::kind_name() {
  static const std::string name = "hazard";
  return name;
}

HazardTimeModel::HazardTimeModel(std::vector<std::string> feature_names, double step_seconds, Steps horizon,
                                 std::size_t rows, std::size_t worlds, HazardParameters parameters)
    : ConditionalTimeModel(std::move(feature_names), step_seconds, horizon, rows, worlds),
      parameters_(std::move(parameters)) {}

std::unique_ptr<HazardTimeModel> HazardTimeModel::fit(const ConditionalData& data,
                                                      std::vector<std::string> feature_names, Steps horizon,
                                                      double ridge, int bins) {
  const std::size_t F = data.feature_count, N = data.rows();
  HazardParameters out;
  out.ridge = ridge;
  // Standardisation (population moments; a constant feature gets scale 0 and z = 0).
  out.mean.assign(F, 0.0);
  out.scale.assign(F, 0.0);
  for (std::size_t i = 0; i < N; ++i) {
    for (std::size_t f = 0; f < F; ++f) out.mean[f] += data.row(i)[f];
  }
  for (double& m : out.mean) m /= static_cast<double>(N);
  for (std::size_t i = 0; i < N; ++i) {
    for (std::size_t f = 0; f < F; ++f) out.scale[f] += (data.row(i)[f] - out.mean[f]) * (data.row(i)[f] - out.mean[f]);
  }
  for (double& s : out.scale) s = std::sqrt(s / static_cast<double>(N));
  const auto standardised = [&](std::span<const double> x) {
    std::vector<double> z(F, 0.0);
    for (std::size_t f = 0; f < F; ++f) z[f] = out.scale[f] > 0 ? (x[f] - out.mean[f]) / out.scale[f] : 0.0;
    return z;
  };

  // Planning: grouped counts, then L-BFGS.
  HazardFit problem;
  problem.horizon = horizon;
  problem.features = F;
  problem.rows = static_cast<double>(N);
  problem.ridge = ridge;
  out.bin_end = bin_ends(horizon, bins);
  problem.bins = out.bin_end.size();
  problem.bin_of.assign(static_cast<std::size_t>(horizon) + 1, 0);
  for (std::size_t j = 0, t = 1; t <= static_cast<std::size_t>(horizon); ++t) {
    if (static_cast<int>(t) > out.bin_end[j]) ++j;
    problem.bin_of[t] = static_cast<int>(j);
  }
  const auto H = static_cast<std::size_t>(horizon);
  std::map<std::vector<double>, std::size_t> group_of;
  double found_rows = 0, steps_at_risk = 0;
  for (std::size_t i = 0; i < N; ++i) {
    const std::vector<double> x(data.row(i).begin(), data.row(i).end());
    auto [it, added] = group_of.emplace(x, problem.groups.size());
    if (added)
      problem.groups.push_back(
          Group{standardised(x), std::vector<double>(H + 1, 0.0), std::vector<double>(H + 1, 0.0)});
    Group& group = problem.groups[it->second];
    const auto t = static_cast<std::size_t>(data.planning[i]);
    if (data.found[i] != 0 && t <= H) {
      group.found[t] += 1;
      found_rows += 1;
      steps_at_risk += static_cast<double>(t);
    } else {
      group.cut_off[std::min(t, H)] += 1;  // found after the horizon: not found within it
      steps_at_risk += static_cast<double>(std::min(t, H));
    }
  }
  const std::size_t dimension = problem.bins + 2 * F + 1;
  std::vector<double> theta(dimension, 0.0);
  // Start: the pooled hazard per step for every bin, no cure, no feature effects.
  const double start_hazard = std::clamp(found_rows / std::max(steps_at_risk, 1.0), 1e-4, 1 - 1e-4);
  for (std::size_t j = 0; j < problem.bins; ++j) theta[j] = std::log(start_hazard / (1 - start_hazard));
  theta[problem.bins + F] = -3;
  nlopt_opt optimiser = nlopt_create(NLOPT_LD_LBFGS, static_cast<unsigned>(dimension));
  // (Bounds keep a baseline with no finding in its bin, which tends to minus infinity, finite.)
  const std::vector<double> lower(dimension, -30.0), upper(dimension, 30.0);
  nlopt_set_lower_bounds(optimiser, lower.data());
  nlopt_set_upper_bounds(optimiser, upper.data());
  nlopt_set_min_objective(optimiser, objective, &problem);
  nlopt_set_ftol_rel(optimiser, 1e-12);
  nlopt_set_xtol_rel(optimiser, 1e-10);
  nlopt_set_maxeval(optimiser, 5000);
  double minimum = 0;
  const nlopt_result result = nlopt_optimize(optimiser, theta.data(), &minimum);
  nlopt_destroy(optimiser);
  if (result < 0 && result != NLOPT_ROUNDOFF_LIMITED) {
    throw std::runtime_error("the hazard model's optimiser failed (NLopt code " + std::to_string(result) + ")");
  }
  objective(static_cast<unsigned>(dimension), theta.data(), nullptr, &problem);  // the likelihood at the optimum
  out.baseline.assign(theta.begin(), theta.begin() + static_cast<std::ptrdiff_t>(problem.bins));
  out.hazard.assign(theta.begin() + static_cast<std::ptrdiff_t>(problem.bins),
                    theta.begin() + static_cast<std::ptrdiff_t>(problem.bins + F));
  out.cure_intercept = theta[problem.bins + F];
  out.cure.assign(theta.begin() + static_cast<std::ptrdiff_t>(problem.bins + F + 1), theta.end());
  out.iterations = problem.evaluations;
  out.log_likelihood = problem.log_likelihood;

  // Execution: ridge least squares of log(seconds) on [1, z]. The normal equations are summed
  // here in row order (not by Eigen's product, whose blocking follows the CPU's cache sizes);
  // Eigen's LDLT solves the small system.
  const std::size_t P = F + 1;
  Eigen::MatrixXd gram = Eigen::MatrixXd::Zero(static_cast<Eigen::Index>(P), static_cast<Eigen::Index>(P));
  Eigen::VectorXd moment = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(P));
  std::vector<double> row(P);
  double count = 0;
  std::vector<std::pair<std::vector<double>, double>> observations;
  for (std::size_t i = 0; i < N; ++i) {
    if (data.found[i] == 0) continue;
    const std::vector<double> z = standardised(data.row(i));
    row[0] = 1;
    std::copy(z.begin(), z.end(), row.begin() + 1);
    const double y = portable_log(std::max(data.execution_seconds[i], 1e-6 * data.step_seconds));
    for (std::size_t r = 0; r < P; ++r) {
      for (std::size_t c = 0; c < P; ++c)
        gram(static_cast<Eigen::Index>(r), static_cast<Eigen::Index>(c)) += row[r] * row[c];
      moment(static_cast<Eigen::Index>(r)) += row[r] * y;
    }
    observations.emplace_back(row, y);
    count += 1;
  }
  out.execution.assign(F, 0.0);
  out.execution_sigma = 1;
  if (count > 0) {
    for (std::size_t f = 1; f < P; ++f)
      gram(static_cast<Eigen::Index>(f), static_cast<Eigen::Index>(f)) += ridge * count;
    gram(0, 0) += 1e-12;  // a single row of constants stays solvable
    const Eigen::VectorXd c = gram.ldlt().solve(moment);
    out.execution_intercept = c(0);
    for (std::size_t f = 0; f < F; ++f) out.execution[f] = c(static_cast<Eigen::Index>(f + 1));
    double squares = 0;
    for (const auto& [x, y] : observations) {
      double fitted = 0;
      for (std::size_t r = 0; r < P; ++r) fitted += c(static_cast<Eigen::Index>(r)) * x[r];
      squares += (y - fitted) * (y - fitted);
    }
    out.execution_sigma = std::max(std::sqrt(squares / count), 1e-3);
  }
  const std::set<std::string> worlds(data.worlds.begin(), data.worlds.end());
  return std::make_unique<HazardTimeModel>(std::move(feature_names), data.step_seconds, horizon, N, worlds.size(),
                                           std::move(out));
}

PredictedTimes HazardTimeModel::predict_checked(std::span<const double> features) const {
  const HazardParameters& p = parameters_;
  const std::size_t F = feature_count();
  double linear = 0, kappa = p.cure_intercept, mu = p.execution_intercept;
  for (std::size_t f = 0; f < F; ++f) {
    const double z = p.scale[f] > 0 ? (features[f] - p.mean[f]) / p.scale[f] : 0.0;
    linear += p.hazard[f] * z;
    kappa += p.cure[f] * z;
    mu += p.execution[f] * z;
  }
  const auto H = static_cast<std::size_t>(horizon());
  std::vector<double> planning(H + 1, 0.0), execution(H + 1, 0.0);
  double alive = 1 - portable_logistic(kappa);
  std::size_t bin = 0;
  for (std::size_t t = 1; t <= H; ++t) {
    if (static_cast<int>(t) > p.bin_end[bin]) ++bin;
    const double h = portable_logistic(p.baseline[bin] + linear);
    planning[t] = alive * h;
    alive -= planning[t];
  }
  double below = 0;
  for (std::size_t k = 1; k <= H; ++k) {
    const double upper = normal_cdf((portable_log(static_cast<double>(k) * step_seconds()) - mu) / p.execution_sigma);
    execution[k] = std::max(upper - below, 0.0);
    below = upper;
  }
  return {Distribution::from_pmf(std::move(planning)), Distribution::from_pmf(std::move(execution))};
}

std::string HazardTimeModel::parameters_json() const {
  const HazardParameters& p = parameters_;
  detail::ModelJson json = {{"mean", p.mean},
                            {"scale", p.scale},
                            {"bin_end", p.bin_end},
                            {"baseline", p.baseline},
                            {"hazard", p.hazard},
                            {"cure_intercept", p.cure_intercept},
                            {"cure", p.cure},
                            {"execution_intercept", p.execution_intercept},
                            {"execution", p.execution},
                            {"execution_sigma", p.execution_sigma},
                            {"ridge", p.ridge},
                            {"evaluations", p.iterations},
                            {"log_likelihood", p.log_likelihood}};
  return json.dump();
}

namespace detail {

std::unique_ptr<ConditionalTimeModel> read_hazard_model(const ParameterReader& reader, ModelHeader header) {
  const std::size_t F = header.feature_names.size();
  HazardParameters p;
  p.mean = reader.reals("mean", F == 0 ? 0 : F);
  p.scale = reader.reals("scale", F == 0 ? 0 : F);
  if (p.mean.size() != F || p.scale.size() != F) reader.fail("mean", "must hold one number per feature");
  p.bin_end = reader.whole_numbers("bin_end");
  for (std::size_t j = 0; j < p.bin_end.size(); ++j) {
    if (p.bin_end[j] < 1 || (j > 0 && p.bin_end[j] <= p.bin_end[j - 1])) reader.fail("bin_end", "must increase from 1");
  }
  if (p.bin_end.back() != header.horizon) reader.fail("bin_end", "must end at the horizon");
  p.baseline = reader.reals("baseline", p.bin_end.size());
  p.hazard = reader.reals("hazard", F == 0 ? 0 : F);
  p.cure_intercept = reader.real("cure_intercept");
  p.cure = reader.reals("cure", F == 0 ? 0 : F);
  p.execution_intercept = reader.real("execution_intercept");
  p.execution = reader.reals("execution", F == 0 ? 0 : F);
  if (p.hazard.size() != F || p.cure.size() != F || p.execution.size() != F) {
    reader.fail("hazard", "the weights must hold one number per feature");
  }
  p.execution_sigma = reader.real("execution_sigma");
  if (!(p.execution_sigma > 0)) reader.fail("execution_sigma", "must be positive");
  p.ridge = reader.real("ridge");
  p.log_likelihood = reader.real("log_likelihood");
  const double evaluations = reader.real("evaluations");
  if (!(evaluations >= 0 && evaluations <= 1e9 && evaluations == std::floor(evaluations))) {
    reader.fail("evaluations", "must be a whole number >= 0");
  }
  p.iterations = static_cast<int>(evaluations);
  return std::make_unique<HazardTimeModel>(std::move(header.feature_names), header.step_seconds, header.horizon,
                                           header.rows, header.worlds, std::move(p));
}

}  // namespace detail
}  // namespace ontime
