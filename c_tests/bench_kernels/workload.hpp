// The workload: N particles' μ, F = R1·diag(σ)·R2 (Haar rotations, σ log-uniform in [0.5, 2])
// and Z, drawn in double from the fixed seed.
#pragma once

#include "bench_kernels/api.hpp"

namespace {

/// Haar rotation in SO(2): angle uniform in [0, 2π).
Eigen::Matrix2d haar_rotation2(Rng& rng) {
  const double t = rng.uniform(0.0, 6.283185307179586476925);
  Eigen::Matrix2d r;
  r << std::cos(t), -std::sin(t), std::sin(t), std::cos(t);
  return r;
}

/// Haar rotation in SO(3): the unit quaternion of a normalized standard Gaussian 4-vector is
/// uniform on S³, and the double cover S³ → SO(3) maps the uniform measure to the Haar measure
/// (Shoemake 1992, "Uniform random rotations", Graphics Gems III).
Eigen::Matrix3d haar_rotation3(Rng& rng) {
  Eigen::Vector4d q;
  do {
    for (int k = 0; k < 4; ++k) q(k) = rng.normal();
  } while (q.norm() < 1e-6);
  q.normalize();
  return Eigen::Quaterniond(q(0), q(1), q(2), q(3)).toRotationMatrix();
}

/// μ, F, Z of n particles in double (rounded to each case's precision later).
struct Workload {
  int d = 0;
  std::size_t n = 0;
  std::vector<double> mu, f, z;
};

Workload make_workload(int d, std::size_t n) {
  Rng rng(kSeed + static_cast<std::uint64_t>(d));
  Workload w;
  w.d = d;
  w.n = n;
  const std::size_t dd = static_cast<std::size_t>(d) * d;
  w.mu.assign(n, 1.0);
  w.f.resize(n * dd);
  w.z.resize(n * dd);
  for (std::size_t i = 0; i < n; ++i) {
    Eigen::Vector3d sigma;
    for (int k = 0; k < d; ++k) sigma(k) = rng.log_uniform(0.5, 2.0);
    if (d == 2) {
      const Eigen::Matrix2d r1 = haar_rotation2(rng), r2 = haar_rotation2(rng);
      const Eigen::Matrix2d f = r1 * sigma.head<2>().asDiagonal() * r2;
      std::copy(f.data(), f.data() + 4, w.f.begin() + i * dd);
    } else {
      const Eigen::Matrix3d r1 = haar_rotation3(rng), r2 = haar_rotation3(rng);
      const Eigen::Matrix3d f = r1 * sigma.asDiagonal() * r2;
      std::copy(f.data(), f.data() + 9, w.f.begin() + i * dd);
    }
    for (std::size_t k = 0; k < dd; ++k) w.z[i * dd + k] = rng.uniform(-1.0, 1.0);
  }
  return w;
}

}  // namespace
