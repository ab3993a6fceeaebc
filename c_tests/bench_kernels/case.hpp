// One case (scalar, dimension): its inputs and output buffers, every call checked and compared
// before timing, and the timed calls that fill its row of the table.
#pragma once

#include "bench_kernels/agreement.hpp"
#include "bench_kernels/api.hpp"
#include "bench_kernels/eigen_baseline.hpp"
#include "bench_kernels/timing.hpp"
#include "bench_kernels/workload.hpp"

namespace {

struct Row {
  std::string name;
  double separate = NAN, combined = NAN, prepare = NAN, apply = NAN, apply_psd = NAN,
         eigen = NAN, floor = NAN;
  std::size_t floor_bytes = 0;  // bytes per particle moved by the memory floor
};

/// μ, F and Z of the workload rounded to T.
template <class T, int D>
struct Inputs {
  static constexpr std::size_t dd = D * D;
  explicit Inputs(const Workload& w) : n(w.n), mu(n), f(n * dd), z(n * dd) {
    for (std::size_t i = 0; i < n; ++i) mu.data()[i] = static_cast<T>(w.mu[i]);
    for (std::size_t k = 0; k < n * dd; ++k) {
      f.data()[k] = static_cast<T>(w.f[k]);
      z.data()[k] = static_cast<T>(w.z[k]);
    }
  }
  std::size_t n;
  Buffer<T> mu, f, z;
};

/// The outputs of the separate calls (the reference of every comparison), of the Eigen
/// baseline and of the memory floor; n_dd = n·d² scalars each.
template <class T>
struct SeparateOutputs {
  explicit SeparateOutputs(std::size_t n_dd)
      : sep_ahat(n_dd), sep_cz(n_dd), eig_ahat(n_dd), eig_cz(n_dd), floor_a(n_dd),
        floor_c(n_dd) {}
  Buffer<T> sep_ahat, sep_cz, eig_ahat, eig_cz, floor_a, floor_c;
};

/// The outputs of the combined, prepare and apply calls, of ampm_chat_z_psd_batch, and of the
/// calls with optional outputs left out; n_dd = n·d², n_plen = n·ampm_hessian_len.
template <class T>
struct CallOutputs {
  CallOutputs(std::size_t n_dd, std::size_t n_plen)
      : comb_ahat(n_dd), comb_cz(n_dd), prep_ahat(n_dd), prepared(n_plen), app_cz(n_dd),
        app_psd(n_dd), sep_psd(n_dd), only_ahat(n_dd), only_cz(n_dd), prepared2(n_plen),
        app_cz2(n_dd) {}
  Buffer<T> comb_ahat, comb_cz, prep_ahat, prepared, app_cz, app_psd;
  Buffer<T> sep_psd;
  Buffer<T> only_ahat, only_cz, prepared2, app_cz2;
};

/// The separate calls and the Eigen baseline, each checked (AMPM_OK, first_failed = n).
template <class T, int D>
void run_separate(const char* name, const Inputs<T, D>& in, SeparateOutputs<T>& o) {
  using A = Api<T, D>;
  const std::size_t n = in.n;
  std::size_t ff = n + 1;
  check_call(name, "ampm_ahat_batch",
             A::ahat_batch(n, in.mu.data(), in.f.data(), o.sep_ahat.data(), &ff), &ff, n);
  ff = n + 1;
  check_call(name, "ampm_chat_z_batch",
             A::chat_z_batch(n, in.mu.data(), in.f.data(), in.z.data(), o.sep_cz.data(), &ff),
             &ff, n);
  ff = eigen_batch<T, D>(n, in.mu.data(), in.f.data(), in.z.data(), o.eig_ahat.data(),
                         o.eig_cz.data());
  if (ff != n)
    fail(std::string(name) + " Eigen baseline: J <= 0 or not finite at particle " +
         std::to_string(ff));
}

/// The combined call, prepare + apply (psd = 0, 1), ampm_chat_z_psd_batch, and the optional
/// outputs (ahat or chat_z NULL, prepare without Â), each checked.
template <class T, int D>
void run_calls(const char* name, const Inputs<T, D>& in, CallOutputs<T>& o) {
  using A = Api<T, D>;
  const std::size_t n = in.n;
  const T* mu = in.mu.data();
  const T* f = in.f.data();
  const T* z = in.z.data();
  std::size_t ff = n + 1;
  check_call(name, "ampm_ahat_chat_z_batch",
             A::ahat_chat_z_batch(n, mu, f, z, o.comb_ahat.data(), o.comb_cz.data(), &ff), &ff,
             n);
  ff = n + 1;
  check_call(name, "ampm_hessian_prepare_batch",
             A::hessian_prepare(n, mu, f, o.prep_ahat.data(), o.prepared.data(), &ff), &ff, n);
  ff = n + 1;
  check_call(name, "ampm_hessian_apply_batch (psd = 0)",
             A::hessian_apply(n, o.prepared.data(), z, o.app_cz.data(), 0, &ff), &ff, n);
  ff = n + 1;
  check_call(name, "ampm_hessian_apply_batch (psd = 1)",
             A::hessian_apply(n, o.prepared.data(), z, o.app_psd.data(), 1, &ff), &ff, n);
  ff = n + 1;
  check_call(name, "ampm_chat_z_psd_batch",
             A::chat_z_psd_batch(n, mu, f, z, o.sep_psd.data(), &ff), &ff, n);
  // The optional outputs: ahat or chat_z NULL (Z NULL with it), prepare without Â.
  ff = n + 1;
  check_call(name, "ampm_ahat_chat_z_batch (chat_z = Z = NULL)",
             A::ahat_chat_z_batch(n, mu, f, nullptr, o.only_ahat.data(), nullptr, &ff), &ff, n);
  ff = n + 1;
  check_call(name, "ampm_ahat_chat_z_batch (ahat = NULL)",
             A::ahat_chat_z_batch(n, mu, f, z, nullptr, o.only_cz.data(), &ff), &ff, n);
  ff = n + 1;
  check_call(name, "ampm_hessian_prepare_batch (ahat = NULL)",
             A::hessian_prepare(n, mu, f, nullptr, o.prepared2.data(), &ff), &ff, n);
  ff = n + 1;
  check_call(name, "ampm_hessian_apply_batch (psd = 0, prepared without Â)",
             A::hessian_apply(n, o.prepared2.data(), z, o.app_cz2.data(), 0, &ff), &ff, n);
}

/// Every comparison of the case, in the order of the table (exits on a disagreement).
template <class T, int D>
void compare_all(const char* name, const Inputs<T, D>& in, const SeparateOutputs<T>& s,
                 const CallOutputs<T>& o, std::vector<Agreement>& agreements) {
  const std::size_t n = in.n;
  const T* mu = in.mu.data();
  const T* f = in.f.data();
  const T* z = in.z.data();
  agreements.push_back(agree<T, D>(name, "combined Â vs separate", n, o.comb_ahat.data(),
                                   s.sep_ahat.data(), f, z, mu));
  agreements.push_back(agree<T, D>(name, "combined Ĉ:Z vs separate", n, o.comb_cz.data(),
                                   s.sep_cz.data(), f, z, nullptr));
  agreements.push_back(agree<T, D>(name, "prepare Â vs separate", n, o.prep_ahat.data(),
                                   s.sep_ahat.data(), f, z, mu));
  agreements.push_back(agree<T, D>(name, "apply(psd = 0) Ĉ:Z vs separate", n, o.app_cz.data(),
                                   s.sep_cz.data(), f, z, nullptr));
  agreements.push_back(agree<T, D>(name, "apply(psd = 1) Ĉ⁺:Z vs ampm_chat_z_psd_batch", n,
                                   o.app_psd.data(), o.sep_psd.data(), f, z, nullptr));
  agreements.push_back(agree<T, D>(name, "combined, Â only, vs separate", n,
                                   o.only_ahat.data(), s.sep_ahat.data(), f, z, mu));
  agreements.push_back(agree<T, D>(name, "combined, Ĉ:Z only, vs separate", n,
                                   o.only_cz.data(), s.sep_cz.data(), f, z, nullptr));
  agreements.push_back(agree<T, D>(name, "apply(psd = 0) after prepare without Â vs separate",
                                   n, o.app_cz2.data(), s.sep_cz.data(), f, z, nullptr));
  agreements.push_back(agree<T, D>(name, "Eigen Â vs separate", n, s.eig_ahat.data(),
                                   s.sep_ahat.data(), f, z, mu));
  agreements.push_back(agree<T, D>(name, "Eigen Ĉ:Z vs separate", n, s.eig_cz.data(),
                                   s.sep_cz.data(), f, z, nullptr));
}

/// Times every call of the case (median of kReps runs, ns per particle) into `row`.
template <class T, int D>
void time_case(const char* name, const Inputs<T, D>& in, SeparateOutputs<T>& s,
               CallOutputs<T>& o, Row& row) {
  using A = Api<T, D>;
  const std::size_t n = in.n;
  const T* mu = in.mu.data();
  const T* f = in.f.data();
  const T* z = in.z.data();
  row.separate = time_per_particle("separate calls", name, n, kReps, [&](std::size_t* first) {
    const AmpmStatus s1 = A::ahat_batch(n, mu, f, s.sep_ahat.data(), first);
    if (s1 != AMPM_OK) return s1;
    return A::chat_z_batch(n, mu, f, z, s.sep_cz.data(), first);
  });
  row.combined = time_per_particle("combined", name, n, kReps, [&](std::size_t* first) {
    return A::ahat_chat_z_batch(n, mu, f, z, o.comb_ahat.data(), o.comb_cz.data(), first);
  });
  row.prepare = time_per_particle("prepare", name, n, kReps, [&](std::size_t* first) {
    return A::hessian_prepare(n, mu, f, o.prep_ahat.data(), o.prepared.data(), first);
  });
  row.apply = time_per_particle("apply (psd = 0)", name, n, kReps, [&](std::size_t* first) {
    return A::hessian_apply(n, o.prepared.data(), z, o.app_cz.data(), 0, first);
  });
  row.apply_psd = time_per_particle("apply (psd = 1)", name, n, kReps, [&](std::size_t* first) {
    return A::hessian_apply(n, o.prepared.data(), z, o.app_psd.data(), 1, first);
  });
  row.eigen = time_per_particle("Eigen baseline", name, n, kReps, [&](std::size_t* first) {
    *first = eigen_batch<T, D>(n, mu, f, z, s.eig_ahat.data(), s.eig_cz.data());
    return *first == n ? AMPM_OK : AMPM_ERR_NON_POSITIVE_J;
  });
  row.floor = time_per_particle("memory floor", name, n, kReps, [&](std::size_t* first) {
    memory_floor<T, D>(n, mu, f, z, s.floor_a.data(), s.floor_c.data());
    *first = n;
    return AMPM_OK;
  });
}

/// One case: every call checked and compared with the separate calls (always, before timing;
/// the comparisons appended to `agreements`), then, with `timing`, every call timed.
template <class T, int D>
Row run_case(const Workload& w, bool timing, std::vector<Agreement>& agreements) {
  using A = Api<T, D>;
  constexpr std::size_t dd = D * D;
  const std::size_t n = w.n;
  const char* name = A::name;

  const Inputs<T, D> in(w);
  SeparateOutputs<T> sep(n * dd);

  // ---- agreement (always, before timing) ----
  run_separate<T, D>(name, in, sep);
  const std::size_t plen = A::hessian_len();
  if (plen == 0) fail(std::string(name) + ": ampm_hessian_len returned 0");
  CallOutputs<T> calls(n * dd, n * plen);
  run_calls<T, D>(name, in, calls);
  compare_all<T, D>(name, in, sep, calls, agreements);

  Row row;
  row.name = name;
  row.floor_bytes = (1 + 4 * dd) * sizeof(T);
  if (!timing) return row;

  // ---- timing ----
  time_case<T, D>(name, in, sep, calls, row);
  return row;
}

}  // namespace
