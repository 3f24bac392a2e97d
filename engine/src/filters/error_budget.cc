#include "driftlab/error_budget.h"

#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "driftlab/sensor_terms.h"
#include "driftlab/spec_error.h"

namespace driftlab {
namespace {

// "<triad>.<datasheet key>" of the sensor term whose engine parameter is `param`.
std::string TermSourceName(std::string_view param, SensorTriad t) {
  for (const SensorTerm& term : SensorTerms()) {
    if (term.param == param && !term.datasheet_key.of(t).empty()) {
      return std::string(t == SensorTriad::kGyro ? "gyro." : "accel.") +
             std::string(term.datasheet_key.of(t));
    }
  }
  return std::string(t == SensorTriad::kGyro ? "gyro." : "accel.") + std::string(param);
}

// The aid's name in source names: its field path without "aiding." ("gnss").
std::string AidName(const std::string& path) {
  constexpr std::string_view kPrefix = "aiding.";
  return path.rfind(kPrefix, 0) == 0 ? path.substr(kPrefix.size()) : path;
}

class Splitter {
 public:
  Splitter(const ErrorStateNoise& noise, const ErrorStateMatrix& P0)
      : P0_(P0),
        q_(ErrorStateProcessNoise(noise).diagonal()),
        size_(static_cast<int>(P0.rows())),
        p0_owner_(Eigen::MatrixXi::Constant(size_, size_, -1)),
        q_left_(q_) {
    sources_.reserve(kMaxSources);  // Source returns references that must stay valid
  }

  // The source `name`, created on first use.
  ErrorSource& Source(const std::string& name, const std::string& group) {
    for (ErrorSource& s : sources_) {
      if (s.name == name) return s;
    }
    if (sources_.size() == kMaxSources) {
      throw SpecError("budget", std::to_string(kMaxSources + 1) + " error sources",
                      "at most " + std::to_string(kMaxSources));
    }
    ErrorSource s;
    s.name = name;
    s.group = group;
    s.P0 = ErrorStateMatrix::Zero(size_, size_);
    s.q_c = Eigen::VectorXd::Zero(size_);
    sources_.push_back(std::move(s));
    return sources_.back();
  }
  // The block of P0 on states [first, first + count) goes to `s`.
  void TakeP0(ErrorSource& s, int first, int count) {
    const int index = static_cast<int>(&s - sources_.data());
    for (int i = first; i < first + count; ++i) {
      for (int j = first; j < first + count; ++j) {
        s.P0(i, j) = P0_(i, j);
        p0_owner_(i, j) = index;
      }
    }
  }
  // Q_c(j, j) of states [first, first + count), or `q` of it when q >= 0, goes to `s`.
  void TakeQ(ErrorSource& s, int first, int count, double q = -1.0) {
    for (int j = first; j < first + count; ++j) {
      const double share = q >= 0.0 ? q : q_left_[j];
      s.q_c[j] += share;
      q_left_[j] -= share;
    }
  }
  std::vector<ErrorSource> Finish() {
    // Every nonzero entry of P0 must lie in one source's block: otherwise P0 correlates sources.
    for (int i = 0; i < size_; ++i) {
      for (int j = 0; j < size_; ++j) {
        if (P0_(i, j) != 0.0 && p0_owner_(i, j) < 0) {
          throw SpecError("budget", "P0(" + std::to_string(i) + ", " + std::to_string(j) + ")",
                          "an initial covariance without correlation between error sources");
        }
      }
      if (q_left_[i] != 0.0) {
        throw SpecError("budget", "Q_c(" + std::to_string(i) + ") unassigned",
                        "every process noise of the model in a source");
      }
    }
    std::vector<ErrorSource> out;
    for (ErrorSource& s : sources_) {
      if (!s.P0.isZero(0.0) || !s.q_c.isZero(0.0) || !s.aid_term.empty()) {
        out.push_back(std::move(s));
      }
    }
    return out;
  }

 private:
  static constexpr size_t kMaxSources = 256;
  const ErrorStateMatrix& P0_;
  Eigen::VectorXd q_;
  int size_;
  Eigen::MatrixXi p0_owner_;
  Eigen::VectorXd q_left_;
  std::vector<ErrorSource> sources_;
};

// One triad's white noise, bias states and scale factor / misalignment.
void SplitTriad(SensorTriad t, const TriadErrorParams& p, const ErrorStateNoise& noise,
                const ErrorStateLayout& layout, Splitter* split) {
  const bool gyro = t == SensorTriad::kGyro;
  const std::string group = gyro ? "gyro" : "accel";
  // White noise: N^2 on the attitude (gyro) or velocity (accelerometer) states; what the model
  // adds to it beyond N^2 is the white-noise bound of the scale factor and misalignment
  // (ErrorModelOptions::augment_scale_misalignment = false).
  const int white_first = gyro ? kErrAttitude : kErrVelocity;
  const double psd = gyro ? noise.gyro_white_psd : noise.accel_white_psd;
  const double white = p.white_noise_density * p.white_noise_density;
  if (psd > 0.0) {
    ErrorSource& w = split->Source(TermSourceName("white_noise_density", t), group);
    split->TakeQ(w, white_first, 3, std::min(white, psd));
    if (psd > white) {
      split->TakeQ(split->Source(group + ".scale_misalignment_white_bound", group), white_first, 3);
    }
  }
  // Bias states: the primary (core) block and the extra blocks, each with its source.
  std::vector<std::pair<int, BiasStateSource>> blocks;
  const BiasStateModel& primary = gyro ? noise.gyro_bias : noise.accel_bias;
  blocks.emplace_back(gyro ? kErrGyroBias : kErrAccelBias, primary.source);
  const auto& extra = gyro ? noise.gyro_bias_extra : noise.accel_bias_extra;
  const auto& extra_first = gyro ? layout.gyro_bias_extra : layout.accel_bias_extra;
  for (size_t i = 0; i < extra.size(); ++i) blocks.emplace_back(extra_first[i], extra[i].source);
  for (const auto& [first, source] : blocks) {
    switch (source) {
      case BiasStateSource::kTurnOnAndRandomWalk:
        split->TakeP0(split->Source(TermSourceName("turn_on_bias_sigma", t), group), first, 3);
        split->TakeQ(split->Source(TermSourceName("random_walk", t), group), first, 3);
        break;
      case BiasStateSource::kGaussMarkov: {
        ErrorSource& s = split->Source(TermSourceName("bias_gauss_markov.sigma", t), group);
        split->TakeP0(s, first, 3);
        split->TakeQ(s, first, 3);
        break;
      }
      case BiasStateSource::kFlicker: {
        ErrorSource& s = split->Source(TermSourceName("bias_flicker.bias_instability", t), group);
        split->TakeP0(s, first, 3);
        split->TakeQ(s, first, 3);
        break;
      }
    }
  }
  const int scale = gyro ? layout.gyro_scale : layout.accel_scale;
  const int mis = gyro ? layout.gyro_misalignment : layout.accel_misalignment;
  if (scale >= 0) {
    split->TakeP0(split->Source(TermSourceName("scale_factor_sigma", t), group), scale, 3);
    split->TakeP0(split->Source(TermSourceName("misalignment_sigma_rad", t), group), mis, 6);
  }
}

}  // namespace

std::vector<ErrorSource> SplitErrorSources(const ImuErrorModel& model, const ErrorStateNoise& noise,
                                           const ErrorStateMatrix& P0, const AidingSensors& aids) {
  const ErrorStateLayout layout(noise);
  if (P0.rows() != layout.size || P0.cols() != layout.size) {
    throw SpecError("budget.P0", std::to_string(P0.rows()) + " x " + std::to_string(P0.cols()),
                    std::to_string(layout.size) + " states");
  }
  Splitter split(noise, P0);
  split.TakeP0(split.Source("initial.position", "initial"), kErrPosition, 3);
  split.TakeP0(split.Source("initial.velocity", "initial"), kErrVelocity, 3);
  split.TakeP0(split.Source("initial.attitude", "initial"), kErrAttitude, 3);
  SplitTriad(SensorTriad::kGyro, model.gyro, noise, layout, &split);
  SplitTriad(SensorTriad::kAccel, model.accel, noise, layout, &split);
  for (size_t b = 0; b < noise.aiding_states.size(); ++b) {
    const AidingErrorStates& a = noise.aiding_states[b];
    const std::string group = AidName(a.owner);
    ErrorSource& s = split.Source(group + "." + (a.term.empty() ? "error_states" : a.term), group);
    const int count = static_cast<int>(a.sigma.size());
    split.TakeP0(s, layout.aiding[b], count);
    split.TakeQ(s, layout.aiding[b], count);
  }
  for (const auto& aid : aids) {
    const std::string group = AidName(aid->path());
    for (int r = 0; r < AidingUpdate::kMaxDim; ++r) {
      ErrorSource& s = split.Source(group + "." + aid->NoiseTerm(r), group);
      s.aid = aid->path();
      s.aid_term = aid->NoiseTerm(r);
    }
  }
  return split.Finish();
}

void SourceJosephUpdate(const Eigen::MatrixXd& H, const Eigen::MatrixXd& R,
                        const Eigen::MatrixXd& K, uint32_t rows, ErrorStateMatrix* P_s) {
  // (I - K H) P (I - K H)^T + K R_s K^T = P - K HP - (K HP)^T + K (H P H^T + R_s) K^T.
  const Eigen::MatrixXd HP = H * (*P_s);
  Eigen::MatrixXd S = HP * H.transpose();
  for (Eigen::Index i = 0; i < R.rows(); ++i) {
    for (Eigen::Index j = 0; j < R.cols(); ++j) {
      if ((rows >> i & 1u) != 0 && (rows >> j & 1u) != 0) S(i, j) += R(i, j);
    }
  }
  const ErrorStateMatrix KHP = K * HP;
  *P_s = (*P_s - KHP - KHP.transpose() + K * S * K.transpose()).eval();
  *P_s = 0.5 * (*P_s + P_s->transpose()).eval();
}

ComponentVariances ComponentVariancesOf(const ErrorStateMatrix& P, const EulerAngles& attitude) {
  ComponentVariances v{};
  for (int i = 0; i < 6; ++i) v[static_cast<size_t>(i)] = P(i, i);
  const Matrix3d T = EulerErrorFromAttitudeError(attitude);
  const Matrix3d P_euler = T * P.block<3, 3>(kErrAttitude, kErrAttitude) * T.transpose();
  for (int i = 0; i < 3; ++i) v[static_cast<size_t>(6 + i)] = P_euler(i, i);
  v[static_cast<int>(ErrorComponent::kHorizontalPosition)] = P(0, 0) + P(1, 1);
  v[static_cast<int>(ErrorComponent::kPosition3d)] = P(0, 0) + P(1, 1) + P(2, 2);
  return v;
}

}  // namespace driftlab
