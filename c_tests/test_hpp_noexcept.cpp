// include/ampm.hpp without AMPM_HPP_EXCEPTIONS: every wrapper, builder and view is noexcept
// (checked at compile time for the four (scalar, dimension) pairs), ampm::check and ampm::Error
// are not declared, and the wrappers still report errors as statuses at run time. That the
// header also compiles with -fno-exceptions is checked by compiling c_tests/hpp_check.cpp with
// that flag (a separate compiler run, since every test here shares the same flags).
#include <cstddef>
#include <cstdint>

#include "ampm.hpp"

#include <cstdio>
#include <limits>
#include <utility>

#if defined(AMPM_HPP_EXCEPTIONS)
#error "this test checks the header without AMPM_HPP_EXCEPTIONS"
#endif

namespace {

// ampm::check is found by argument-dependent lookup when it exists.
template <class S>
auto has_check(int) -> decltype(check(std::declval<S>()), std::true_type{});
template <class S>
std::false_type has_check(...);
static_assert(!decltype(has_check<ampm::Status>(0))::value, "ampm::check without exceptions");
static_assert(!decltype(has_check<ampm::BatchStatus>(0))::value, "ampm::check without exceptions");

/// Never called: the parameters name values of each type for the noexcept operands.
template <class T, int D>
void all_noexcept(const T*& c,
                   T*& o,
                   T& mu,
                   const ampm::Options& opt,
                   ampm::span<const T>& sc,
                   ampm::span<T>& so,
                   const ampm::Material<T>& m,
                   const ampm::Particles<T, D>& p,
                   AmpmNodeBox& box,
                   const ampm::P2gView<T, D>& pv,
                   const ampm::G2pView<T, D>& gv,
                   const ampm::ForceView<T, D>& fv,
                   const std::array<ampm::G2pView<T, D>, D>& faces,
                   const std::array<T*, D>& pa,
                   const std::array<const T*, D>& ca,
                   ampm::span<int>& si) {
  using K = ampm::Kernels<T, D>;
  static_assert(noexcept(K::b_z(c, c, o)) && noexcept(K::z_b(c, c, o)) && noexcept(K::energy_hat(mu, c, o)) &&
         noexcept(K::ahat(mu, c, o)) && noexcept(K::chat_z(mu, c, c, o)) &&
         noexcept(K::chat_z_psd(mu, c, c, o)) && noexcept(K::chat_matrix(mu, c, o)) &&
         noexcept(K::chat_psd_matrix(mu, c, o)) && noexcept(K::energy_hat(opt, mu, c, o)) &&
         noexcept(K::ahat(opt, mu, c, o)) && noexcept(K::chat_z(opt, mu, c, c, o)) &&
         noexcept(K::svd(c, o, o, o)) && noexcept(K::svd(opt, c, o, o, o)) &&
         noexcept(K::polar(c, o, o)) && noexcept(K::polar(opt, c, o, o)) &&
         noexcept(K::ahat_batch(0, c, c, o)) && noexcept(K::ahat_batch(sc, sc, so)) &&
         noexcept(K::ahat_batch(opt, sc, sc, so)) && noexcept(K::chat_z_batch(sc, sc, sc, so)) &&
         noexcept(K::chat_z_batch(opt, sc, sc, sc, so)) &&
         noexcept(K::chat_z_psd_batch(sc, sc, sc, so)) &&
         noexcept(K::ahat_chat_z_batch(sc, sc, sc, so, so)) && noexcept(K::hessian_len()) &&
         noexcept(K::hessian_prepare_batch(sc, sc, so, so)) &&
         noexcept(K::hessian_apply_batch(sc, sc, so, true)) &&
         noexcept(ampm::p2g(m, 0, 0, mu, mu, p, pv)) && noexcept(ampm::g2p_update(m, 0, mu, mu, p, gv)) &&
         noexcept(ampm::g2p_update_mac(m, 0, mu, mu, p, faces, &gv)) &&
         noexcept(ampm::node_range(0, 0, mu, p, box)) && noexcept(ampm::force_prepare(m, p, so)) &&
         noexcept(ampm::force_apply(0, mu, p, sc, fv)) && noexcept(ampm::stencil(0, 0, mu, p, si, so, so)) &&
         noexcept(ampm::pressure(m, mu, p, so, so)) && noexcept(ampm::Material<T>().mu(mu).lambda(mu)) &&
         noexcept(ampm::Particles<T, D>(3).x(o).slice(0, 1)) &&
         noexcept(ampm::P2gView<T, D>::separate(box, o, pa, pa)) &&
         noexcept(ampm::G2pView<T, D>::separate(box, ca)) &&
         noexcept(ampm::ForceView<T, D>::separate(box, ca, pa)) && noexcept(ampm::set_isa(0)) &&
         noexcept(ampm::isa()) && noexcept(ampm::Status(AMPM_OK).name()),
                "every wrapper is noexcept");
}

}  // namespace

int main() {
  // Taking the addresses instantiates the compile-time checks for the four pairs.
  (void)&all_noexcept<float, 2>;
  (void)&all_noexcept<float, 3>;
  (void)&all_noexcept<double, 2>;
  (void)&all_noexcept<double, 3>;
  long failures = 0;
  const double f[4] = {std::numeric_limits<double>::quiet_NaN(), 0, 0, 1};
  double out[4] = {7, 7, 7, 7};
  const ampm::Status s = ampm::Kernels2d::ahat(1.0, f, out);
  if (s != AMPM_ERR_NON_FINITE || out[0] != 7) {
    std::fprintf(stderr, "FAIL: ahat(NaN) gave %s\n", s.name());
    ++failures;
  }
  std::printf("test_hpp_noexcept: 1 check (+ compile-time checks), %ld failures\n", failures);
  return failures == 0 ? 0 : 1;
}
