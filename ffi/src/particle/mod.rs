//! C entry points of the MPM particle updates: P2G into the host's grid, G2P and the particle
//! update from it, the implicit force differential (prepare, apply), stencils and pressures.
//! The types' docs are the header's documentation of layouts, units and rules.
#![allow(clippy::missing_safety_doc, clippy::too_many_arguments)]
// The docs are the header's C text (`lo[a]`, `stride[0]`), not rustdoc links.
#![allow(rustdoc::broken_intra_doc_links)]

pub(crate) mod imp;

pub use crate::generated::fields::*;
pub use crate::generated::force::*;
pub use crate::generated::particle::*;

use core::ffi::{c_int, c_uchar, c_uint};

/// Model bit of AmpmMaterial.model: snow plasticity of solids (Stomakhin et al. 2013): the
/// singular values of F_E are clamped to [1 − theta_c, 1 + theta_s], the rest goes to F_P, and
/// mu, lambda harden by e^(xi (1 − J_P)).
pub const AMPM_MODEL_PLASTIC: c_uint = 1;
/// Model bit: heat transfer. P2G writes the heat channels; G2P reads node temperatures and
/// writes particle temperatures (PIC/FLIP blend with AmpmMaterial.flip).
pub const AMPM_MODEL_THERMAL: c_uint = 2;
/// Model bit: melting and freezing through the latent heat buffer U in [0, L] (requires
/// AMPM_MODEL_THERMAL; reads and writes the particles' latent and phase arrays).
pub const AMPM_MODEL_PHASE_CHANGE: c_uint = 4;
/// Model bit: the dilational energy Psi_lambda is left to the host's pressure solve (the P2G
/// force is deviatoric only, inv_lambda = 0 allowed); without it Psi_lambda is in the stress
/// force, which needs inv_lambda > 0.
pub const AMPM_MODEL_PRESSURE_SOLVE: c_uint = 8;
/// Model bit: the force differential is projected onto its negative semi-definite part, block
/// by block in the rotated basis of F_E (deviatoric and dilational parts together), so that the
/// backward-Euler matrix M − dt² K is positive definite and CG applies.
pub const AMPM_MODEL_PSD_HESSIAN: c_uint = 16;
/// Quadratic B-spline kernel: 3 nodes per axis, K^d = 9 (2D) or 27 (3D) stencil nodes.
pub const AMPM_KERNEL_QUADRATIC: c_uint = 2;
/// Cubic B-spline kernel: 4 nodes per axis, K^d = 16 (2D) or 64 (3D) stencil nodes.
pub const AMPM_KERNEL_CUBIC: c_uint = 3;
/// The collocated grid: nodes at i·h. A value 0 ≤ a < d selects the MAC face grid of velocity
/// component a instead: nodes at i·h along axis a and at (j + 1/2)·h along the other axes.
pub const AMPM_GRID_COLLOCATED: c_int = -1;
/// Phase code of a solid particle.
pub const AMPM_PHASE_SOLID: c_uchar = 0;
/// Phase code of a liquid particle.
pub const AMPM_PHASE_LIQUID: c_uchar = 1;
/// Scalars per particle of the prepared force differential, 2D: ampm_force_prepare_2d_* writes
/// n·AMPM_FORCE_SLOT_LEN_2D scalars (opaque to the host).
pub const AMPM_FORCE_SLOT_LEN_2D: usize = 11;
/// Scalars per particle of the prepared force differential, 3D.
pub const AMPM_FORCE_SLOT_LEN_3D: usize = 25;

/// Material parameters of one phase (SI units).
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct AmpmPhaseParams<T> {
    /// mu ≥ 0 (Pa) of the fixed corotated deviatoric energy; must be 0 for the liquid.
    pub mu: T,
    /// 1/lambda ≥ 0 (1/Pa) of Psi_lambda = lambda/2 (J_E − 1)²; 0 is incompressible (needs
    /// AMPM_MODEL_PRESSURE_SOLVE).
    pub inv_lambda: T,
    /// Specific heat capacity c > 0 (J/(kg·K)); read with AMPM_MODEL_THERMAL.
    pub heat_capacity: T,
    /// Thermal conductivity kappa ≥ 0 (W/(m·K)); read with AMPM_MODEL_THERMAL.
    pub conductivity: T,
}

/// What a scene models (AMPM_MODEL_* bits) and its parameters. Fields of parts that are off are
/// not read. Parameters are validated by every call (AMPM_ERR_NON_FINITE or
/// AMPM_ERR_INVALID_ARGUMENT for a value outside its domain); unknown model bits, or
/// PHASE_CHANGE without THERMAL, are whole-call errors (AMPM_ERR_INVALID_ARGUMENT).
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct AmpmMaterial<T> {
    /// OR of AMPM_MODEL_* bits.
    pub model: c_uint,
    /// Parameters of solid particles.
    pub solid: AmpmPhaseParams<T>,
    /// Parameters of liquid particles (mu = 0).
    pub liquid: AmpmPhaseParams<T>,
    /// Snow critical compression theta_c in [0, 1) (AMPM_MODEL_PLASTIC).
    pub critical_compression: T,
    /// Snow critical stretch theta_s ≥ 0 (AMPM_MODEL_PLASTIC).
    pub critical_stretch: T,
    /// Hardening xi ≥ 0 (AMPM_MODEL_PLASTIC).
    pub hardening: T,
    /// FLIP fraction alpha in [0, 1] of the temperature transfer, 0 = PIC (AMPM_MODEL_THERMAL).
    pub flip: T,
    /// Melting point T_m (K) (AMPM_MODEL_PHASE_CHANGE).
    pub melting_point: T,
    /// Specific latent heat L ≥ 0 (J/kg) (AMPM_MODEL_PHASE_CHANGE).
    pub latent_heat: T,
}

/// Particle data, structure of arrays, n particles, SI units.
///
/// Layouts: particle p's vector is at [d·p + a] (a = 0..d−1); its d×d matrices are column-major
/// at [d²·p + i + d·j] (entry (i, j)); scalars at [p].
///
/// Validity (checked per particle; a particle breaking a rule fails with the status given):
/// every field read is finite (AMPM_ERR_NON_FINITE); mass > 0 and volume0 > 0
/// (AMPM_ERR_INVALID_ARGUMENT); det F_E > 0 and det F_P > 0 (AMPM_ERR_NON_POSITIVE_J;
/// AMPM_ERR_OVERFLOW when a determinant is not representable); |x_a/h| < 2^30
/// (AMPM_ERR_INVALID_ARGUMENT); phase codes 0 or 1. With AMPM_MODEL_PHASE_CHANGE the thermal
/// state obeys: 0 ≤ U ≤ L; a solid has T ≤ T_m, a liquid T ≥ T_m; 0 < U < L only at T = T_m;
/// a solid below T_m has U = 0, a liquid above it U = L (AMPM_ERR_INVALID_ARGUMENT otherwise).
/// A call that returns AMPM_OK for a particle leaves it in a state that every later call
/// accepts.
///
/// A liquid keeps only its volume history: its F_E is J_E^(1/d)·I and its F_P is J_P^(1/d)·I.
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct AmpmParticles<T> {
    /// Positions x_p (m, relative to the grid origin), n·d.
    pub x: *mut T,
    /// Velocities (m/s), n·d.
    pub v: *mut T,
    /// APIC affine matrices C_p (1/s), n·d², column-major.
    pub affine: *mut T,
    /// Elastic deformation gradients F_E, n·d², column-major.
    pub f_e: *mut T,
    /// Plastic deformation gradients F_P, n·d² (identity for a purely elastic solid).
    pub f_p: *mut T,
    /// Masses m_p (kg), n.
    pub mass: *const T,
    /// Reference volumes V0_p (m³), n.
    pub volume0: *const T,
    /// Temperatures (K), n; read and written with AMPM_MODEL_THERMAL, else may be NULL.
    pub temperature: *mut T,
    /// Latent buffers U (J/kg), n; read and written with AMPM_MODEL_PHASE_CHANGE, else may be
    /// NULL.
    pub latent: *mut T,
    /// Phases (AMPM_PHASE_*), n; required with AMPM_MODEL_PHASE_CHANGE; NULL means all solid.
    pub phase: *mut c_uchar,
}

/// The nodes a grid view covers: grid indices lo[a] ≤ i_a < lo[a] + dims[a] on each axis a
/// (entries [2] are ignored in 2D). A view may cover the whole grid, a block of it, or one MAC
/// face grid. A particle whose stencil (K nodes per axis from its base node, see
/// ampm_stencil_*) is not inside the box fails with AMPM_ERR_OUTSIDE_GRID and transfers
/// nothing; ampm_node_range_* gives the box a set of particles needs.
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct AmpmNodeBox {
    /// Grid index of the first node per axis.
    pub lo: [i32; 3],
    /// Nodes per axis (≥ 0).
    pub dims: [i32; 3],
}

/// One output scalar per node of a view's box: node i is at
/// data[(i_0 − lo_0)·stride[0] + (i_1 − lo_1)·stride[1] (+ (i_2 − lo_2)·stride[2] in 3D)].
/// Strides count scalars, not bytes, and may be negative. Separate arrays x-fastest use
/// stride = {1, nx, nx·ny}; an interleaved node struct of s scalars uses {s, s·nx, s·nx·ny}
/// with data pointing at the field in the first node. data = NULL: the channel is absent.
/// data must be valid for every node of the box.
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct AmpmChannel<T> {
    /// Address of node lo (NULL: absent).
    pub data: *mut T,
    /// Scalars between neighbouring nodes along each axis.
    pub stride: [isize; 3],
}

/// One input scalar per node of a view's box (read only); addressing as AmpmChannel.
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct AmpmConstChannel<T> {
    /// Address of node lo (NULL: absent).
    pub data: *const T,
    /// Scalars between neighbouring nodes along each axis.
    pub stride: [isize; 3],
}

/// Where ampm_p2g_* scatter-adds (+=): the host zeroes its channels before the first P2G of a
/// step. Absent channels (data = NULL) are skipped. Per particle p and stencil node i, with
/// weight w_i and gradient ∇w_i (1/m):
/// - mass += w_i m_p (kg);
/// - momentum[a] += w_i m_p (v_p + C_p (x_i − x_p))_a + impulse_dt·f_ia (kg·m/s);
/// - force[a] += f_ia = −V0_p (τ_p ∇w_i)_a (N), τ_p = Â F_Eᵀ + λ (J_E − 1) J_E I the Kirchhoff
///   stress (Pa; the λ term without AMPM_MODEL_PRESSURE_SOLVE, Â only for μ > 0);
/// - with AMPM_MODEL_THERMAL, collocated grid only: heat_capacity += w_i m_p c (J/K),
///   thermal_energy += w_i m_p c T_p (J), conductivity += w_i m_p κ (kg·W/(m·K)).
///
/// Afterwards, per node with mass m_i > 0: velocity v_i = momentum_i / m_i; temperature
/// T_i = thermal_energy_i / heat_capacity_i; conductivity κ_i = conductivity_i / m_i; the
/// host's heat solve is then (Σ w m c)_i dT_i/dt = ∇·(κ ∇T)_i. On a MAC face grid a, only mass,
/// momentum[a] and force[a] are written (with the face grid's own stencil).
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct AmpmP2gView<T> {
    /// The nodes the channels cover.
    pub nodes: AmpmNodeBox,
    /// Node mass (kg).
    pub mass: AmpmChannel<T>,
    /// Node momentum per axis (kg·m/s); entry [2] ignored in 2D.
    pub momentum: [AmpmChannel<T>; 3],
    /// Node stress force per axis (N); entry [2] ignored in 2D.
    pub force: [AmpmChannel<T>; 3],
    /// Node heat capacity (J/K), AMPM_MODEL_THERMAL.
    pub heat_capacity: AmpmChannel<T>,
    /// Node thermal energy (J), AMPM_MODEL_THERMAL.
    pub thermal_energy: AmpmChannel<T>,
    /// Node conductivity mass (kg·W/(m·K)), AMPM_MODEL_THERMAL.
    pub conductivity: AmpmChannel<T>,
}

/// Where ampm_g2p_update_* reads: new node velocities v_i^(n+1) (m/s, required) and, with
/// AMPM_MODEL_THERMAL, new and old node temperatures T_i^(n+1), T_i^n (K, required). Every node
/// value a particle reads must be finite (AMPM_ERR_NON_FINITE for that particle otherwise);
/// nodes outside all stencils may hold anything (e.g. NaN for massless nodes).
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct AmpmG2pView<T> {
    /// The nodes the channels cover.
    pub nodes: AmpmNodeBox,
    /// New node velocity per axis (m/s); entry [2] ignored in 2D.
    pub velocity: [AmpmConstChannel<T>; 3],
    /// New node temperature T^(n+1) (K), AMPM_MODEL_THERMAL.
    pub temperature: AmpmConstChannel<T>,
    /// Old node temperature T^n (K), AMPM_MODEL_THERMAL.
    pub temperature_old: AmpmConstChannel<T>,
}

/// The channels of ampm_force_apply_*: node displacements du (m) are read, node force
/// differentials df (N) are scatter-added (+=; the host zeroes them first). All 2·d channels
/// are required and df must not alias du.
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct AmpmForceView<T> {
    /// The nodes the channels cover.
    pub nodes: AmpmNodeBox,
    /// Node displacement per axis (m); entry [2] ignored in 2D.
    pub du: [AmpmConstChannel<T>; 3],
    /// Node force differential per axis (N); entry [2] ignored in 2D.
    pub df: [AmpmChannel<T>; 3],
}
