// An accelerometer tumble for the calibration tests: 50 Hz, 25 s initial static, then 13 more
// poses of 3 s with 1 s linear transitions; raw f = T f_b + b with T lower triangular (the
// calibration frame), gyro columns 0. Optionally with deterministic noise (a sum of two
// incommensurate sines of the sample index per axis, amplitude `noise` [m/s^2]) and clipped at
// +-clip [m/s^2] (0 = not clipped), as a saturated sensor outputs it. Header-only.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <vector>

namespace driftlab::testing {

// Rows t_s, gx, gy, gz, ax, ay, az.
inline std::vector<std::array<double, 7>> AccelTumbleRows(const double b[3], double noise = 0.0,
                                                          double clip = 0.0) {
  const double T[3][3] = {{1.002, 0, 0}, {1e-3, 0.998, 0}, {-2e-3, 1.5e-3, 1.003}};
  const double s = 1 / std::sqrt(3.0), g = 9.80619;  // |f| = WGS-84 normal gravity at 45 deg, 0 m
  const std::vector<std::array<double, 3>> dirs = {
      {0, 0, -1},  {1, 0, 0},   {-1, 0, 0},  {0, 1, 0},  {0, -1, 0},   {0, 0, 1},  {s, s, s},
      {-s, s, -s}, {s, -s, -s}, {-s, -s, s}, {s, s, -s}, {-s, -s, -s}, {-s, s, s}, {s, -s, s}};
  std::vector<std::array<double, 7>> rows;
  auto emit = [&](const std::array<double, 3>& d) {
    const int k = static_cast<int>(rows.size());
    std::array<double, 7> row{k / 50.0, 0, 0, 0, 0, 0, 0};
    for (int i = 0; i < 3; ++i) {
      double f = b[i];
      for (int j = 0; j < 3; ++j) f += T[i][j] * g * d[j];
      f += noise * (std::sin(1.7 * k + i) + std::sin(0.31 * k * (i + 2))) / 2;
      if (clip > 0) f = std::clamp(f, -clip, clip);
      row[4 + i] = f;
    }
    rows.push_back(row);
  };
  for (int i = 0; i < 25 * 50; ++i) emit(dirs[0]);
  for (size_t p = 1; p < dirs.size(); ++p) {
    for (int i = 1; i <= 50; ++i) {  // transition: not of unit norm, but not static either
      std::array<double, 3> d;
      for (int j = 0; j < 3; ++j) d[j] = dirs[p - 1][j] + (dirs[p][j] - dirs[p - 1][j]) * i / 50.0;
      emit(d);
    }
    for (int i = 0; i < 3 * 50; ++i) emit(dirs[p]);
  }
  return rows;
}

}  // namespace driftlab::testing
