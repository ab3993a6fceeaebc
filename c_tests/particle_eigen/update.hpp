// The reference particle updates: the enthalpy-method heat update and the G2P update of one
// particle from its gathered sample (APIC, F_E with the remedy, the snow clamp, liquids).
#pragma once

#include "reference.hpp"

namespace {

/// Enthalpy-method heat update (see the file comment); q in J/kg.
template <int D>
void ref_heat(const RefMaterial& m, RefParticle<D>& p, ld q) {
  ld e = p.t < m.tm ? m.c_s * (p.t - m.tm) : p.t > m.tm ? m.latent + m.c_l * (p.t - m.tm) : p.u;
  e += q;
  if (e < 0) {
    p.phase = 0, p.u = 0, p.t = m.tm + e / m.c_s;
  } else if (e > m.latent) {
    p.phase = 1, p.u = m.latent, p.t = m.tm + (e - m.latent) / m.c_l;
  } else {
    p.t = m.tm, p.u = e;  // the phase switches only when the buffer leaves [0, L]
  }
}

/// What G2P gathers for one particle: v, C, ∇v and the temperature sums.
template <int D>
struct RefSample {
  Eigen::Matrix<ld, D, 1> v = Eigen::Matrix<ld, D, 1>::Zero();
  MatL<D> c = MatL<D>::Zero(), gv = MatL<D>::Zero();
  ld t_pic = 0, t_flip = 0;
};

/// G2P update of one particle from its gathered sample.
template <int D>
RefParticle<D> ref_update(const RefMaterial& m, ld dt, RefParticle<D> p,
                          const RefSample<D>& s) {
  if (m.thermal) {
    const ld t_star = (1 - m.flip) * s.t_pic + m.flip * (p.t + s.t_flip);
    if (m.phase_change)
      ref_heat(m, p, (p.phase == 0 ? m.c_s : m.c_l) * (t_star - p.t));
    else
      p.t = t_star;
  }
  p.v = s.v;
  p.c = s.c;
  p.x += dt * s.v;
  const MatL<D> id = MatL<D>::Identity();
  MatL<D> a = id + dt * s.gv;
  for (int k = 1; a.determinant() <= 0 && k <= 64; ++k) {
    a = id + std::ldexp(dt, -k) * s.gv;
    for (int i = 0; i < k; ++i) a = a * a;
  }
  p.fe = a * p.fe;
  if (p.phase == 1) {
    // A liquid keeps only its volume history: J_E and J_P, each as a multiple of I.
    const ld je = p.fe.determinant(), jp = p.fp.determinant();
    p.fe = (D == 2 ? std::sqrt(je) : std::cbrt(je)) * id;
    p.fp = (D == 2 ? std::sqrt(jp) : std::cbrt(jp)) * id;
  } else if (m.plastic) {
    const Eigen::JacobiSVD<MatL<D>> svd(p.fe, Eigen::ComputeFullU | Eigen::ComputeFullV);
    Eigen::Matrix<ld, D, 1> sig = svd.singularValues(), cl = sig;
    for (int i = 0; i < D; ++i) cl(i) = std::min(std::max(sig(i), 1 - m.theta_c), 1 + m.theta_s);
    const MatL<D> u = svd.matrixU(), vv = svd.matrixV();
    p.fe = u * cl.asDiagonal() * vv.transpose();
    p.fp = vv * sig.cwiseQuotient(cl).asDiagonal() * vv.transpose() * p.fp;
  }
  return p;
}

}  // namespace
