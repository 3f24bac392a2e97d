// Noise-model fit of Allan-deviation curves (noise_fit.h states the model, weights and rules).
#include "driftlab/calib/noise_fit.h"

#include <ceres/ceres.h>
#include <ceres/covariance.h>
#include <ceres/manifold.h>

#include <Eigen/Dense>
#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <memory>
#include <numbers>
#include <string>
#include <vector>

#include "driftlab/allan.h"
#include "driftlab/elementary.h"
#include "driftlab/sensors.h"
#include "driftlab/spec_error.h"
#include "driftlab/units.h"
#include "noise_fit_model.h"

namespace driftlab::calib {
namespace {

using noise_fit_model::Basis;
using noise_fit_model::GaussMarkovShape;
using noise_fit_model::kB;
using noise_fit_model::kFlickerFloor;
using noise_fit_model::kK;
using noise_fit_model::kN;
using noise_fit_model::kQ;
using noise_fit_model::kR;
using noise_fit_model::kTerms;
using noise_fit_model::Term;

// psi(x) and psi'(x) for x > 0: recurrence up to x >= 6, then the asymptotic series
// (Abramowitz & Stegun 6.3.5, 6.3.18, 6.4.6, 6.4.12); error < 1e-10 there.
double Digamma(double x) {
  double r = 0.0;
  while (x < 6.0) {
    r -= 1.0 / x;
    x += 1.0;
  }
  const double x2 = 1.0 / (x * x);
  return r + math::Log(x) - 0.5 / x -
         x2 * (1.0 / 12.0 - x2 * (1.0 / 120.0 - x2 * (1.0 / 252.0 - x2 / 240.0)));
}

double Trigamma(double x) {
  double r = 0.0;
  while (x < 6.0) {
    r += 1.0 / (x * x);
    x += 1.0;
  }
  const double x2 = 1.0 / (x * x);
  return r + 1.0 / x + 0.5 * x2 +
         x2 / x * (1.0 / 6.0 - x2 * (1.0 / 30.0 - x2 * (1.0 / 42.0 - x2 / 30.0)));
}

struct FitPoint {
  double tau_s = 0.0;
  double y = 0.0;                      // ln AVAR - b(edf)
  double sigma = 0.0;                  // sqrt(psi'(edf / 2))
  std::array<double, kTerms> basis{};  // f_k(t); the Gauss-Markov slot is computed from tau
  int curve = 0;                       // index of the curve the point belongs to
  int64_t m = 0;                       // averaging factor (0 = unknown: uncorrelated)
};

// One ADEV point: r = (ln sum_k s_k x_k f_k(t) - y) / sigma. Parameter blocks: x (kTerms) and, for
// the Gauss-Markov model, ln tau (1).
class PointCost final : public ceres::CostFunction {
 public:
  PointCost(const FitPoint& point, const std::array<double, kTerms>& scale, bool gauss_markov)
      : point_(point), scale_(scale), gauss_markov_(gauss_markov) {
    set_num_residuals(1);
    mutable_parameter_block_sizes()->push_back(kTerms);
    if (gauss_markov_) mutable_parameter_block_sizes()->push_back(1);
  }

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override {
    const double* x = parameters[0];
    std::array<double, kTerms> f = point_.basis;
    double d_gm = 0.0;  // d f_B / d ln tau
    if (gauss_markov_) {
      const double tau = math::Exp(parameters[1][0]);
      f[kB] = GaussMarkovShape(tau, point_.tau_s);
      // Central difference in ln tau, step 1e-4: truncation error ~ h^2 / 6 f''' ~ 2e-9 relative.
      constexpr double kH = 1e-4;
      d_gm = (GaussMarkovShape(tau * math::Exp(kH), point_.tau_s) -
              GaussMarkovShape(tau * math::Exp(-kH), point_.tau_s)) /
             (2.0 * kH);
    }
    double model = 0.0;
    for (int k = 0; k < kTerms; ++k) model += scale_[k] * x[k] * f[k];
    if (!(model > 0.0) || !std::isfinite(model)) return false;
    residuals[0] = (math::Log(model) - point_.y) / point_.sigma;
    if (jacobians != nullptr) {
      const double g = 1.0 / (model * point_.sigma);
      if (jacobians[0] != nullptr) {
        for (int k = 0; k < kTerms; ++k) jacobians[0][k] = scale_[k] * f[k] * g;
      }
      if (gauss_markov_ && jacobians[1] != nullptr) {
        jacobians[1][0] = scale_[kB] * x[kB] * d_gm * g;
      }
    }
    return true;
  }

 private:
  FitPoint point_;
  std::array<double, kTerms> scale_;
  bool gauss_markov_;
};

// Correlation between the overlapping Allan-variance estimates at averaging factors m1 and m2 of
// one record of white rate noise (white FM), for a record much longer than 2 m. Each estimate is
// a mean of squares of d_i(m) = sum_k w_m(k - i) y_k (w_m = -1 on [0, m), +1 on [m, 2m)); for
// Gaussian y, cov(d_i(m1)^2, d_j(m2)^2) = 2 cov(d_i(m1), d_j(m2))^2 (Isserlis), so
//   rho(m1, m2) = sum_L R12(L)^2 / sqrt(sum_L R11(L)^2 sum_L R22(L)^2),
// R12(L) = sum_k w_m1(k) w_m2(k + L) (lag cross-correlation of the weight functions). It depends
// on m2 / m1 and, for small m, on m itself; large m are scaled down to m1 <= 256 keeping the
// ratio. The same rho serves ln AVAR (first order). Other noise types are more correlated across
// tau; the white-FM value is a lower bound used everywhere.
double WhiteFmAvarCorrelation(int64_t m1, int64_t m2) {
  if (m1 <= 0 || m2 <= 0) return 0.0;  // unknown m: independent
  if (m1 == m2) return 1.0;
  if (m1 > m2) std::swap(m1, m2);
  const double ratio = static_cast<double>(m2) / static_cast<double>(m1);
  if (ratio > 256.0) return 0.0;  // rho ~ (m1/m2)^1.5 scale: negligible there
  if (m1 > 256) {
    m2 = std::max<int64_t>(257, std::llround(256.0 * ratio));
    m1 = 256;
  }
  // sum_L R(L)^2 for the weight functions of ma and mb; R(L) = -S_b(L, L + ma) + S_b(L + ma,
  // L + 2 ma) with S_b(a, b) the sum of w_mb over [a, b) (a prefix sum): O(ma + mb).
  const auto sum_r2 = [](int64_t ma, int64_t mb) {
    const auto prefix = [mb](int64_t k) -> double {  // sum of w_mb over [0, k)
      k = std::clamp<int64_t>(k, 0, 2 * mb);
      return k <= mb ? -static_cast<double>(k) : static_cast<double>(k - 2 * mb);
    };
    double total = 0.0;
    for (int64_t lag = -(2 * ma - 1); lag < 2 * mb; ++lag) {
      const double r =
          -(prefix(lag + ma) - prefix(lag)) + (prefix(lag + 2 * ma) - prefix(lag + ma));
      total += r * r;
    }
    return total;
  };
  return sum_r2(m1, m2) / std::sqrt(sum_r2(m1, m1) * sum_r2(m2, m2));
}

// All points of one curve with their correlation (generalised least squares): the normalised
// residuals r_i of PointCost have the correlation matrix C = L L^T; the cost uses L^-1 r, whose
// components are uncorrelated with unit variance, so chi2 = r^T C^-1 r.
class CurveCost final : public ceres::CostFunction {
 public:
  CurveCost(std::vector<FitPoint> points, const std::array<double, kTerms>& scale,
            bool gauss_markov, Eigen::MatrixXd l_inverse)
      : l_inverse_(std::move(l_inverse)), gauss_markov_(gauss_markov) {
    for (const FitPoint& p : points) {
      costs_.push_back(std::make_unique<PointCost>(p, scale, gauss_markov));
    }
    set_num_residuals(static_cast<int>(costs_.size()));
    mutable_parameter_block_sizes()->push_back(kTerms);
    if (gauss_markov_) mutable_parameter_block_sizes()->push_back(1);
  }

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override {
    const int n = static_cast<int>(costs_.size());
    Eigen::VectorXd r(n);
    Eigen::MatrixXd j0(n, kTerms), j1(n, 1);
    for (int i = 0; i < n; ++i) {
      double row0[kTerms], row1[1];
      double* jac[2] = {row0, row1};
      if (!costs_[i]->Evaluate(parameters, &r[i], jacobians != nullptr ? jac : nullptr)) {
        return false;
      }
      if (jacobians != nullptr) {
        for (int k = 0; k < kTerms; ++k) j0(i, k) = row0[k];
        j1(i, 0) = gauss_markov_ ? row1[0] : 0.0;
      }
    }
    Eigen::Map<Eigen::VectorXd>(residuals, n) = l_inverse_ * r;
    if (jacobians != nullptr) {
      if (jacobians[0] != nullptr) {
        Eigen::Map<Eigen::Matrix<double, Eigen::Dynamic, kTerms, Eigen::RowMajor>>(
            jacobians[0], n, kTerms) = l_inverse_ * j0;
      }
      if (gauss_markov_ && jacobians[1] != nullptr) {
        Eigen::Map<Eigen::VectorXd>(jacobians[1], n) = l_inverse_ * j1;
      }
    }
    return true;
  }

 private:
  std::vector<std::unique_ptr<PointCost>> costs_;
  Eigen::MatrixXd l_inverse_;
  bool gauss_markov_;
};

// L^-1 of the Cholesky factor of the points' correlation matrix (WhiteFmAvarCorrelation).
Eigen::MatrixXd InverseCholeskyOfCorrelation(const std::vector<FitPoint>& points) {
  const int n = static_cast<int>(points.size());
  Eigen::MatrixXd c(n, n);
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < n; ++j) {
      c(i, j) = i == j ? 1.0 : WhiteFmAvarCorrelation(points[i].m, points[j].m);
    }
  }
  Eigen::LLT<Eigen::MatrixXd> llt(c);
  if (llt.info() != Eigen::Success) return Eigen::MatrixXd::Identity(n, n);
  return llt.matrixL().solve(Eigen::MatrixXd::Identity(n, n));
}

// One weighted least-squares fit of the model with the terms in `active` (the others fixed at 0).
struct Pass {
  bool ok = false;
  std::array<double, kTerms> x{};               // scaled coefficients a_k / s_k
  std::array<double, kTerms * kTerms> cov_x{};  // their covariance (not inflated)
  bool has_covariance = false;
  double ln_tau_gm = 0.0;
  double var_ln_tau = NAN;
  double chi2 = 0.0;
  int n_parameters = 0;
  int iterations = 0;
  std::string message;
};

struct Problem {
  const std::vector<FitPoint>* points = nullptr;
  std::vector<std::vector<FitPoint>> curves;  // the points by curve
  std::vector<Eigen::MatrixXd> l_inverse;     // per curve
  std::array<double, kTerms> scale{};
  bool gauss_markov = false;
  double tau_first = 0.0;
  double tau_last = 0.0;
  int max_iterations = 200;
};

Pass Solve(const Problem& pr, const std::array<bool, kTerms>& active,
           const std::array<double, kTerms>& x0, double ln_tau0, bool want_covariance) {
  Pass pass;
  pass.x = x0;
  pass.ln_tau_gm = ln_tau0;
  int n_active = 0;
  for (int k = 0; k < kTerms; ++k) {
    n_active += active[k] ? 1 : 0;
    pass.x[k] = active[k] ? (x0[k] > 0.0 ? x0[k] : 0.5) : 0.0;
  }
  const bool fit_tau = pr.gauss_markov && active[kB];
  pass.n_parameters = n_active + (fit_tau ? 1 : 0);
  if (n_active == 0) {
    pass.message = "no term";
    return pass;
  }
  ceres::Problem::Options problem_options;
  ceres::Problem problem(problem_options);
  for (size_t c = 0; c < pr.curves.size(); ++c) {
    auto* cost = new CurveCost(pr.curves[c], pr.scale, pr.gauss_markov, pr.l_inverse[c]);
    if (pr.gauss_markov) {
      problem.AddResidualBlock(cost, nullptr, pass.x.data(), &pass.ln_tau_gm);
    } else {
      problem.AddResidualBlock(cost, nullptr, pass.x.data());
    }
  }
  std::vector<int> fixed;
  for (int k = 0; k < kTerms; ++k) {
    if (!active[k]) {
      fixed.push_back(k);
    } else {
      problem.SetParameterLowerBound(pass.x.data(), k, 0.0);
    }
  }
  if (!fixed.empty()) problem.SetManifold(pass.x.data(), new ceres::SubsetManifold(kTerms, fixed));
  if (pr.gauss_markov) {
    if (fit_tau) {
      // tau between a tenth of the shortest and ten times the longest averaging time.
      problem.SetParameterLowerBound(&pass.ln_tau_gm, 0, math::Log(pr.tau_first / 10.0));
      problem.SetParameterUpperBound(&pass.ln_tau_gm, 0, math::Log(pr.tau_last * 10.0));
    } else {
      problem.SetParameterBlockConstant(&pass.ln_tau_gm);
    }
  }
  ceres::Solver::Options solver_options;
  solver_options.linear_solver_type = ceres::DENSE_QR;
  solver_options.max_num_iterations = pr.max_iterations;
  solver_options.function_tolerance = 1e-14;
  solver_options.gradient_tolerance = 1e-14;
  solver_options.parameter_tolerance = 1e-12;
  solver_options.logging_type = ceres::SILENT;
  solver_options.num_threads = 1;
  ceres::Solver::Summary summary;
  ceres::Solve(solver_options, &problem, &summary);
  pass.iterations = static_cast<int>(summary.iterations.size());
  if (!summary.IsSolutionUsable()) {
    pass.message = summary.message;
    return pass;
  }
  pass.chi2 = 2.0 * summary.final_cost;
  pass.ok = true;
  if (!want_covariance) return pass;
  ceres::Covariance::Options covariance_options;
  covariance_options.algorithm_type = ceres::DENSE_SVD;
  ceres::Covariance covariance(covariance_options);
  std::vector<std::pair<const double*, const double*>> blocks = {{pass.x.data(), pass.x.data()}};
  if (fit_tau) blocks.push_back({&pass.ln_tau_gm, &pass.ln_tau_gm});
  if (covariance.Compute(blocks, &problem)) {
    covariance.GetCovarianceBlock(pass.x.data(), pass.x.data(), pass.cov_x.data());
    if (fit_tau) covariance.GetCovarianceBlock(&pass.ln_tau_gm, &pass.ln_tau_gm, &pass.var_ln_tau);
    pass.has_covariance = true;
  }
  return pass;
}

// Smallest k with P(Binomial(n, p) <= k) >= q.
int BinomialQuantile(int n, double p, double q) {
  double term = math::Exp(n * math::Log1p(-p));  // P(X = 0) = (1 - p)^n
  double cdf = term;
  int k = 0;
  while (cdf < q && k < n) {
    term *= static_cast<double>(n - k) / (k + 1) * p / (1.0 - p);
    cdf += term;
    ++k;
  }
  return k;
}

}  // namespace

NoiseFitResult FitAllanNoiseModel(std::span<const AllanPoint> curve,
                                  const NoiseFitOptions& options) {
  const std::vector<AllanPoint> copy(curve.begin(), curve.end());
  return FitAllanNoiseModel(std::span<const std::vector<AllanPoint>>(&copy, 1), options);
}

NoiseFitResult FitAllanNoiseModel(std::span<const std::vector<AllanPoint>> curves,
                                  const NoiseFitOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  if (!(options.confidence >= 0.5 && options.confidence < 1.0)) {
    throw SpecError("noise_fit.confidence", std::to_string(options.confidence), "[0.5, 1)");
  }
  if (options.max_iterations < 1) {
    throw SpecError("noise_fit.max_iterations", std::to_string(options.max_iterations), ">= 1");
  }
  // Tau range of the usable points.
  double tau_first = INFINITY, tau_last = 0.0;
  for (const auto& c : curves) {
    for (const AllanPoint& p : c) {
      if (p.edf > 0.0 && p.adev > 0.0 && std::isfinite(p.adev) && p.tau_s > 0.0) {
        tau_first = std::min(tau_first, p.tau_s);
        tau_last = std::max(tau_last, p.tau_s);
      }
    }
  }
  if (!(tau_last > 0.0)) {
    throw SpecError("allan curve", "no point with adev > 0 and edf > 0",
                    "an Allan-deviation curve of a noisy signal (at least one usable point)");
  }
  NoiseFitResult result;
  result.bias_model = options.bias_model;
  result.flicker_tau_min_s =
      options.flicker_tau_min_s > 0.0 ? options.flicker_tau_min_s : tau_first;
  result.flicker_tau_max_s = options.flicker_tau_max_s > 0.0 ? options.flicker_tau_max_s : tau_last;
  const bool flicker = options.bias_model == BiasModel::kFlickerFlat ||
                       options.bias_model == BiasModel::kFlickerBand;
  if (flicker && !(result.flicker_tau_min_s < result.flicker_tau_max_s &&
                   result.flicker_tau_max_s / result.flicker_tau_min_s <= kMaxFlickerRangeRatio)) {
    throw SpecError("noise_fit.flicker_tau_min_s",
                    std::to_string(result.flicker_tau_min_s) + " s (tau_max_s " +
                        std::to_string(result.flicker_tau_max_s) + " s)",
                    "0 < flicker_tau_min_s < flicker_tau_max_s <= 1e9 flicker_tau_min_s");
  }
  const bool gauss_markov = options.bias_model == BiasModel::kGaussMarkov;

  std::vector<FitPoint> points;
  for (size_t ci = 0; ci < curves.size(); ++ci) {
    for (const AllanPoint& p : curves[ci]) {
      if (!(p.edf > 0.0 && p.adev > 0.0 && std::isfinite(p.adev) && p.tau_s > 0.0)) continue;
      FitPoint fp;
      fp.tau_s = p.tau_s;
      const double half_edf = 0.5 * p.edf;
      fp.y = 2.0 * math::Log(p.adev) - (Digamma(half_edf) - math::Log(half_edf));
      fp.sigma = std::sqrt(Trigamma(half_edf));
      fp.basis =
          Basis(options.bias_model, result.flicker_tau_min_s, result.flicker_tau_max_s, p.tau_s);
      fp.curve = static_cast<int>(ci);
      fp.m = p.m;
      points.push_back(fp);
    }
  }

  std::array<bool, kTerms> active = {options.fit_quantization, options.fit_white_noise,
                                     options.bias_model != BiasModel::kNone,
                                     options.fit_random_walk, options.fit_rate_ramp};
  for (int k = 0; k < kTerms; ++k) Term(result, k)->fitted = active[k];
  result.gauss_markov_tau_s.fitted = gauss_markov;

  // Scale of each coefficient: the largest variance the term alone may have without exceeding
  // the data at any point, s_k = min_i AVAR_i / f_k(t_i); x_k = a_k / s_k is then O(1) or less.
  double ln_tau_gm = math::Log(std::sqrt(tau_first * tau_last));
  std::array<double, kTerms> scale{};
  for (int k = 0; k < kTerms; ++k) {
    scale[k] = INFINITY;
    for (const FitPoint& p : points) {
      const double f =
          (k == kB && gauss_markov) ? GaussMarkovShape(math::Exp(ln_tau_gm), p.tau_s) : p.basis[k];
      if (f > 0.0) scale[k] = std::min(scale[k], math::Exp(p.y) / f);
    }
    if (!std::isfinite(scale[k]) || !(scale[k] > 0.0)) {
      active[k] = false;
      scale[k] = 1.0;  // the term is fixed at 0; a finite scale keeps 0 * f finite
    }
  }
  Problem problem{&points,      {},        {},       scale,
                  gauss_markov, tau_first, tau_last, options.max_iterations};
  problem.curves.resize(curves.size());
  for (const FitPoint& p : points) problem.curves[p.curve].push_back(p);
  std::erase_if(problem.curves, [](const std::vector<FitPoint>& c) { return c.empty(); });
  for (const auto& c : problem.curves) problem.l_inverse.push_back(InverseCholeskyOfCorrelation(c));
  const int n_points = static_cast<int>(points.size());
  const auto check_size = [&](int n_parameters) {
    if (n_points <= n_parameters) {
      throw SpecError("allan curve", std::to_string(n_points) + " usable points",
                      "more points than fitted parameters (" + std::to_string(n_parameters) +
                          "): a longer record or a denser tau grid");
    }
  };
  const auto run = [&](const std::array<bool, kTerms>& use, const std::array<double, kTerms>& x0,
                       double ln_tau0, bool want_covariance) {
    Pass pass = Solve(problem, use, x0, ln_tau0, want_covariance);
    result.iterations += pass.iterations;
    ++result.passes;
    return pass;
  };
  const auto inflation = [&](const Pass& pass) {
    return std::max(1.0, pass.chi2 / (n_points - pass.n_parameters));
  };
  int n_active = 0;
  for (int k = 0; k < kTerms; ++k) n_active += active[k] ? 1 : 0;
  if (n_active == 0) {
    throw SpecError("allan curve", "no noise term is fitted",
                    "at least one term (fit_* options, bias_model) with a finite scale");
  }
  check_size(n_active + (gauss_markov && active[kB] ? 1 : 0));

  // Backward elimination by the likelihood-ratio test (noise_fit.h).
  const double alpha = 1.0 - options.confidence;
  const double threshold_1 = ChiSquareQuantile(1.0 - 2.0 * alpha, 1.0);
  const double threshold_gm = ChiSquareQuantile(options.confidence, 2.0);
  const auto threshold_of = [&](int k) {
    return (k == kB && gauss_markov) ? threshold_gm : threshold_1;
  };
  Pass current = run(active, {}, ln_tau_gm, true);
  if (!current.ok) {
    throw SpecError("allan curve", "the noise-model fit failed (" + current.message + ")",
                    "a curve the model can describe");
  }
  while (true) {
    int n_now = 0;
    for (int k = 0; k < kTerms; ++k) n_now += active[k] ? 1 : 0;
    if (n_now <= 1) break;
    int worst = -1;
    double worst_margin = INFINITY;
    Pass worst_pass;
    for (int k = 0; k < kTerms; ++k) {
      if (!active[k]) continue;
      std::array<bool, kTerms> without = active;
      without[k] = false;
      Pass reduced = run(without, current.x, current.ln_tau_gm, false);
      // A reduced model that cannot be fitted keeps the term.
      const double d =
          reduced.ok ? std::max(0.0, reduced.chi2 - current.chi2) / inflation(current) : INFINITY;
      NoiseTermEstimate& t = *Term(result, k);
      t.lr_statistic = d;
      t.lr_threshold = threshold_of(k);
      // Compare on the p-value scale through the ratio to each term's own threshold.
      const double margin = d / threshold_of(k);
      if (margin < worst_margin) {
        worst_margin = margin;
        worst = k;
        worst_pass = std::move(reduced);
      }
    }
    if (worst < 0 || worst_margin >= 1.0) break;
    // Drop `worst`: its 95 % one-sided bound from the fit that still held it.
    NoiseTermEstimate& t = *Term(result, worst);
    const double a = scale[worst] * current.x[worst];
    const double var_x =
        current.has_covariance ? current.cov_x[worst * kTerms + worst] * inflation(current) : NAN;
    const double sigma_a = scale[worst] * std::sqrt(std::max(0.0, var_x));
    t.determined = false;
    t.value = 0.0;
    t.sigma = NAN;
    t.upper_bound = std::sqrt(std::max(a, 0.0) + 1.645 * sigma_a);
    active[worst] = false;
    current = run(active, worst_pass.x, worst_pass.ln_tau_gm, true);
    if (!current.ok) {
      throw SpecError("allan curve", "the noise-model fit failed (" + current.message + ")",
                      "a curve the model can describe");
    }
  }
  if (!current.has_covariance) {
    throw SpecError("allan curve",
                    "the fitted noise terms are not separable on this tau range (singular "
                    "covariance)",
                    "a curve spanning the terms' slopes, or fewer fitted terms");
  }
  const double chi2 = current.chi2;
  result.n_parameters = current.n_parameters;
  const double infl = inflation(current);
  for (int k = 0; k < kTerms; ++k) {
    if (!active[k]) continue;
    NoiseTermEstimate& t = *Term(result, k);
    const double a = scale[k] * current.x[k];
    const double sigma_a =
        scale[k] * std::sqrt(std::max(0.0, current.cov_x[k * kTerms + k]) * infl);
    t.determined = true;
    t.value = std::sqrt(std::max(a, 0.0));
    t.sigma = t.value > 0.0 ? sigma_a / (2.0 * t.value) : NAN;  // sigma_c = sigma_a / (2 c)
    t.lower_95 = std::sqrt(std::max(0.0, a - 1.96 * sigma_a));
    t.upper_95 = std::sqrt(std::max(0.0, a + 1.96 * sigma_a));
    t.upper_bound = NAN;
  }
  if (gauss_markov) {
    NoiseTermEstimate& t = result.gauss_markov_tau_s;
    if (active[kB]) {
      const double sigma_ln_tau = std::sqrt(std::max(0.0, current.var_ln_tau) * infl);
      t.determined = true;
      t.value = math::Exp(current.ln_tau_gm);
      t.sigma = t.value * sigma_ln_tau;  // d tau = tau d ln tau
      t.lower_95 = t.value * math::Exp(-1.96 * sigma_ln_tau);
      t.upper_95 = t.value * math::Exp(1.96 * sigma_ln_tau);
    } else {
      t.determined = false;
      t.value = 0.0;
    }
  }
  result.n_points = static_cast<int>(points.size());
  result.chi2_per_dof = chi2 / (result.n_points - result.n_parameters);
  result.residual_rms = std::sqrt(chi2 / result.n_points);
  result.chi2 = chi2;
  const double dof = result.n_points - result.n_parameters;
  result.chi2_low = ChiSquareQuantile(0.001, dof);
  result.chi2_high = ChiSquareQuantile(0.999, dof);
  // Fitted curve against each point's 95 % interval (the interval of the estimate, allan.h).
  for (const auto& c : curves) {
    for (const AllanPoint& p : c) {
      if (!(p.edf > 0.0 && p.adev > 0.0 && std::isfinite(p.adev) && p.tau_s > 0.0)) continue;
      if (!(p.adev_high > p.adev_low)) continue;  // no interval given
      const double model = FittedAllanDeviation(result, p.tau_s);
      if (model < p.adev_low || model > p.adev_high) {
        ++result.points_outside_95;
        result.tau_outside_95_s.push_back(p.tau_s);
      }
    }
  }
  result.expected_outside_95 = 0.05 * result.n_points;
  result.max_plausible_outside_95 = BinomialQuantile(result.n_points, 0.05, 0.99);
  char text[512];
  if (result.points_outside_95 > 0) {
    std::string taus;
    for (size_t i = 0; i < result.tau_outside_95_s.size() && i < 8; ++i) {
      char one[32];
      std::snprintf(one, sizeof one, "%s%.4g", i ? ", " : "", result.tau_outside_95_s[i]);
      taus += one;
    }
    if (result.tau_outside_95_s.size() > 8) taus += ", ...";
    std::snprintf(text, sizeof text,
                  "the fitted curve leaves the 95 %% interval at %d of %d points (tau %s s); a "
                  "correct model leaves about %.1f (5 %%), at most %d at 99 %% (binomial)%s",
                  result.points_outside_95, result.n_points, taus.c_str(),
                  result.expected_outside_95, result.max_plausible_outside_95,
                  result.points_outside_95 > result.max_plausible_outside_95
                      ? ": the model does not describe the data there"
                      : "");
    result.warnings.push_back(text);
  }
  if (chi2 > result.chi2_high || chi2 < result.chi2_low) {
    std::snprintf(text, sizeof text,
                  "chi2 %.4g for %.0f degrees of freedom (chi2/dof %.3g) lies outside the chi2_dof "
                  "0.1 %%-99.9 %% range [%.4g, %.4g]: %s",
                  chi2, dof, result.chi2_per_dof, result.chi2_low, result.chi2_high,
                  chi2 > result.chi2_high
                      ? "the model misses a feature of the data (a term absent from the model or a "
                        "different bias shape); the terms' intervals are scaled by chi2/dof"
                      : "the residuals are smaller than the confidence intervals allow (weights "
                        "too wide)");
    result.warnings.push_back(text);
  }
  result.fit_time_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return result;
}

}  // namespace driftlab::calib
