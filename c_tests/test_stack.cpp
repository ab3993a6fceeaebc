// Stack use of the library's calls, against the bounds include/ampm.h states ("Stack.": the
// kernels at most 32 KiB, the particle calls at most 96 KiB): hosts run the library on
// job-system fibers with small stacks, so the bounds are part of the contract.
//
// Each call runs on a POSIX thread whose stack is a buffer this test allocates and paints with
// a byte pattern; after the thread ends, the lowest overwritten byte gives the thread's
// high-water mark. A thread that runs only the measuring lambda with a trivial call
// (ampm_isa) gives the baseline (thread start-up, TLS placed at the top of the buffer), which
// is subtracted. Calls, 2D and 3D, f32 and f64, on every instruction set the CPU accepts: single
// kernels (the Ĉ matrix with the PSD option, the SVD), the batch kernels (ahat_chat_z, hessian
// prepare and apply), P2G with every channel (momentum,
// force, and the three heat channels of a thermal material: the most node sums per particle),
// G2P with heat, force prepare and force apply. The stencils are quadratic and cubic.
// Skipped (ctest status 77) in AddressSanitizer builds: instrumented frames are larger by design.
#include <pthread.h>

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <array>
#include <cstring>
#include <functional>
#include <string>
#include <utility>
#include <vector>

#include "ampm.hpp"
#include "common.hpp"

namespace {

ampm_test::Checker g_ck;
#define CHECK(...) AMPM_CHECK(g_ck, __VA_ARGS__)

constexpr std::size_t kKernelBound = 32 * 1024;    // kernels, single and batch, as include/ampm.h states
constexpr std::size_t kParticleBound = 96 * 1024;  // p2g, g2p_update, force_prepare/apply
constexpr std::size_t kStack = 1024 * 1024;      // the painted thread stack
constexpr unsigned char kPaint = 0xA5;

/// High-water mark in bytes of a thread that runs `body` on a painted stack.
std::size_t high_water(const std::function<void()>& body) {
  void* mem = nullptr;
  if (posix_memalign(&mem, 4096, kStack) != 0) {
    std::fprintf(stderr, "test_stack: cannot allocate the stack\n");
    std::exit(2);
  }
  auto* bytes = static_cast<unsigned char*>(mem);
  std::memset(bytes, kPaint, kStack);
  pthread_attr_t attr;
  pthread_attr_init(&attr);
  pthread_attr_setstack(&attr, mem, kStack);
  pthread_t th;
  auto run = [](void* arg) -> void* {
    (*static_cast<const std::function<void()>*>(arg))();
    return nullptr;
  };
  if (pthread_create(&th, &attr, run, const_cast<std::function<void()>*>(&body)) != 0) {
    std::fprintf(stderr, "test_stack: cannot start a thread\n");
    std::exit(2);
  }
  pthread_join(th, nullptr);
  pthread_attr_destroy(&attr);
  std::size_t low = 0;
  while (low < kStack && bytes[low] == kPaint) ++low;
  std::free(mem);
  return kStack - low;
}

template <class T>
T jitter(std::size_t k) {  // deterministic, in [-0.5, 0.5)
  return static_cast<T>(static_cast<double>((k * 2654435761u) % 1000u) / 1000.0 - 0.5);
}

/// One scene of `n` particles in a block, its grid, and every call of the library on it.
template <class T, int D>
struct Scene {
  static constexpr std::size_t kM = static_cast<std::size_t>(D) * D;
  std::size_t n;
  unsigned kernel;
  T h = T(0.05), dt = T(1e-4);
  std::vector<T> x, v, c, fe, fp, m, v0, t, u;
  std::vector<unsigned char> ph;
  AmpmNodeBox box{};
  std::size_t nodes = 0;
  std::vector<T> mass, mom[D], force[D], hc, te, cond, vel[D], tn, to, du[D], df[D], slots;
  std::vector<T> mu, f, z, ahat, chat_z, prepared, applied;
  ampm::Material<T> mat;

  Scene(std::size_t per_axis, unsigned kern) : kernel(kern) {
    n = 1;
    for (int a = 0; a < D; ++a) n *= per_axis;
    x.resize(n * D), v.resize(n * D), c.assign(n * kM, 0), fe.assign(n * kM, 0), fp.assign(n * kM, 0);
    m.assign(n, T(1e-2)), v0.assign(n, T(1e-5)), t.assign(n, T(260)), u.assign(n, 0), ph.assign(n, 0);
    for (std::size_t p = 0; p < n; ++p) {
      std::size_t q = p;
      for (int a = 0; a < D; ++a) {
        x[p * D + a] = (T(4) + (T(q % per_axis) + T(0.5) + T(0.3) * jitter<T>(p * D + a)) * T(0.5)) * h;
        v[p * D + a] = jitter<T>(p + 7 * a);
        q /= per_axis;
      }
      for (int i = 0; i < D; ++i) {
        fe[p * kM + i * (D + 1)] = T(1) + T(0.05) * jitter<T>(p + i);
        fp[p * kM + i * (D + 1)] = T(1);
      }
    }
    mat = ampm::Material<T>()
              .mu(T(1e5))
              .lambda(T(1e5))
              .heat_capacity(T(2000))
              .conductivity(T(2))
              .liquid(ampm::PhaseParams<T>().mu(0).lambda(T(1e5)).heat_capacity(T(4000)).conductivity(T(0.6)))
              .melting_point(T(273))
              .latent_heat(T(3.3e5))
              .flip(T(0.95))
              .enable(AMPM_MODEL_THERMAL | AMPM_MODEL_PHASE_CHANGE | AMPM_MODEL_PSD_HESSIAN);
    const bool ok = ampm::node_range(kernel, AMPM_GRID_COLLOCATED, h, particles(), box).ok();
    CHECK(ok, "node_range");
    for (int a = 0; a < D; ++a) box.lo[a] -= 1, box.dims[a] += 2;
    nodes = ampm::node_count<D>(box);
    for (auto* g : {&mass, &hc, &te, &cond}) g->assign(nodes, 0);
    tn.assign(nodes, T(270)), to.assign(nodes, T(269.5));
    for (int a = 0; a < D; ++a) {
      mom[a].assign(nodes, 0), force[a].assign(nodes, 0), df[a].assign(nodes, 0);
      vel[a].resize(nodes), du[a].resize(nodes);
      for (std::size_t k = 0; k < nodes; ++k) vel[a][k] = T(0.1) * jitter<T>(k + a), du[a][k] = T(1e-6) * jitter<T>(3 * k + a);
    }
    slots.assign(n * ampm::force_slot_len<D>(), 0);
    mu.assign(n, T(1e5)), f = fe, z = fe, ahat.assign(n * kM, 0), chat_z.assign(n * kM, 0);
    prepared.assign(n * ampm::Kernels<T, D>::hessian_len(), 0), applied.assign(n * kM, 0);
  }
  ampm::Particles<T, D> particles() {
    ampm::Particles<T, D> p(n);
    p.x(x).v(v).affine(c).f_e(fe).f_p(fp).mass(m).volume0(v0).temperature(t).latent(u).phase(ph);
    return p;
  }
  /// The data pointers of per-axis arrays, as `T*` (outputs) or `const T*` (inputs).
  template <class P = T*>
  static std::array<P, D> ptrs(std::vector<T> (&a)[D]) {
    std::array<P, D> r{};
    for (int k = 0; k < D; ++k) r[static_cast<std::size_t>(k)] = a[k].data();
    return r;
  }

  /// The calls, each with its name and stack bound, to be measured one by one.
  struct Call {
    std::string name;
    std::size_t bound;
    std::function<bool()> run;
    template <class F>
    Call(const char* n, std::size_t b, F&& f) : name(n), bound(b), run(std::forward<F>(f)) {}
  };
  std::vector<Call> calls() {
    using K = ampm::Kernels<T, D>;
    const std::size_t kb = kKernelBound, pb = kParticleBound;
    std::vector<Call> r;
    r.emplace_back("chat_psd_matrix (single)", kb, [this] {
      std::vector<T> out(kM * kM);
      return K::chat_psd_matrix(mu[0], f.data(), out.data()).ok();
    });
    r.emplace_back("svd (single)", kb, [this] {
      T u_[kM], s_[D], v_[kM];
      return K::svd(f.data(), u_, s_, v_).ok();
    });
    r.emplace_back("ahat_chat_z_batch", kb, [this] {
      return K::ahat_chat_z_batch(n, mu.data(), f.data(), z.data(), ahat.data(), chat_z.data()).ok();
    });
    r.emplace_back("hessian_prepare_batch", kb, [this] {
      return K::hessian_prepare_batch(n, mu.data(), f.data(), nullptr, prepared.data()).ok();
    });
    r.emplace_back("hessian_apply_batch", kb, [this] {
      return K::hessian_apply_batch(n, prepared.data(), z.data(), applied.data(), true).ok();
    });
    r.emplace_back("p2g (momentum, force, heat)", pb, [this] {
      auto view = ampm::P2gView<T, D>::separate(box, mass.data(), ptrs(mom), ptrs(force));
      view.heat_capacity(hc.data()).thermal_energy(te.data()).conductivity(cond.data());
      return ampm::p2g(mat, kernel, AMPM_GRID_COLLOCATED, h, T(0), particles(), view).ok();
    });
    r.emplace_back("force_prepare", pb, [this] { return ampm::force_prepare(mat, particles(), ampm::span<T>(slots)).ok(); });
    r.emplace_back("force_apply", pb, [this] {
      const auto view = ampm::ForceView<T, D>::separate(box, ptrs<const T*>(du), ptrs(df));
      return ampm::force_apply(kernel, h, particles(), ampm::span<const T>(slots), view).ok();
    });
    r.emplace_back("g2p_update (heat)", pb, [this] {
      const auto view = ampm::G2pView<T, D>::separate(box, ptrs<const T*>(vel), tn.data(), to.data());
      return ampm::g2p_update(mat, kernel, h, dt, particles(), view).ok();
    });
    return r;
  }
};

template <class T, int D>
void measure(const char* name, std::size_t per_axis, std::size_t baseline, std::size_t& worst) {
  for (unsigned kernel : {AMPM_KERNEL_QUADRATIC, AMPM_KERNEL_CUBIC}) {
    Scene<T, D> s(per_axis, kernel);
    for (auto& call : s.calls()) {
      const char* what = call.name.c_str();
      bool ok = false;
      const std::size_t used = high_water([&] { ok = call.run(); });
      const std::size_t own = used > baseline ? used - baseline : 0;
      if (own > worst) worst = own;
      CHECK(ok, "%s %s kernel %u: status", name, what, kernel);
      CHECK(own <= call.bound, "%s %s kernel %u: %zu bytes of stack > %zu", name, what, kernel, own, call.bound);
      std::printf("  %s %-30s %s: %6zu bytes (bound %zu)\n", name, what,
                  kernel == AMPM_KERNEL_QUADRATIC ? "quadratic" : "cubic", own, call.bound);
    }
  }
}

}  // namespace

int main() {
#if defined(__SANITIZE_ADDRESS__)
  std::printf("test_stack: skipped, AddressSanitizer frames are larger by design\n");
  return 77;  // SKIP_RETURN_CODE (c_tests/CMakeLists.txt)
#endif
  // The painting must see a stack: the baseline thread uses some itself.
  const std::size_t baseline = high_water([] { (void)ampm_isa(); });
  CHECK(baseline > 0 && baseline < kKernelBound, "baseline %zu", baseline);
  std::printf("test_stack: baseline thread %zu bytes; per call, beyond it:\n", baseline);
  const std::uint32_t start_isa = ampm::isa();
  std::size_t worst = 0;
  int isas = 0;
  for (std::uint32_t isa : {AMPM_ISA_AVX512, AMPM_ISA_AVX2, AMPM_ISA_SCALAR}) {
    if (!ampm::set_isa(isa).ok()) continue;
    ++isas;
    std::printf(" instruction set %u\n", isa);
    measure<float, 3>("3D f32", 6, baseline, worst);
    measure<double, 3>("3D f64", 6, baseline, worst);
    measure<float, 2>("2D f32", 14, baseline, worst);
    measure<double, 2>("2D f64", 14, baseline, worst);
  }
  CHECK(isas >= 1 && ampm::set_isa(start_isa).ok(), "instruction sets run: %d", isas);
  // The measurement itself must be able to fail: a frame larger than the bound shows up.
  constexpr std::size_t kFrame = kParticleBound + 4096;
  const std::size_t big = high_water([] {
    volatile unsigned char frame[kFrame];
    for (std::size_t k = 0; k < kFrame; k += 512) frame[k] = 1;
    (void)frame[0];
  });
  CHECK(big >= baseline + kFrame - 512, "a %zu-byte frame measured as %zu", kFrame, big);
  std::printf("test_stack: largest call %zu bytes, %d instruction sets\n", worst, isas);
  g_ck.summary("test_stack");
  return g_ck.exit_code();
}
