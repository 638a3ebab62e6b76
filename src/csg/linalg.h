// voxfield CSG — 3x3 linear algebra for importing transforms: polar decomposition (a rotation
// times a symmetric stretch), the symmetric eigenproblem (Jacobi rotations) and rotation matrices
// to axis and angle. Matrices are row major.
#pragma once

#include <array>
#include <cmath>

#include "voxfield/box.h"

namespace voxfield::csg::detail {

using Mat3 = std::array<double, 9>;

inline Mat3 mul(const Mat3& a, const Mat3& b) {
  Mat3 r{};
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      for (int k = 0; k < 3; ++k) r[i * 3 + j] += a[i * 3 + k] * b[k * 3 + j];
  return r;
}
inline Mat3 transpose(const Mat3& a) {
  return {a[0], a[3], a[6], a[1], a[4], a[7], a[2], a[5], a[8]};
}
inline double det(const Mat3& a) {
  return a[0] * (a[4] * a[8] - a[5] * a[7]) - a[1] * (a[3] * a[8] - a[5] * a[6]) +
         a[2] * (a[3] * a[7] - a[4] * a[6]);
}
inline Mat3 inverse(const Mat3& a) {
  const double d = det(a);
  return {(a[4] * a[8] - a[5] * a[7]) / d, (a[2] * a[7] - a[1] * a[8]) / d,
          (a[1] * a[5] - a[2] * a[4]) / d, (a[5] * a[6] - a[3] * a[8]) / d,
          (a[0] * a[8] - a[2] * a[6]) / d, (a[2] * a[3] - a[0] * a[5]) / d,
          (a[3] * a[7] - a[4] * a[6]) / d, (a[1] * a[6] - a[0] * a[7]) / d,
          (a[0] * a[4] - a[1] * a[3]) / d};
}
inline Vec3d apply(const Mat3& a, Vec3d v) {
  return {a[0] * v.x + a[1] * v.y + a[2] * v.z, a[3] * v.x + a[4] * v.y + a[5] * v.z,
          a[6] * v.x + a[7] * v.y + a[8] * v.z};
}

// L = R S with R a rotation and S symmetric (L invertible with det > 0), by the iteration
// R <- (R + R^-T) / 2 (Higham), which converges quadratically.
inline void polar(const Mat3& l, Mat3& r, Mat3& s) {
  r = l;
  for (int it = 0; it < 30; ++it) {
    const Mat3 inv_t = transpose(inverse(r));
    Mat3 next;
    double change = 0;
    for (int i = 0; i < 9; ++i) {
      next[i] = (r[i] + inv_t[i]) / 2;
      change = std::max(change, std::abs(next[i] - r[i]));
    }
    r = next;
    if (change < 1e-15) break;
  }
  s = mul(transpose(r), l);
  for (int i = 0; i < 3; ++i)  // symmetrise away rounding
    for (int j = i + 1; j < 3; ++j) s[i * 3 + j] = s[j * 3 + i] = (s[i * 3 + j] + s[j * 3 + i]) / 2;
}

// A symmetric matrix as V diag(w) V^T (V's columns the eigenvectors, det V = +1).
inline void eigen_symmetric(Mat3 a, Mat3& v, Vec3d& w) {
  v = {1, 0, 0, 0, 1, 0, 0, 0, 1};
  for (int sweep = 0; sweep < 50; ++sweep) {
    const double off = std::abs(a[1]) + std::abs(a[2]) + std::abs(a[5]);
    if (off < 1e-15 * (std::abs(a[0]) + std::abs(a[4]) + std::abs(a[8]) + 1e-300)) break;
    for (int p = 0; p < 2; ++p)
      for (int q = p + 1; q < 3; ++q) {
        const double apq = a[p * 3 + q];
        if (apq == 0) continue;
        const double theta = (a[q * 3 + q] - a[p * 3 + p]) / (2 * apq);
        const double t = (theta >= 0 ? 1 : -1) / (std::abs(theta) + std::sqrt(theta * theta + 1));
        const double c = 1 / std::sqrt(t * t + 1), s = t * c;
        for (int k = 0; k < 3; ++k) {  // a <- J^T a J, v <- v J
          const double akp = a[k * 3 + p], akq = a[k * 3 + q];
          a[k * 3 + p] = c * akp - s * akq;
          a[k * 3 + q] = s * akp + c * akq;
        }
        for (int k = 0; k < 3; ++k) {
          const double apk = a[p * 3 + k], aqk = a[q * 3 + k];
          a[p * 3 + k] = c * apk - s * aqk;
          a[q * 3 + k] = s * apk + c * aqk;
        }
        for (int k = 0; k < 3; ++k) {
          const double vkp = v[k * 3 + p], vkq = v[k * 3 + q];
          v[k * 3 + p] = c * vkp - s * vkq;
          v[k * 3 + q] = s * vkp + c * vkq;
        }
      }
  }
  w = {a[0], a[4], a[8]};
  if (det(v) < 0)
    for (int k = 0; k < 3; ++k) v[k * 3 + 2] = -v[k * 3 + 2];
}

// A rotation matrix as an angle in degrees about a unit axis (the axis is z for no rotation).
inline void axis_angle(const Mat3& r, double& degrees, Vec3d& axis) {
  // The quaternion (Shepperd's method: the largest of four candidates, for stability).
  const double tr = r[0] + r[4] + r[8];
  double w, x, y, z;
  if (tr > r[0] && tr > r[4] && tr > r[8]) {
    const double s = std::sqrt(1 + tr) * 2;
    w = s / 4, x = (r[7] - r[5]) / s, y = (r[2] - r[6]) / s, z = (r[3] - r[1]) / s;
  } else if (r[0] > r[4] && r[0] > r[8]) {
    const double s = std::sqrt(1 + r[0] - r[4] - r[8]) * 2;
    w = (r[7] - r[5]) / s, x = s / 4, y = (r[1] + r[3]) / s, z = (r[2] + r[6]) / s;
  } else if (r[4] > r[8]) {
    const double s = std::sqrt(1 + r[4] - r[0] - r[8]) * 2;
    w = (r[2] - r[6]) / s, x = (r[1] + r[3]) / s, y = s / 4, z = (r[5] + r[7]) / s;
  } else {
    const double s = std::sqrt(1 + r[8] - r[0] - r[4]) * 2;
    w = (r[3] - r[1]) / s, x = (r[2] + r[6]) / s, y = (r[5] + r[7]) / s, z = s / 4;
  }
  const double n = std::sqrt(x * x + y * y + z * z);
  if (n < 1e-15) {
    degrees = 0;
    axis = {0, 0, 1};
    return;
  }
  degrees = 2 * std::atan2(n, w) * (180.0 / 3.14159265358979323846);
  axis = {x / n, y / n, z / n};
}

}  // namespace voxfield::csg::detail
