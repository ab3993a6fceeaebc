// The MPM particle transfers from C++/Eigen, through the C ABI only:
//   ampm_stencil_<d>_<p>, ampm_node_range_<d>_<p>, ampm_p2g_<d>_<p> (collocated and MAC face
//   grids), ampm_g2p_update_<d>_<p>, ampm_g2p_update_mac_<d>_<p>, ampm_force_prepare_<d>_<p> +
//   ampm_force_apply_<d>_<p> (exact and PSD-projected), ampm_pressure_<d>_<p>
// against an independent long-double Eigen implementation of the same updates written here
// from the papers, sharing no code with the library. The host owns dense grid arrays over a
// node box (x fastest, or an interleaved node struct with a reversed axis), points the views'
// channels at them, and the reference computes the same node sums and particle updates:
//   - B-spline stencils from the textbook piecewise formulas, positions x_i = (base + o)·h
//     (face grids shifted by h/2), derivatives by the chain rule;
//   - APIC (Jiang et al. 2015): m_i = Σ w m, p_i = Σ w m (v + C (x_i − x_p)), v = Σ w v_i,
//     C = (Σ w v_i (x_i − x_p)ᵀ) / (κ h²), ∇v = Σ v_i ∇w_iᵀ; on a MAC grid component a, row a
//     of C and row a of ∇v from face grid a;
//   - the stress from common.hpp's `Reference<D>` (Â of the seed's index formulas) plus the
//     dilational P_λ = λ(J − 1) J F⁻ᵀ, node force f_i = Σ −V⁰ P Fᵀ ∇w;
//   - F_E ← (I + Δt∇v) F_E with the remedy (I + 2⁻ᵏΔt∇v)^(2ᵏ), Eigen::JacobiSVD for the snow
//     clamp; a liquid keeps only its volume history: F_E ← J_E^(1/d) I, F_P ← J_P^(1/d) I;
//   - heat by the enthalpy method: e = c_s (T − T_m) below the melting point, U at it,
//     L + c_l (T − T_m) above; e += q, then back to (T, U, phase) with the buffer's hysteresis;
//   - the force differential from `Reference<D>::chat_z` plus δP_λ differentiated with
//     inverses (δ(F⁻ᵀ) = −F⁻ᵀ δFᵀ F⁻ᵀ), not the library's rotated-basis form; its projection
//     onto the negative semi-definite part as the eigen-decomposition (Eigen's
//     SelfAdjointEigenSolver in long double) of the whole d²×d² particle operator G ↦ M(G),
//     dilational part included, with positive eigenvalues set to 0 (the spectral projection is
//     unique, so it equals the library's block-by-block projection in the basis of F_E).
//
// Tolerance: C·ε·scale with ε of the precision under test and `scale` the sum of the magnitudes
// of the terms summed (stated per check). Every library quantity is a short chain (≲ 30
// operations, sums over ≤ 64 stencil nodes) of backward-stable steps on well-conditioned data
// (κ(F_E) ≤ 1.3), so C = 64 + 2·K^d bounds the accumulated rounding of one particle's
// contribution; a node sums the contributions of at most n particles, which adds n·ε relative
// to the sum of their magnitudes (recursive summation), so node sums get C + n. The stress and
// the Hessian go through an SVD and Ĉ's four terms, so they get the 32·ε·κ of
// test_hessian_eigen.cpp times 8 (the products with F_E, ∇w and the sums over the stencil):
// 256, plus n for the node sums. The NSD projection is 1-Lipschitz in the Frobenius norm
// (for symmetric matrices, X ↦ min(X, 0) inherits the Lipschitz constant of the scalar map), so
// the projected differential keeps the tolerance of the exact one.
//
// This file holds run() (one case through every check, in order) and main(); the parts are in
// c_tests/particle_eigen/: reference.hpp (the independent reference: stencils, stress, force
// differential), update.hpp (the reference particle updates), host.hpp (the host's grid,
// channels and SoA particles), case.hpp (one case: sizes, tolerances, material, particles) and
// the checks by what they test: checks_stencil.hpp, checks_p2g.hpp (collocated and MAC face
// P2G), checks_force.hpp (force differential), checks_pressure.hpp and checks_g2p.hpp (G2P and
// the particle update, collocated and MAC).
#include "particle_eigen/case.hpp"
#include "particle_eigen/checks_force.hpp"
#include "particle_eigen/checks_g2p.hpp"
#include "particle_eigen/checks_p2g.hpp"
#include "particle_eigen/checks_pressure.hpp"
#include "particle_eigen/checks_stencil.hpp"

#include <vector>

using namespace ampm_test;

namespace {

/// One case (scalar T, dimension D, with or without the pressure solve) through every check,
/// in the order of their calls to the library.
template <class T, int D>
void run(Checker& ck, bool pressure_solve) {
  Case<T, D> cs(ck, pressure_solve);
  cs.check_stencils();
  const std::vector<std::vector<T>> grid_a = cs.check_p2g();
  cs.check_p2g_interleaved(grid_a);
  cs.check_p2g_impulse(grid_a);
  cs.check_stress();
  cs.check_p2g_faces();
  cs.check_p2g_outside_grid();
  cs.check_force_differential();
  cs.check_pressure();
  cs.check_g2p();
}

}  // namespace

int main() {
  Checker ck;
  std::vector<std::uint32_t> isas{AMPM_ISA_SCALAR};
  for (std::uint32_t isa : simd_isas()) isas.push_back(isa);
  for (std::uint32_t isa : isas) {
    const IsaRestore keep;
    AMPM_CHECK_STATUS(ck, ampm_set_isa(isa), AMPM_OK);
    std::printf("instruction set %s\n", isa_name(isa));
    for (bool ps : {false, true}) {
      run<float, 2>(ck, ps);
      run<double, 2>(ck, ps);
      run<float, 3>(ck, ps);
      run<double, 3>(ck, ps);
    }
  }
  ck.summary("test_particle_eigen");
  return ck.exit_code();
}
