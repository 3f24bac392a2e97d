// The fixed workload of scripts/ci/machine_factor.sh: a translation unit like driftlab's own
// (Eigen fixed-size algebra, quaternions, standard containers and algorithms), compiled at -O2.
// Its compile time, against the same compile on the reference machine, is the factor CI scales its
// time budgets by. Never linked or run; change it only together with the reference time.
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <algorithm>
#include <map>
#include <string>
#include <vector>

template <int N>
Eigen::Matrix<double, N, N> Step(const Eigen::Matrix<double, N, N>& a) {
  return a * a.transpose() + Eigen::Matrix<double, N, N>::Identity();
}

double Work(const std::vector<double>& v) {
  std::map<std::string, double> m;
  for (size_t i = 0; i < v.size(); ++i) m[std::to_string(i)] = v[i];
  double s = Step<3>(Eigen::Matrix3d::Constant(v[0])).sum();
  s += Step<15>(Eigen::Matrix<double, 15, 15>::Constant(v[0])).sum();
  const Eigen::Quaterniond q(Eigen::AngleAxisd(v[0], Eigen::Vector3d::UnitZ()));
  s += q.toRotationMatrix().sum();
  for (const auto& [k, x] : m) s += x * static_cast<double>(k.size());
  std::vector<double> w(v);
  std::sort(w.begin(), w.end());
  return s + w.front();
}
