// An MPM host written against include/ampm.h only (no Eigen, no test helpers): the explicit
// time step loop a C or C++ engine runs with the particle API, in 2D and 3D, f32 and f64, and
// the conservation laws that loop must keep.
//
// The host owns its grid: each step it asks ampm_node_range_* for the node box its particles
// reach (its lower corner moves and may be negative), allocates dense x-fastest arrays over it,
// zeroes them and points the view channels at them. One step:
//   P2G (ampm_p2g_*, impulse_dt = 0, separate force channels) → grid update
//   v_i = (p_i + Δt f_i)/m_i (no gravity, no boundaries: free flight) → G2P (ampm_g2p_update_*).
//
// Asserted every step (ε of the precision; A = K^d stencil nodes; n_add = the most particles
// whose stencils share one node, counted from ampm_stencil_* each step):
//   - mass: Σ_i m_i = Σ_p m_p. Each particle's weights sum to 1 up to (A + 6d)·ε (per-axis
//     weights of ~4 operations, products of d factors, w·m), and a node sums ≤ n_add terms
//     (recursive summation, n_add·ε of the sum of magnitudes): (n_add + A + 6d)·ε·Σ_p m_p.
//   - momentum, stage by stage, per component a, with S_a = Σ_p m_p (|v_pa| + 3.5 h Σ_b |C_ab|)
//     (|x_i − x_p| ≤ 3.5 h per axis in the library's q0 + m C h o form, |fx| ≤ 1.5, o ≤ 2) and
//     F_a = Σ_p Σ_i |f_ip,a| (measured by a one-particle P2G of each particle into a scratch
//     view of its own stencil):
//       P2G      |Σ_i p_ia − Σ_p m_p v_pa| ≤ c_P·ε·S_a,   c_P = n_add + A + 6d + 8
//                (Σ_i w_i (x_i − x_p) = 0 for B-splines);
//       forces   |Σ_i f_ia| ≤ c_P·ε·F_a  (Σ_i ∇w_i = 0);
//       impulse  P2G with impulse_dt = Δt and no force channel gives p + Δt f:
//                Σ_i |p'_ia − (p_ia + Δt f_ia)| ≤ 2(c_P + 2)·ε·(S_a + Δt F_a);
//       G2P      |Σ_p m_p v'_pa − Σ_i m_i v_ia| ≤ (n_add + A + 4)·ε·Σ_i m_i |v_ia|
//                (v'_p = Σ_i w_ip v_i, and Σ_p w_ip m_p = m_i up to n_add·ε);
//     and over the run |P_t − P_0| ≤ Σ_steps c_step·ε·(S_a + Δt F_a),
//     c_step = 2 n_add + 2A + 6d + 13 (the stages above plus the 3 roundings of the grid
//     update): ε × steps × Σ|m v| with the operation counts made explicit.
//   - J_E·J_P > 0 and every particle field finite.
//
// Heat (AMPM_MODEL_THERMAL, no phase change), PIC (flip = 0) and FLIP (flip = 1). The host's
// heat step, written out: T_i = thermal_energy_i / heat_capacity_i, κ_i = conductivity_i / m_i,
// material fraction θ_i = min(1, m_i/(ρ h^d)), face coefficients k_ij = h^(d−2)·½(κ_i + κ_j)·
// min(θ_i, θ_j) between face neighbours that both have mass (no flux elsewhere: an insulated
// box), and explicit conservative steps on the node energies E_i = C_i T_i:
//   Φ_ij = Δt_h k_ij (T_j − T_i), E_i += Φ_ij, E_j −= Φ_ij,
// with Δt_h = Δt/n_sub ≤ ½ min_i C_i/Σ_j k_ij (monotone: each new T_i is a convex combination).
// What is conserved, exactly in exact arithmetic, with the same weights w_ip in P2G and G2P
// (G2P samples before it moves the particle) and c_p fixed (no phase change):
//   P2G       Σ_i E_i = Σ_i Σ_p w_ip m_p c_p T_p = Σ_p m_p c_p T_p          (Σ_i w_ip = 1);
//   diffusion Σ_i E_i unchanged (each face flux is added once and subtracted once);
//   G2P, PIC  Σ_p m_p c_p T'_p = Σ_p m_p c_p Σ_i w_ip T_i = Σ_i C_i T_i = Σ_i E_i^new;
//   G2P, FLIP Σ_p m_p c_p (T_p + Σ_i w_ip (T_i^new − T_i^old))
//             = Σ_p m c T_p + Σ_i (E_i^new − E_i^old) = Σ_i E_i^new as well.
// So PIC G2P of temperature does conserve the total heat here: it smooths (the spread shrinks,
// asserted as the max principle max/min T non-increasing/non-decreasing for PIC), it does not
// lose heat. Bounds with H = Σ_p m c T_p (T > 0): P2G (n_add + A + 6d + 4)·ε·H; diffusion
// (2d + 1)·ε·(Σ_i E_i + Σ|Φ|) per substep; G2P (2 n_add + A + 6d + 10)·ε·H.
//
// Phase change (AMPM_MODEL_PHASE_CHANGE): an ice block at 260 K; the host's heat step also
// couples every massive node to a warm ambient at T_amb across each face whose neighbour has
// no mass (Φ = Δt_h h^(d−2) κ_i θ_i (T_amb − T_i)) and records the heat Q_in it injects. The
// library turns the grid's temperature change into q_p = c_phase (T*_p − T_p) (J/kg) and spends
// it on the enthalpy e(T, U, phase) = c_s (T − T_m) (solid below T_m), U (at T_m),
// L + c_l (T − T_m) (liquid above), i.e. m Δe = m (c_s ΔT_s + ΔU + c_l ΔT_l) across phase
// switches. The host computes T*_p itself from ampm_stencil_* weights and asserts per particle
// |Δe − q| ≤ ε [(2A + 28) c T_scale + 14 L] (its T* and the library's, (A + 4)·ε·T_scale each;
// q, 2 roundings; ≤ 4 segments of ≤ 3 roundings in the library; the host's e, 2 each side), and
// globally Σ_p m_p Δe_p = Q_in (PIC: Σ_p m c T*_p = Σ_i E_i^new as above), with the grid-side
// bounds added. Some particles must melt.
//
// Sizes: a block of 2 particles per cell per axis (spacing h/2), 24² (2D) or 10³ (3D)
// particles, 40 steps (the ice block 16² or 8³, 60 steps); a few seconds in Release, most of it
// in the one-particle P2G calls that measure Σ|f|.
//
// The parts are in c_tests/host_loop/: check.hpp (CHECK, CHECK_OK), host.hpp (the C symbols,
// the host's particles and grid), scene.hpp (the scenes and the block), run.hpp (one run's
// state), mechanics.hpp (P2G, the grid update, G2P and their checks) and heat.hpp (the host's
// heat step and the heat and phase-change checks).
#include "host_loop/check.hpp"
#include "host_loop/host.hpp"
#include "host_loop/scene.hpp"
#include "host_loop/run.hpp"
#include "host_loop/mechanics.hpp"
#include "host_loop/heat.hpp"

#include <chrono>
#include <cstdio>
#include <vector>

namespace {

/// One run of the host loop; `thermal` selects the heat checks, `melt` the phase-change ones.
template <class T, int D>
void run(const Scene& s, const char* label) {
  using A = Api<T, D>;
  const auto t_start = std::chrono::steady_clock::now();
  Run<T, D> r(s, label);
  for (int step = 0; step < s.steps; ++step) {
    // ---- the node box and the host's arrays ----
    const int n_add = node_box(r);
    // ---- P2G ----
    p2g(r);
    check_p2g(r, step, n_add, force_magnitudes(r));
    // ---- grid update: free flight ----
    grid_update(r);
    // ---- heat on the grid ----
    Heat heat;
    if (r.thermal) heat_step(r, step, n_add, heat);
    // ---- the host's own T*_p and q_p (phase change), before G2P ----
    std::vector<ld> q_host(r.n, 0), e_before(r.n, 0);
    if (r.melt) host_t_star(r, q_host, e_before);
    // ---- G2P ----
    Vec3 grid_mv, grid_mv_abs;
    g2p(r, grid_mv, grid_mv_abs);
    // ---- after the step ----
    check_particles(r, step, n_add, grid_mv, grid_mv_abs);
    if (r.thermal && !r.melt) check_heat(r, step, n_add, heat);
    if (r.melt) check_melt(r, step, n_add, heat, q_host, e_before);
  }
  if (r.melt) check_melted(r);
  std::printf("  %s %s: %zu particles, %d steps, %.2f s\n", A::name, label, r.n, s.steps,
              std::chrono::duration<double>(std::chrono::steady_clock::now() - t_start).count());
}

template <class T, int D>
void all() {
  Scene mech;
  mech.model = 0;
  mech.per_axis = D == 2 ? 24 : 10;
  run<T, D>(mech, "elastic free flight");

  for (double flip : {0.0, 1.0}) {
    Scene heat = mech;
    heat.model = AMPM_MODEL_THERMAL;
    heat.k_s = 200;
    heat.flip = flip;
    run<T, D>(heat, flip == 0 ? "heat, PIC" : "heat, FLIP");
  }

  Scene ice;
  ice.model = AMPM_MODEL_THERMAL | AMPM_MODEL_PHASE_CHANGE;
  ice.per_axis = D == 2 ? 16 : 8;
  ice.k_s = ice.k_l = D == 2 ? 1000 : 400;
  ice.steps = 60;
  ice.c_s = 2, ice.c_l = 4, ice.latent = 40, ice.tm = 273;
  ice.t_init = 260;
  ice.warm_ambient = true;
  ice.t_ambient = 500;
  ice.moving = false;
  ice.flip = 0;
  run<T, D>(ice, "ice block, warm ambient");
}

}  // namespace

int main() {
  all<float, 2>();
  all<double, 2>();
  all<float, 3>();
  all<double, 3>();
  std::printf("test_host_loop: %ld checks, %ld failures\n", g_checks, g_failures);
  return g_failures == 0 ? 0 : 1;
}
