// One backward-Euler step of an elastic block with conjugate gradients on the prepared force
// differential (ampm_force_prepare_3d_* once per Newton step, ampm_force_apply_3d_* once per
// CG iteration), 3D, f64 and f32, the host owning its grid arrays.
//
// The step (Stomakhin et al. 2013, §4.2; the apply's documentation): P2G gives node masses m_i,
// momenta p_i and stress forces f_i; v*_i = (p_i + Δt f_i)/m_i; then
//   (M − Δt² K) v = M v*,   (A v)_i = m_i v_i − Δt·df_i,   df = apply(du = Δt·v),
// on the nodes with mass (the unknowns; du = 0 elsewhere). With AMPM_MODEL_PSD_HESSIAN the
// stiffness K = ∂f/∂x is symmetric negative semi-definite, so A is symmetric positive definite.
// CG is preconditioned by M (Jacobi on the mass): the preconditioned operator M⁻¹A is
// self-adjoint in the M inner product with spectrum in [1, λ_max].
//
// Asserted (ε of the precision; A_K = 27 stencil nodes; n_add = the most particles sharing a
// node; d = 3):
//   - per particle, the operator G ↦ M_p(G) (node force differential M_p ∇w_i for
//     G = Σ_j du_j ∇w_jᵀ), probed through one-particle applies with du_j = e_a (x_j − x_p)_b
//     (then G = e_a e_bᵀ, since Σ_j ∇w_j (x_j − x_p)ᵀ = I) and read back as
//     M = Σ_i df_i (x_i − x_p)ᵀ: the 9×9 matrix S_p is symmetric and, with the PSD option,
//     negative semi-definite, to c_S·ε·‖S_p‖_F with c_S = 4(A_K + 8d)·2√d (the probe's and the
//     read-back's sums over 27 nodes, |∇w||x_i − x_p| ≤ 2√d, and the apply's ≈ 8d operations);
//   - A symmetric: |⟨u, A w⟩ − ⟨w, A u⟩| ≤ c_g·ε·(Σ_i m_i|u_i||w_i| + Δt² Σ_p ‖S_p‖_F g_p(u)
//     g_p(w)), g_p(u) = Σ_j |u_j||∇w_jp|, c_g = 2(n_add + A_K + 8d + 8), for random u, w;
//   - A positive definite on random u: ⟨u, A u⟩ − ⟨u, M u⟩ = −Δt²⟨u, K u⟩ ≥ −(that bound);
//   - CG's recursive residual reaches ‖r‖_(M⁻¹) ≤ tol·‖b‖_(M⁻¹) (tol 1e-8 in f64, 1e-4 in
//     f32) within k_max = ⌈½√κ ln(2√κ ‖r_0‖/(tol ‖b‖))⌉ iterations (the CG bound
//     ‖r_k‖ ≤ 2√κ ((√κ − 1)/(√κ + 1))^k ‖r_0‖ in the M⁻¹ norm), where κ is bounded above by
//     Gershgorin: λ_max(M⁻¹A) ≤ 1 + Δt² max_i (√d/m_i) Σ_p ‖S_p‖_F |∇w_ip| Σ_j |∇w_jp|; and the
//     true residual ‖b − A v‖ (a fresh apply) is within tol plus the accumulated rounding gap
//     between the recursive and the true residual (Greenbaum 1997), bounded per iteration as in
//     Host::cg (implicit_cg/cg.hpp). In f64 that gap is ≲ 2e-9 and the check is sharp; in f32
//     at Δt = 20 h/c the worst-case gap reaches ~1 (ε·κ·c_g·iterations), so there the true
//     residual (printed, ~1.1–1.7e-4) is asserted only that loosely: ε·κ ≈ 1e-4 is the floor of
//     an f32 apply.
//   - the linearisation (exact Hessian, no projection) against central differences of the
//     force it linearises, the energy gradient f_i(x̂) = −V⁰ P(F̂) F_Eᵀ ∇w_i at
//     F̂ = (I + δ G_p) F_E, G_p = Σ_j du_j ∇w_jpᵀ (positions, hence stencils, unchanged; F_E in
//     the transposed factor is the prepared one): the host gets τ' = P(F̂) F̂ᵀ of each particle
//     from a one-particle P2G with F_E replaced by F̂ (τ' = −(1/V⁰) Σ_i f_i (x_i − x_p)ᵀ) and
//     assembles f_i(δ) = Σ_p −V⁰ τ'_p (I + δ G_p)⁻ᵀ ∇w_ip. FD(δ) = (f(+δ) − f(−δ))/(2δ):
//     ‖FD(δ) − apply(du)‖ ≤ 2·‖FD(2δ) − FD(δ)‖/3 (twice the Richardson estimate of the O(δ²)
//     truncation error of FD(δ)) + the rounding ‖c_τ·ε·Φ/δ + c_g·ε·Ψ‖, c_τ = 256 + 2√d·A_K
//     (the stress's 256·ε of ‖τ‖ + μ + λ ≤ 3(μ + λ) for these singular values, as in
//     test_particle_eigen.cpp, and the recovery's sum), node scales
//     Φ_i = Σ_p V⁰_p·3(μ + λ)·|∇w_ip| and Ψ_i = Σ_p ‖S_p‖_F g_p(du) |∇w_ip|; checked at strains
//     δ·‖G‖ = (c_τ ε)^(1/3)·2^j, j = 0..3. (The P2G force with F_E replaced, −V⁰ τ' ∇w_i, has
//     the extra first-order geometric term −V⁰ τ Gᵀ ∇w_i, not symmetric in du and not part of
//     the differential; its distance from the apply is printed.)
//   - a large step, Δt = 20× the explicit limit h/c, repeated: no NaN, J_E > 0, every CG
//     converges within its bound, and the mechanical energy E = Σ_p ½ m |v|² + V⁰ (Ψ̂_μ + Ψ_λ)
//     never exceeds its initial value: backward Euler with a definite stiffness is dissipative
//     (the linear step is a contraction in the energy norm), so energy cannot grow (the kinetic
//     energy grows only by taking the elastic energy the block starts with). An explicit step at
//     the same Δt is printed for contrast, not asserted.
//
// The parts are in c_tests/implicit_cg/: block.hpp (the host's particles and grid, the
// material, the block), host.hpp (the host's calls of one step), cg.hpp (the solver),
// operator.hpp (symmetry, definiteness, the linearisation) and large_steps.hpp.
#include "common.hpp"

#include "implicit_cg/block.hpp"
#include "implicit_cg/host.hpp"
#include "implicit_cg/cg.hpp"
#include "implicit_cg/operator.hpp"
#include "implicit_cg/large_steps.hpp"

namespace {

template <class T>
void run(Checker& ck) {
  const ld tol = sizeof(T) == 8 ? 1e-8L : 1e-4L;
  Setup<T> s;
  Rng rng(kSeed);
  Parts<T> p;
  make_block<T>(s, p, rng);
  Host<T> host(ck, s, p);
  const ld wave = std::sqrt((s.lambda + 2 * s.mu) / s.rho);
  const ld dt_cfl = s.h / wave;
  const T dt = static_cast<T>(4 * dt_cfl);
  const ld c_g_base = 8 + KD + 8 * D;

  Step<T> st;
  host.p2g(st, dt);
  const ld c_g = 2 * (st.n_add + c_g_base);

  // ---- the PSD operator: symmetric, positive definite ----
  host.prepare(st, true);
  check_symmetric_definite(ck, host, p, st, dt, c_g, rng);

  // ---- CG on the backward-Euler system ----
  std::array<std::vector<T>, 3> vnew;
  host.cg(st, dt, tol, vnew, "Δt = 4 h/c");

  // ---- the linearisation against central differences of the P2G force (exact Hessian) ----
  check_linearisation(ck, s, p, host, st, c_g, rng);

  // ---- large implicit steps ----
  check_large_steps(ck, s, p, dt_cfl, tol);

  // For contrast (printed, not asserted): symplectic Euler at the same large Δt.
  print_explicit_steps(s, p, dt_cfl);
}

}  // namespace

int main() {
  Checker ck;
  run<double>(ck);
  run<float>(ck);
  ck.summary("test_implicit_cg");
  return ck.exit_code();
}
