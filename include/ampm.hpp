// ampm.hpp: header-only C++17 interface to the ampm C ABI (ampm.h), namespace `ampm`.
//
// Zero-overhead templates over the scalar T (float, double) and the dimension D (2, 3) that
// forward to ampm_<op>_<D>d_<f32|f64>; every layout, unit, NULL rule, status and thread rule is
// the one documented in ampm.h, and each wrapper names the C function it calls.
//
//   ampm::Status, ampm::BatchStatus   [[nodiscard]] results: ok(), explicit bool, code(),
//                                     name(), message(); BatchStatus adds first_failed.
//   ampm::span<T>                     pointer + size; a null span passes NULL to C.
//   ampm::Kernels<T, D>               the constitutive kernels (b_z ... polar, batches,
//                                     hessian prepare/apply); aliases Kernels3f etc.
//   ampm::Options                     AmpmOptions builder for the `_ex` overloads.
//   ampm::Material<T>, PhaseParams<T> AmpmMaterial builders (named setters).
//   ampm::Particles<T, D>             AmpmParticles builder (SoA pointers by name, slices).
//   ampm::node_box<D>, Channel<T, D>  AmpmNodeBox and channel builders (strides in scalars).
//   ampm::P2gView, G2pView, ForceView grid-view builders: separate arrays or node structs.
//   ampm::p2g, g2p_update, g2p_update_mac, node_range, force_prepare, force_apply, stencil,
//   pressure                          the particle transfers, T and D deduced.
//   ampm::set_isa, ampm::isa          the instruction set of the batch calls.
//
// Errors are statuses; nothing throws. With AMPM_HPP_EXCEPTIONS defined (exceptions on),
// ampm::check(status) throws ampm::Error (a std::runtime_error) on failure. Without it the
// header compiles with -fno-exceptions. With Eigen included first (or AMPM_HPP_EIGEN defined),
// overloads on Eigen::Matrix<T, D, D> are added (ampm/eigen.hpp).
#ifndef AMPM_HPP
#define AMPM_HPP

#include "ampm/core.hpp"
#include "ampm/kernels.hpp"
#include "ampm/particles.hpp"
#include "ampm/transfers.hpp"

#if defined(AMPM_HPP_EIGEN) || defined(EIGEN_WORLD_VERSION)
#include "ampm/eigen.hpp"
#endif

#endif  // AMPM_HPP
