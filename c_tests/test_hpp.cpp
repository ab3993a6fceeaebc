// include/ampm.hpp, kernels: every wrapper of ampm::Kernels<T, D> and the Eigen overloads give
// bit-identical outputs, statuses and first_failed indices to the direct C call, for the four
// (scalar, dimension) pairs, on valid and invalid inputs (NaN, J < 0, mu < 0, invalid options,
// NULL pointers); span overloads with sizes that disagree return AMPM_ERR_INVALID_ARGUMENT with
// first_failed = 0 and write nothing; ampm::Status names every code; with AMPM_HPP_EXCEPTIONS,
// ampm::check throws ampm::Error carrying the status and first_failed.
//
// Outputs start as a sentinel in both the wrapper's and the C call's buffers, so "not written"
// is compared as well. The particle API is tested in test_hpp_particles.cpp.
#define AMPM_HPP_EXCEPTIONS
#include "common.hpp"

#include "ampm.hpp"

#include <string>

using namespace ampm_test;

namespace {

Checker ck;

template <class T>
std::vector<T> sentinels(std::size_t n) {
  return std::vector<T>(n, sentinel<T>());
}

template <class T>
bool same(const std::vector<T>& a, const std::vector<T>& b) {
  return a.size() == b.size() && same_bits(a.data(), b.data(), a.size());
}

/// F matrices of a batch: valid ones, and at fixed indices a NaN entry, J < 0, a singular F.
template <class T, int D>
std::vector<T> batch_f(Rng& rng, std::size_t n, bool with_faults) {
  std::vector<T> f(n * D * D);
  for (std::size_t k = 0; k < n; ++k) {
    Eigen::Matrix<ld, D, 1> s = log_uniform_sigma<D>(rng, 0.5, 2.0);
    const Mat<T, D> m = round_to<T, D>(random_f_with_sigma<D>(rng, s));
    std::memcpy(&f[k * D * D], m.data(), sizeof(T) * D * D);
  }
  if (with_faults && n > 20) {
    f[5 * D * D + 1] = std::numeric_limits<T>::quiet_NaN();
    for (int j = 0; j < D; ++j) f[11 * D * D + D * j] = -f[11 * D * D + D * j];  // row 0 → J < 0
    for (int i = 0; i < D * D; ++i) f[17 * D * D + i] = 0;                       // singular
  }
  return f;
}

template <class T, int D>
std::vector<T> batch_z(Rng& rng, std::size_t n) {
  std::vector<T> z(n * D * D);
  for (auto& v : z) v = static_cast<T>(rng.normal());
  return z;
}

// ---- status --------------------------------------------------------------------------------

void test_status() {
  const AmpmStatus codes[] = {AMPM_OK, AMPM_ERR_NULL_POINTER, AMPM_ERR_NON_FINITE,
                              AMPM_ERR_NON_POSITIVE_J, AMPM_ERR_OVERFLOW,
                              AMPM_ERR_INVALID_ARGUMENT, AMPM_ERR_NOT_CONVERGED,
                              AMPM_ERR_INTERNAL, AMPM_ERR_NOT_PREPARED, AMPM_ERR_OUTSIDE_GRID};
  for (AmpmStatus c : codes) {
    const ampm::Status s(c);
    AMPM_CHECK(ck, s.code() == c, "code %d", int(c));
    AMPM_CHECK(ck, s.ok() == (c == AMPM_OK) && bool(s) == (c == AMPM_OK), "ok() of %d", int(c));
    AMPM_CHECK(ck, std::string(s.name()) == status_name(c), "name %s", s.name());
    AMPM_CHECK(ck, std::strlen(s.message()) > 5, "message of %s", s.name());
    AMPM_CHECK(ck, s == c && !(s != c) && (c == AMPM_OK || s != AMPM_OK), "compare %s", s.name());
    const ampm::BatchStatus b(c, 7);
    AMPM_CHECK(ck, b.code() == c && b.first_failed == 7 && b.status() == c, "batch %d", int(c));
  }
  AMPM_CHECK(ck, std::string(ampm::status_name(static_cast<AmpmStatus>(99))) == "AMPM_ERR_UNKNOWN",
             "unknown code name");
  // A default Status is success; distinct messages per code.
  AMPM_CHECK(ck, ampm::Status().ok(), "default status");
  AMPM_CHECK(ck, std::string(ampm::Status(AMPM_ERR_NON_FINITE).message()) !=
                     ampm::Status(AMPM_ERR_OVERFLOW).message(), "messages differ");
}

void test_exceptions() {
  bool thrown = false;
  try {
    ampm::check(ampm::BatchStatus(AMPM_ERR_NON_POSITIVE_J, 11));
  } catch (const ampm::Error& e) {
    thrown = true;
    AMPM_CHECK(ck, e.status() == AMPM_ERR_NON_POSITIVE_J && e.first_failed() == 11,
               "Error carries %s / %zu", e.status().name(), e.first_failed());
    AMPM_CHECK(ck, std::string(e.what()).find("AMPM_ERR_NON_POSITIVE_J") != std::string::npos,
               "what(): %s", e.what());
  }
  AMPM_CHECK(ck, thrown, "check(error) throws");
  thrown = false;
  try {
    ampm::check(ampm::Status(AMPM_OK));
    ampm::check(ampm::BatchStatus(AMPM_OK, 5));
  } catch (const std::exception&) {
    thrown = true;
  }
  AMPM_CHECK(ck, !thrown, "check(AMPM_OK) does not throw");
  // A real failing call through check, caught as std::runtime_error.
  const float f[9] = {std::numeric_limits<float>::quiet_NaN(), 0, 0, 0, 1, 0, 0, 0, 1};
  float out[9];
  thrown = false;
  try {
    ampm::check(ampm::Kernels3f::ahat(1.0f, f, out));
  } catch (const std::runtime_error& e) {
    const auto* err = dynamic_cast<const ampm::Error*>(&e);
    thrown = err != nullptr && err->status() == AMPM_ERR_NON_FINITE;
  }
  AMPM_CHECK(ck, thrown, "check(ahat(NaN)) throws Error(AMPM_ERR_NON_FINITE)");
}

// ---- single-particle kernels ---------------------------------------------------------------

/// Compares one wrapper call against the C call: same status, same output bytes.
#define SAME_SINGLE(label, nout, wrap_call, c_call)                                         \
  do {                                                                                      \
    auto out = sentinels<T>(nout);                                                          \
    auto ref = sentinels<T>(nout);                                                          \
    const ampm::Status sw = [&](T* o) { return wrap_call; }(out.data());                   \
    const AmpmStatus sc = [&](T* o) { return c_call; }(ref.data());                        \
    AMPM_CHECK(ck, sw.code() == sc && same(out, ref), "%s %s case %d: %s vs %s", name,     \
               label, c, sw.name(), status_name(sc));                                       \
  } while (0)

template <class T, int D>
void test_single(const char* name, std::uint64_t seed) {
  using K = ampm::Kernels<T, D>;
  using A = ampm::detail::api<T, D>;
  constexpr std::size_t M = D * D;
  Rng rng(seed);
  const auto fs = batch_f<T, D>(rng, 24, true);
  const auto zs = batch_z<T, D>(rng, 24);
  const T mus[] = {T(1e5), T(0), T(-1), std::numeric_limits<T>::quiet_NaN()};
  ampm::Options qr;
  qr.method(D == 3 ? AMPM_METHOD_QR : AMPM_METHOD_CLOSED_FORM_2D).max_iterations(20);
  ampm::Options bad;
  bad.method(99);
  const AmpmOptions* popt[] = {&qr.c(), &bad.c()};
  const ampm::Options* wopt[] = {&qr, &bad};
  int cases = 0;
  for (int c = 0; c < 24; ++c) {
    const T* f = &fs[static_cast<std::size_t>(c) * M];
    const T* z = &zs[static_cast<std::size_t>(c) * M];
    const T mu = mus[c % 4 == 3 ? (c / 4) % 4 : 0];
    const ampm::Options& wo = *wopt[c % 2];
    const AmpmOptions* co = popt[c % 2];
    SAME_SINGLE("b_z", M, K::b_z(f, z, o), A::b_z(f, z, o));
    SAME_SINGLE("z_b", M, K::z_b(f, z, o), A::z_b(f, z, o));
    SAME_SINGLE("energy_hat", 1, K::energy_hat(mu, f, o), A::energy_hat(mu, f, o));
    SAME_SINGLE("ahat", M, K::ahat(mu, f, o), A::ahat(mu, f, o));
    SAME_SINGLE("chat_z", M, K::chat_z(mu, f, z, o), A::chat_z(mu, f, z, o));
    SAME_SINGLE("chat_z_psd", M, K::chat_z_psd(mu, f, z, o), A::chat_z_psd(mu, f, z, o));
    SAME_SINGLE("chat_matrix", M * M, K::chat_matrix(mu, f, o), A::chat_matrix(mu, f, o));
    SAME_SINGLE("chat_psd_matrix", M * M, K::chat_psd_matrix(mu, f, o),
                A::chat_psd_matrix(mu, f, o));
    SAME_SINGLE("energy_hat_ex", 1, K::energy_hat(wo, mu, f, o), A::energy_hat_ex(co, mu, f, o));
    SAME_SINGLE("ahat_ex", M, K::ahat(wo, mu, f, o), A::ahat_ex(co, mu, f, o));
    SAME_SINGLE("chat_z_ex", M, K::chat_z(wo, mu, f, z, o), A::chat_z_ex(co, mu, f, z, o));
    // svd / polar: outputs packed [u | sigma | v] and [r | s].
    SAME_SINGLE("svd", 2 * M + D, K::svd(f, o, o + M, o + M + D),
                A::svd(nullptr, f, o, o + M, o + M + D));
    SAME_SINGLE("svd_ex", 2 * M + D, K::svd(wo, f, o, o + M, o + M + D),
                A::svd(co, f, o, o + M, o + M + D));
    SAME_SINGLE("polar", 2 * M, K::polar(f, o, o + M), A::polar(nullptr, f, o, o + M));
    SAME_SINGLE("polar_ex", 2 * M, K::polar(wo, f, o, o + M), A::polar(co, f, o, o + M));
    ++cases;
  }
  // The default Options reproduce the non-_ex call exactly (documented in ampm.h).
  {
    const int c = 0;
    const T* f = fs.data();
    SAME_SINGLE("ahat(Options())", M, K::ahat(ampm::Options(), T(1e5), f, o),
                A::ahat(T(1e5), f, o));
  }
  // NULL pointers go through unchanged.
  {
    const int c = -1;
    SAME_SINGLE("ahat(NULL f)", M, K::ahat(T(1), nullptr, o), A::ahat(T(1), nullptr, o));
    T tmp[M] = {};
    const ampm::Status s = K::ahat(T(1), tmp, nullptr);
    AMPM_CHECK(ck, s == AMPM_ERR_NULL_POINTER, "%s ahat(NULL out): %s", name, s.name());
  }
  // The faults of batch_f give the documented statuses through the wrapper.
  T o[M];
  AMPM_CHECK(ck, K::ahat(T(1), &fs[5 * M], o) == AMPM_ERR_NON_FINITE, "%s NaN", name);
  AMPM_CHECK(ck, K::ahat(T(1), &fs[11 * M], o) == AMPM_ERR_NON_POSITIVE_J, "%s J<0", name);
  AMPM_CHECK(ck, K::ahat(T(-1), &fs[0], o) == AMPM_ERR_INVALID_ARGUMENT, "%s mu<0", name);
  AMPM_CHECK(ck, K::ahat(bad, T(1), &fs[0], o) == AMPM_ERR_INVALID_ARGUMENT, "%s bad opt", name);
  AMPM_CHECK(ck, K::hessian_len() == A::hessian_len() && K::hessian_len() == (D == 2 ? 18u : 38u),
             "%s hessian_len %zu", name, K::hessian_len());
  (void)cases;
}
#undef SAME_SINGLE

// ---- batches -------------------------------------------------------------------------------

/// Compares a wrapper batch call with the C call: status, first_failed, every output byte.
#define SAME_BATCH(label, outs_w, outs_c, wrap_call, c_call)                                   \
  do {                                                                                         \
    const ampm::BatchStatus bw = wrap_call;                                                    \
    std::size_t ffc = 12345;                                                                   \
    const AmpmStatus sc = c_call;                                                              \
    bool eq = true;                                                                            \
    for (std::size_t i_ = 0; i_ < outs_w.size(); ++i_) eq = eq && same(*outs_w[i_], *outs_c[i_]); \
    AMPM_CHECK(ck, bw.code() == sc && bw.first_failed == ffc && eq,                            \
               "%s %s: %s/%zu vs %s/%zu, outputs %s", name, label, bw.name(), bw.first_failed, \
               status_name(sc), ffc, eq ? "equal" : "DIFFER");                                 \
  } while (0)

template <class T, int D>
void test_batch(const char* name, std::uint64_t seed, bool faults) {
  using K = ampm::Kernels<T, D>;
  using A = ampm::detail::api<T, D>;
  constexpr std::size_t M = D * D;
  const std::size_t n = 37, L = K::hessian_len();
  Rng rng(seed);
  const auto f = batch_f<T, D>(rng, n, faults);
  const auto z = batch_z<T, D>(rng, n);
  std::vector<T> mu(n, T(1e5));
  mu[3] = 0;
  if (faults) mu[23] = -1;
  ampm::Options opt;
  opt.method(D == 3 ? AMPM_METHOD_MCADAMS : 0).sweeps(D == 3 ? 5 : 0);
  using V = std::vector<T>;
  V w1 = sentinels<T>(n * M), c1 = w1, w2 = w1, c2 = w1;
  V wp = sentinels<T>(n * L), cp = wp;
  std::vector<V*> W1{&w1}, C1{&c1}, W2{&w1, &w2}, C2{&c1, &c2};
  auto reset = [&] {
    for (V* v : {&w1, &c1, &w2, &c2}) std::fill(v->begin(), v->end(), sentinel<T>());
    std::fill(wp.begin(), wp.end(), sentinel<T>());
    std::fill(cp.begin(), cp.end(), sentinel<T>());
  };
  // span overloads (vectors convert to spans) and pointer overloads
  SAME_BATCH("ahat_batch", W1, C1, K::ahat_batch(mu, f, w1),
             A::ahat_batch(n, mu.data(), f.data(), c1.data(), &ffc));
  reset();
  SAME_BATCH("ahat_batch ptr", W1, C1, K::ahat_batch(n, mu.data(), f.data(), w1.data()),
             A::ahat_batch(n, mu.data(), f.data(), c1.data(), &ffc));
  reset();
  SAME_BATCH("ahat_batch_ex", W1, C1, K::ahat_batch(opt, mu, f, w1),
             A::ahat_batch_ex(&opt.c(), n, mu.data(), f.data(), c1.data(), &ffc));
  reset();
  SAME_BATCH("chat_z_batch", W1, C1, K::chat_z_batch(mu, f, z, w1),
             A::chat_z_batch(n, mu.data(), f.data(), z.data(), c1.data(), &ffc));
  reset();
  SAME_BATCH("chat_z_batch_ex", W1, C1, K::chat_z_batch(opt, mu, f, z, w1),
             A::chat_z_batch_ex(&opt.c(), n, mu.data(), f.data(), z.data(), c1.data(), &ffc));
  reset();
  SAME_BATCH("chat_z_psd_batch", W1, C1, K::chat_z_psd_batch(mu, f, z, w1),
             A::chat_z_psd_batch(n, mu.data(), f.data(), z.data(), c1.data(), &ffc));
  reset();
  SAME_BATCH("ahat_chat_z_batch", W2, C2, K::ahat_chat_z_batch(mu, f, z, w1, w2),
             A::ahat_chat_z_batch(n, mu.data(), f.data(), z.data(), c1.data(), c2.data(), &ffc));
  reset();
  SAME_BATCH("ahat_chat_z_batch (chat_z NULL)", W2, C2,
             K::ahat_chat_z_batch(mu, f, nullptr, w1, nullptr),
             A::ahat_chat_z_batch(n, mu.data(), f.data(), nullptr, c1.data(), nullptr, &ffc));
  reset();
  SAME_BATCH("ahat_chat_z_batch (both NULL)", W2, C2,
             K::ahat_chat_z_batch(mu, f, z, nullptr, nullptr),
             A::ahat_chat_z_batch(n, mu.data(), f.data(), z.data(), nullptr, nullptr, &ffc));
  reset();
  std::vector<V*> WP{&w1, &wp}, CP{&c1, &cp};
  SAME_BATCH("hessian_prepare_batch", WP, CP, K::hessian_prepare_batch(mu, f, w1, wp),
             A::hessian_prepare_batch(n, mu.data(), f.data(), c1.data(), cp.data(), &ffc));
  for (bool psd : {false, true}) {
    std::fill(w2.begin(), w2.end(), sentinel<T>());
    std::fill(c2.begin(), c2.end(), sentinel<T>());
    std::vector<V*> WA{&w2}, CA{&c2};
    SAME_BATCH(psd ? "hessian_apply_batch psd" : "hessian_apply_batch", WA, CA,
               K::hessian_apply_batch(wp, z, w2, psd),
               A::hessian_apply_batch(n, cp.data(), z.data(), c2.data(), psd ? 1 : 0, &ffc));
    std::fill(w2.begin(), w2.end(), sentinel<T>());
    std::fill(c2.begin(), c2.end(), sentinel<T>());
    SAME_BATCH("hessian_apply_batch ptr", WA, CA,
               K::hessian_apply_batch(n, wp.data(), z.data(), w2.data(), psd),
               A::hessian_apply_batch(n, cp.data(), z.data(), c2.data(), psd ? 1 : 0, &ffc));
  }
  if (faults) {
    // first failure: index 3 has mu = 0 (valid), 5 is NaN.
    const auto b = K::ahat_batch(mu, f, w1);
    AMPM_CHECK(ck, b.code() == AMPM_ERR_NON_FINITE && b.first_failed == 5, "%s first failure %s/%zu",
               name, b.name(), b.first_failed);
  }
  // NULL spans with n > 0: C's AMPM_ERR_NULL_POINTER, first_failed 0.
  reset();
  SAME_BATCH("ahat_batch NULL f", W1, C1, K::ahat_batch(mu, nullptr, w1),
             A::ahat_batch(n, mu.data(), nullptr, c1.data(), &ffc));
  // Sizes that disagree: AMPM_ERR_INVALID_ARGUMENT, first_failed 0, nothing written.
  auto expect_size_error = [&](const char* label, ampm::BatchStatus b) {
    AMPM_CHECK(ck, b.code() == AMPM_ERR_INVALID_ARGUMENT && b.first_failed == 0 &&
                       all_sentinel(w1.data(), w1.size()) && all_sentinel(w2.data(), w2.size()) &&
                       all_sentinel(wp.data(), wp.size()),
               "%s size mismatch %s: %s/%zu", name, label, b.name(), b.first_failed);
  };
  reset();
  const ampm::span<const T> fshort(f.data(), f.size() - 1), zshort(z.data(), z.size() - M);
  const ampm::span<T> w1long(w1.data(), w1.size()), w1short(w1.data(), w1.size() - M);
  expect_size_error("ahat f", K::ahat_batch(mu, fshort, w1));
  expect_size_error("ahat out", K::ahat_batch(mu, f, w1short));
  expect_size_error("ahat_ex out", K::ahat_batch(opt, mu, f, w1short));
  expect_size_error("chat_z z", K::chat_z_batch(mu, f, zshort, w1));
  expect_size_error("chat_z_ex z", K::chat_z_batch(opt, mu, f, zshort, w1));
  expect_size_error("chat_z_psd z", K::chat_z_psd_batch(mu, f, zshort, w1));
  expect_size_error("ahat_chat_z chat_z", K::ahat_chat_z_batch(mu, f, z, w1, w1short));
  expect_size_error("prepare slots",
                    K::hessian_prepare_batch(mu, f, w1, ampm::span<T>(wp.data(), wp.size() - 1)));
  expect_size_error("apply z not whole",
                    K::hessian_apply_batch(wp, ampm::span<const T>(z.data(), z.size() - 1), w2, false));
  expect_size_error("apply out", K::hessian_apply_batch(wp, z, w1short, false));
  (void)w1long;
}
#undef SAME_BATCH

// ---- Eigen ---------------------------------------------------------------------------------

template <class T, int D>
void test_eigen(const char* name, std::uint64_t seed) {
  using K = ampm::Kernels<T, D>;
  using M = Eigen::Matrix<T, D, D>;
  Rng rng(seed);
  const auto fs = batch_f<T, D>(rng, 24, true);
  const auto zs = batch_z<T, D>(rng, 24);
  for (int c = 0; c < 24; ++c) {
    const M f = Eigen::Map<const M>(&fs[static_cast<std::size_t>(c) * D * D]);
    const M z = Eigen::Map<const M>(&zs[static_cast<std::size_t>(c) * D * D]);
    const T mu = c == 7 ? T(-2) : T(3e4);
    auto bits = [](const auto& a, const auto& b) {
      return std::memcmp(a.data(), b.data(), sizeof(T) * static_cast<std::size_t>(a.size())) == 0;
    };
    M e = M::Constant(sentinel<T>()), p = e;
    bool ok = (ampm::ahat(mu, f, e) == K::ahat(mu, f.data(), p.data())) && bits(e, p);
    auto pr = ampm::ahat(mu, f);
    M p0 = M::Zero();
    ok = ok && pr.first == K::ahat(mu, f.data(), p0.data()) && bits(pr.second, p0);
    e.setConstant(sentinel<T>()), p.setConstant(sentinel<T>());
    ok = ok && ampm::chat_z(mu, f, z, e) == K::chat_z(mu, f.data(), z.data(), p.data()) && bits(e, p);
    auto pc = ampm::chat_z(mu, f, z);
    p0.setZero();
    ok = ok && pc.first == K::chat_z(mu, f.data(), z.data(), p0.data()) && bits(pc.second, p0);
    auto pp = ampm::chat_z_psd(mu, f, z);
    p0.setZero();
    ok = ok && pp.first == K::chat_z_psd(mu, f.data(), z.data(), p0.data()) && bits(pp.second, p0);
    e.setConstant(sentinel<T>()), p.setConstant(sentinel<T>());
    ok = ok && ampm::b_z(f, z, e) == K::b_z(f.data(), z.data(), p.data()) && bits(e, p);
    e.setConstant(sentinel<T>()), p.setConstant(sentinel<T>());
    ok = ok && ampm::z_b(f, z, e) == K::z_b(f.data(), z.data(), p.data()) && bits(e, p);
    T en = sentinel<T>(), pn = sentinel<T>();
    ok = ok && ampm::energy_hat(mu, f, en) == K::energy_hat(mu, f.data(), &pn) &&
         std::memcmp(&en, &pn, sizeof(T)) == 0;
    auto pe = ampm::energy_hat(mu, f);
    pn = 0;
    ok = ok && pe.first == K::energy_hat(mu, f.data(), &pn) && std::memcmp(&pe.second, &pn, sizeof(T)) == 0;
    Eigen::Matrix<T, D * D, D * D> h1, h2;
    h1.setConstant(sentinel<T>()), h2.setConstant(sentinel<T>());
    ok = ok && ampm::chat_matrix(mu, f, h1) == K::chat_matrix(mu, f.data(), h2.data()) && bits(h1, h2);
    ok = ok && ampm::chat_psd_matrix(mu, f, h1) == K::chat_psd_matrix(mu, f.data(), h2.data()) &&
         bits(h1, h2);
    M u1, v1, u2, v2;
    Eigen::Matrix<T, D, 1> s1, s2;
    u1.setConstant(sentinel<T>()), v1 = u1, u2 = u1, v2 = u1, s1.setConstant(sentinel<T>()), s2 = s1;
    ok = ok && ampm::svd(f, u1, s1, v1) == K::svd(f.data(), u2.data(), s2.data(), v2.data()) &&
         bits(u1, u2) && bits(s1, s2) && bits(v1, v2);
    u1.setConstant(sentinel<T>()), v1 = u1, u2 = u1, v2 = u1;
    ok = ok && ampm::polar(f, u1, v1) == K::polar(f.data(), u2.data(), v2.data()) && bits(u1, u2) &&
         bits(v1, v2);
    AMPM_CHECK(ck, ok, "%s Eigen overloads, case %d", name, c);
  }
}

}  // namespace

int main() {
  test_status();
  test_exceptions();
  test_single<float, 2>("2D f32", 101);
  test_single<float, 3>("3D f32", 102);
  test_single<double, 2>("2D f64", 103);
  test_single<double, 3>("3D f64", 104);
  for (bool faults : {false, true}) {
    test_batch<float, 2>("2D f32", 201, faults);
    test_batch<float, 3>("3D f32", 202, faults);
    test_batch<double, 2>("2D f64", 203, faults);
    test_batch<double, 3>("3D f64", 204, faults);
  }
  test_eigen<float, 2>("2D f32", 301);
  test_eigen<float, 3>("3D f32", 302);
  test_eigen<double, 2>("2D f64", 303);
  test_eigen<double, 3>("3D f64", 304);
  // set_isa / isa: the same answers as C.
  const std::uint32_t was = ampm_isa();
  AMPM_CHECK(ck, ampm::isa() == was, "isa()");
  AMPM_CHECK(ck, ampm::set_isa(99) == ampm_set_isa(99) && ampm::set_isa(99) == AMPM_ERR_INVALID_ARGUMENT,
             "set_isa(99)");
  AMPM_CHECK(ck, ampm::set_isa(AMPM_ISA_SCALAR).ok() && ampm::isa() == AMPM_ISA_SCALAR, "set_isa scalar");
  AMPM_CHECK(ck, ampm::set_isa(was).ok() && ampm::isa() == was, "restore isa");
  ck.summary("test_hpp");
  return ck.exit_code();
}
