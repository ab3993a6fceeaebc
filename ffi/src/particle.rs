//! C entry points of the MPM particle updates: stencils, P2G, G2P + particle update,
//! the implicit force differential and the pressure, as batch calls over structure-of-arrays
//! particle data, one wrapper per dim × precision around one generic body (module `imp`).
//!
//! **Particle arrays** ([`AmpmParticles`]): particle `p`'s vector `x` is `x[d·p + a]`, its
//! matrices `affine`, `f_e`, `f_p` are `d·d` scalars column-major at `d²·p`
//! (`F[d²·p + i + d·j] = F_ij`), scalars at `[p]`. Units: SI (m, m/s, 1/s, kg, m³, K, J/kg).
//!
//! **Per-node arrays**: a particle's stencil has `K^d` nodes (`K = 3` quadratic, `4` cubic);
//! node `r` has offsets `o_a = (r / K^a) mod K` (axis 0 fastest) and grid index
//! `base[d·p + a] + o_a`; scalar per-node data of particle `p` is at `[K^d·p + r]`, vector
//! data at `[(K^d·p + r)·d + a]`.
//!
//! **Batch contract**: every valid particle is computed; a failed particle's outputs (and, for
//! the update, its particle data) are left untouched; the first failure's status is returned
//! and its index written to `*first_failed` (n if none; `first_failed` may be NULL). Arrays
//! may be NULL when n = 0, and optional arrays as documented.
#![allow(clippy::missing_safety_doc, clippy::too_many_arguments)]

use crate::status::AmpmStatus;
use core::ffi::{c_int, c_uchar, c_uint};

/// Model bit of `AmpmMaterial.model`: snow plasticity of solids (Stomakhin et al. 2013).
pub const AMPM_MODEL_PLASTIC: c_uint = 1;
/// Model bit: heat transfer (temperatures are read and written).
pub const AMPM_MODEL_THERMAL: c_uint = 2;
/// Model bit: melting and freezing through the latent heat buffer (requires THERMAL).
pub const AMPM_MODEL_PHASE_CHANGE: c_uint = 4;
/// Model bit: the dilational part is left to the host's pressure solve (else it is in the
/// explicit stress force, which needs `inv_lambda > 0`).
pub const AMPM_MODEL_PRESSURE_SOLVE: c_uint = 8;
/// Model bit: the force differential uses the PSD projection of the deviatoric Hessian, Ĉ⁺
/// (with the dilational term, if not left to the pressure solve, added unprojected).
pub const AMPM_MODEL_PSD_HESSIAN: c_uint = 16;
/// Quadratic B-spline kernel (3 nodes per axis).
pub const AMPM_KERNEL_QUADRATIC: c_uint = 2;
/// Cubic B-spline kernel (4 nodes per axis).
pub const AMPM_KERNEL_CUBIC: c_uint = 3;
/// Collocated grid (nodes at i·h); 0 ≤ a < d selects the MAC face grid of component a.
pub const AMPM_GRID_COLLOCATED: c_int = -1;
/// Phase code of a solid particle.
pub const AMPM_PHASE_SOLID: c_uchar = 0;
/// Phase code of a liquid particle.
pub const AMPM_PHASE_LIQUID: c_uchar = 1;

/// Material parameters of one phase.
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct AmpmPhaseParams<T> {
    /// mu ≥ 0 (Pa) of the fixed corotated deviatoric energy; must be 0 for the liquid.
    pub mu: T,
    /// 1/lambda ≥ 0 (1/Pa) of Psi_lambda = lambda/2 (J_E − 1)²; 0 is incompressible.
    pub inv_lambda: T,
    /// Specific heat capacity c > 0 (J/(kg·K)), read with AMPM_MODEL_THERMAL.
    pub heat_capacity: T,
    /// Conductivity kappa ≥ 0 (W/(m·K)), read with AMPM_MODEL_THERMAL.
    pub conductivity: T,
}

/// What a scene models (AMPM_MODEL_* bits) and its parameters; fields of parts that are off
/// are not read.
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct AmpmMaterial<T> {
    /// OR of AMPM_MODEL_* bits; unknown bits are refused.
    pub model: c_uint,
    /// Solid phase parameters.
    pub solid: AmpmPhaseParams<T>,
    /// Liquid phase parameters (mu = 0).
    pub liquid: AmpmPhaseParams<T>,
    /// Snow critical compression theta_c in [0, 1) (AMPM_MODEL_PLASTIC).
    pub critical_compression: T,
    /// Snow critical stretch theta_s ≥ 0 (AMPM_MODEL_PLASTIC).
    pub critical_stretch: T,
    /// Hardening xi ≥ 0: mu = mu0 e^(xi (1 − J_P)), lambda likewise (AMPM_MODEL_PLASTIC).
    pub hardening: T,
    /// FLIP fraction alpha in [0, 1] of the temperature transfer (AMPM_MODEL_THERMAL).
    pub flip: T,
    /// Melting point T_m (K) (AMPM_MODEL_PHASE_CHANGE).
    pub melting_point: T,
    /// Specific latent heat L ≥ 0 (J/kg); the buffer U lives in [0, L] (AMPM_MODEL_PHASE_CHANGE).
    pub latent_heat: T,
}

/// Structure-of-arrays particle data (layouts in the module docs of ffi/src/particle.rs).
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct AmpmParticles<T> {
    /// Positions (m, relative to the grid origin), n·d.
    pub x: *mut T,
    /// Velocities (m/s), n·d.
    pub v: *mut T,
    /// APIC affine matrices C_p (1/s), n·d², column-major.
    pub affine: *mut T,
    /// Elastic deformation gradients F_E, n·d², det > 0.
    pub f_e: *mut T,
    /// Plastic deformation gradients F_P, n·d², det > 0 (identity for purely elastic solids).
    pub f_p: *mut T,
    /// Masses (kg), n, > 0.
    pub mass: *const T,
    /// Reference volumes V0 (m³), n, > 0.
    pub volume0: *const T,
    /// Temperatures (K), n; may be NULL without AMPM_MODEL_THERMAL.
    pub temperature: *mut T,
    /// Latent buffers U (J/kg), n; may be NULL without AMPM_MODEL_PHASE_CHANGE.
    pub latent: *mut T,
    /// Phases (AMPM_PHASE_*), n; may be NULL without AMPM_MODEL_PHASE_CHANGE (all solid).
    pub phase: *mut c_uchar,
}

/// P2G outputs, per particle and stencil node (layouts in the module docs).
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct AmpmP2gNodes<T> {
    /// Base node grid index, n·d.
    pub base: *mut c_int,
    /// Node weights w, n·K^d; may be NULL.
    pub weight: *mut T,
    /// Node masses w m (kg), n·K^d.
    pub mass: *mut T,
    /// Node APIC momenta w m (v + C (x_i − x_p)) (kg·m/s), n·K^d·d.
    pub momentum: *mut T,
    /// Node stress forces −V0 P F_Eᵀ ∇w (N), n·K^d·d.
    pub force: *mut T,
    /// Node heat capacities w m c (J/K), n·K^d; may be NULL (read only with THERMAL).
    pub heat_capacity: *mut T,
    /// Node thermal energies w m c T (J), n·K^d; may be NULL (read only with THERMAL).
    pub thermal_energy: *mut T,
    /// Node conductivity masses w m kappa (kg·W/(m·K)), n·K^d; may be NULL (written only with
    /// THERMAL): the node sum divided by the node mass is the mass-weighted conductivity.
    pub conductivity: *mut T,
}

/// Grid values gathered by the host at each particle's collocated stencil nodes.
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct AmpmGridSamples<T> {
    /// New node velocities v_i^(n+1) (m/s), n·K^d·d.
    pub velocity: *const T,
    /// New node temperatures T_i^(n+1) (K), n·K^d; required with AMPM_MODEL_THERMAL.
    pub temperature: *const T,
    /// Old node temperatures T_i^n (K), n·K^d; required with AMPM_MODEL_THERMAL.
    pub temperature_old: *const T,
}

/// Single-precision material.
pub type AmpmMaterialF32 = AmpmMaterial<f32>;
/// Double-precision material.
pub type AmpmMaterialF64 = AmpmMaterial<f64>;
/// Single-precision particle arrays.
pub type AmpmParticlesF32 = AmpmParticles<f32>;
/// Double-precision particle arrays.
pub type AmpmParticlesF64 = AmpmParticles<f64>;
/// Single-precision P2G outputs.
pub type AmpmP2gNodesF32 = AmpmP2gNodes<f32>;
/// Double-precision P2G outputs.
pub type AmpmP2gNodesF64 = AmpmP2gNodes<f64>;
/// Single-precision grid samples.
pub type AmpmGridSamplesF32 = AmpmGridSamples<f32>;
/// Double-precision grid samples.
pub type AmpmGridSamplesF64 = AmpmGridSamples<f64>;

/// The generic bodies of the entry points below.
mod imp {
    use super::{AmpmGridSamples, AmpmMaterial, AmpmP2gNodes, AmpmParticles};
    use super::{
        AMPM_MODEL_PHASE_CHANGE, AMPM_MODEL_PLASTIC, AMPM_MODEL_PRESSURE_SOLVE,
        AMPM_MODEL_PSD_HESSIAN, AMPM_MODEL_THERMAL,
    };
    use crate::abi::guard;
    use crate::status::AmpmStatus;
    use ampm_core::hessian::HessianDim;
    use ampm_core::particle::update::{self, force_differential, p2g};
    use ampm_core::particle::{
        g2p_update, Definiteness, Dilation, Grid, GridSample, Heat, Kernel, Material, Particle,
        Phase, PhaseParams, Snow, Stencil,
    };
    use ampm_core::polar::{DefaultSvd, SvdMethod};
    use ampm_core::{Error, Mat, Matrix, Real};
    use core::ffi::{c_int, c_uint};
    use core::ptr;

    /// Reads element `i` of an array.
    #[inline]
    unsafe fn rd<T: Copy>(p: *const T, i: usize) -> T {
        ptr::read_unaligned(p.add(i))
    }

    /// Writes element `i` of an array.
    #[inline]
    unsafe fn wr<T: Copy>(p: *mut T, i: usize, v: T) {
        ptr::write_unaligned(p.add(i), v)
    }

    #[inline]
    unsafe fn rd_vec<T: Copy + Default, const D: usize>(p: *const T, i: usize) -> [T; D] {
        let mut v = [T::default(); D];
        for (a, x) in v.iter_mut().enumerate() {
            *x = rd(p, D * i + a);
        }
        v
    }

    #[inline]
    unsafe fn wr_vec<T: Copy, const D: usize>(p: *mut T, i: usize, v: &[T; D]) {
        for (a, x) in v.iter().enumerate() {
            wr(p, D * i + a, *x);
        }
    }

    #[inline]
    unsafe fn rd_mat<T: Real, const D: usize>(p: *const T, i: usize) -> Mat<T, D> {
        let mut m = Mat::<T, D>::ZERO;
        for j in 0..D {
            for r in 0..D {
                m.cols[j][r] = rd(p, D * D * i + r + D * j);
            }
        }
        m
    }

    #[inline]
    unsafe fn wr_mat<T: Real, const D: usize>(p: *mut T, i: usize, m: &Mat<T, D>) {
        for j in 0..D {
            for r in 0..D {
                wr(p, D * D * i + r + D * j, m.cols[j][r]);
            }
        }
    }

    /// Runs `k` for every particle; the contract of the module docs.
    #[inline]
    unsafe fn run(
        n: usize,
        first_failed: *mut usize,
        mut k: impl FnMut(usize) -> Result<(), Error>,
    ) -> AmpmStatus {
        let mut status = AmpmStatus::AMPM_OK;
        let mut first = n;
        for i in 0..n {
            if let Err(e) = k(i) {
                if first == n {
                    first = i;
                    status = e.into();
                }
            }
        }
        if !first_failed.is_null() {
            *first_failed = first;
        }
        status
    }

    /// `n·per` scalars of `T` must be addressable.
    #[inline]
    fn check_size<T>(n: usize, per: usize) -> AmpmStatus {
        match n.checked_mul(per * core::mem::size_of::<T>()) {
            Some(b) if b <= isize::MAX as usize => AmpmStatus::AMPM_OK,
            _ => AmpmStatus::AMPM_ERR_INVALID_ARGUMENT,
        }
    }

    #[inline]
    fn kernel_of(k: c_uint) -> Result<Kernel, Error> {
        match k {
            super::AMPM_KERNEL_QUADRATIC => Ok(Kernel::Quadratic),
            super::AMPM_KERNEL_CUBIC => Ok(Kernel::Cubic),
            _ => Err(Error::InvalidArgument),
        }
    }

    #[inline]
    fn phase_params<T: Copy>(p: &super::AmpmPhaseParams<T>) -> PhaseParams<T> {
        PhaseParams {
            mu: p.mu,
            inv_lambda: p.inv_lambda,
            heat_capacity: p.heat_capacity,
            conductivity: p.conductivity,
        }
    }

    /// The core material of a C material (flags checked; values checked per particle).
    #[inline]
    fn material_of<T: Real>(m: &AmpmMaterial<T>) -> Result<Material<T>, Error> {
        let known = AMPM_MODEL_PLASTIC
            | AMPM_MODEL_THERMAL
            | AMPM_MODEL_PHASE_CHANGE
            | AMPM_MODEL_PRESSURE_SOLVE
            | AMPM_MODEL_PSD_HESSIAN;
        if m.model & !known != 0 {
            return Err(Error::InvalidArgument);
        }
        let thermal = m.model & AMPM_MODEL_THERMAL != 0;
        let phase_change = m.model & AMPM_MODEL_PHASE_CHANGE != 0;
        if phase_change && !thermal {
            return Err(Error::InvalidArgument);
        }
        Ok(Material {
            solid: phase_params(&m.solid),
            liquid: phase_params(&m.liquid),
            plasticity: (m.model & AMPM_MODEL_PLASTIC != 0).then_some(Snow {
                critical_compression: m.critical_compression,
                critical_stretch: m.critical_stretch,
                hardening: m.hardening,
            }),
            heat: thermal.then_some(Heat {
                flip: m.flip,
                melting_point: m.melting_point,
                latent_heat: m.latent_heat,
                phase_change,
            }),
            dilation: if m.model & AMPM_MODEL_PRESSURE_SOLVE != 0 {
                Dilation::PressureSolve
            } else {
                Dilation::Explicit
            },
            hessian: if m.model & AMPM_MODEL_PSD_HESSIAN != 0 {
                Definiteness::Projected
            } else {
                Definiteness::Exact
            },
        })
    }

    /// Reads the material; `Err(status)` to return at once.
    #[inline]
    unsafe fn read_material<T: Real>(m: *const AmpmMaterial<T>) -> Result<Material<T>, AmpmStatus> {
        if m.is_null() {
            return Err(AmpmStatus::AMPM_ERR_NULL_POINTER);
        }
        material_of(&ptr::read_unaligned(m)).map_err(AmpmStatus::from)
    }

    /// Reads the particle arrays and checks the ones `mat` needs.
    #[inline]
    unsafe fn read_particles<T: Real>(
        n: usize,
        ps: *const AmpmParticles<T>,
        mat: &Material<T>,
    ) -> Result<AmpmParticles<T>, AmpmStatus> {
        if ps.is_null() {
            return Err(AmpmStatus::AMPM_ERR_NULL_POINTER);
        }
        let p = ptr::read_unaligned(ps);
        if n == 0 {
            return Ok(p);
        }
        let thermal = mat.heat.is_some();
        let phase_change = mat.heat.is_some_and(|h| h.phase_change);
        let missing = p.x.is_null()
            || p.v.is_null()
            || p.affine.is_null()
            || p.f_e.is_null()
            || p.f_p.is_null()
            || p.mass.is_null()
            || p.volume0.is_null()
            || (thermal && p.temperature.is_null())
            || (phase_change && (p.latent.is_null() || p.phase.is_null()));
        if missing {
            Err(AmpmStatus::AMPM_ERR_NULL_POINTER)
        } else {
            Ok(p)
        }
    }

    /// Particle `i` (reads only the arrays `mat` uses; phase 0 when `phase` is NULL).
    #[inline]
    unsafe fn get<T: Real, const D: usize>(
        ps: &AmpmParticles<T>,
        i: usize,
        mat: &Material<T>,
    ) -> Result<Particle<T, D>, Error> {
        let mut p = Particle::<T, D>::at_rest(rd_vec(ps.x, i), rd(ps.mass, i), rd(ps.volume0, i));
        p.v = rd_vec(ps.v, i);
        p.affine = rd_mat(ps.affine, i);
        p.f_e = rd_mat(ps.f_e, i);
        p.f_p = rd_mat(ps.f_p, i);
        if mat.heat.is_some() {
            p.temperature = rd(ps.temperature, i);
        }
        if mat.heat.is_some_and(|h| h.phase_change) {
            p.latent = rd(ps.latent, i);
        }
        if !ps.phase.is_null() {
            p.phase = Phase::from_code(rd(ps.phase, i))?;
        }
        Ok(p)
    }

    /// Writes back what [`g2p_update`] changes.
    #[inline]
    unsafe fn put<T: Real, const D: usize>(
        ps: &AmpmParticles<T>,
        i: usize,
        mat: &Material<T>,
        p: &Particle<T, D>,
    ) {
        wr_vec(ps.x, i, &p.x);
        wr_vec(ps.v, i, &p.v);
        wr_mat(ps.affine, i, &p.affine);
        wr_mat(ps.f_e, i, &p.f_e);
        wr_mat(ps.f_p, i, &p.f_p);
        if mat.heat.is_some() {
            wr(ps.temperature, i, p.temperature);
        }
        if mat.heat.is_some_and(|h| h.phase_change) {
            wr(ps.latent, i, p.latent);
            wr(ps.phase, i, p.phase as u8);
        }
    }

    macro_rules! tri {
        ($e:expr) => {
            match $e {
                Ok(v) => v,
                Err(s) => return s,
            }
        };
    }

    /// Stencil batch.
    pub(super) unsafe fn stencil<T: Real, const D: usize>(
        n: usize,
        kernel: c_uint,
        grid: c_int,
        h: T,
        x: *const T,
        base: *mut c_int,
        weight: *mut T,
        grad_weight: *mut T,
        first_failed: *mut usize,
    ) -> AmpmStatus {
        guard(|| {
            let kernel = tri!(kernel_of(kernel).map_err(AmpmStatus::from));
            let grid = match grid {
                -1 => Grid::Collocated,
                a if a >= 0 && (a as usize) < D => Grid::Face(a as usize),
                _ => return AmpmStatus::AMPM_ERR_INVALID_ARGUMENT,
            };
            let k = kernel.node_count(D);
            if n > 0 && (x.is_null() || base.is_null() || weight.is_null()) {
                return AmpmStatus::AMPM_ERR_NULL_POINTER;
            }
            let st = check_size::<T>(n, k * D);
            if st != AmpmStatus::AMPM_OK {
                return st;
            }
            run(n, first_failed, |i| {
                let s = Stencil::<T, D>::new(kernel, grid, h, &rd_vec(x, i))?;
                wr_vec(base, i, &s.base);
                for r in 0..k {
                    let nd = s.node(r);
                    wr(weight, k * i + r, nd.weight);
                    if !grad_weight.is_null() {
                        wr_vec(grad_weight, k * i + r, &nd.grad);
                    }
                }
                Ok(())
            })
        })
    }

    /// P2G batch.
    pub(super) unsafe fn p2g_batch<T: Real, const D: usize>(
        n: usize,
        material: *const AmpmMaterial<T>,
        kernel: c_uint,
        h: T,
        particles: *const AmpmParticles<T>,
        nodes: *const AmpmP2gNodes<T>,
        first_failed: *mut usize,
    ) -> AmpmStatus
    where
        Mat<T, D>: Matrix<Scalar = T, Vector = [T; D]>,
        DefaultSvd: SvdMethod<Mat<T, D>>,
    {
        guard(|| {
            let mat = tri!(read_material(material));
            let kernel = tri!(kernel_of(kernel).map_err(AmpmStatus::from));
            let ps = tri!(read_particles(n, particles, &mat));
            if nodes.is_null() {
                return AmpmStatus::AMPM_ERR_NULL_POINTER;
            }
            let out = ptr::read_unaligned(nodes);
            if n > 0
                && (out.base.is_null()
                    || out.mass.is_null()
                    || out.momentum.is_null()
                    || out.force.is_null())
            {
                return AmpmStatus::AMPM_ERR_NULL_POINTER;
            }
            let k = kernel.node_count(D);
            let st = check_size::<T>(n, k * D);
            if st != AmpmStatus::AMPM_OK {
                return st;
            }
            run(n, first_failed, |i| {
                let p = get::<T, D>(&ps, i, &mat)?;
                let q = p2g(&mat, kernel, h, &p)?;
                wr_vec(out.base, i, &q.stencil.base);
                for r in 0..k {
                    let nd = q.node(r);
                    let j = k * i + r;
                    if !out.weight.is_null() {
                        wr(out.weight, j, nd.weight);
                    }
                    wr(out.mass, j, nd.mass);
                    wr_vec(out.momentum, j, &nd.momentum);
                    wr_vec(out.force, j, &nd.force);
                    if mat.heat.is_some() {
                        if !out.heat_capacity.is_null() {
                            wr(out.heat_capacity, j, nd.heat_capacity);
                        }
                        if !out.thermal_energy.is_null() {
                            wr(out.thermal_energy, j, nd.thermal_energy);
                        }
                        if !out.conductivity.is_null() {
                            wr(out.conductivity, j, nd.conductivity);
                        }
                    }
                }
                Ok(())
            })
        })
    }

    /// G2P + update batch.
    pub(super) unsafe fn g2p_update_batch<T: Real, const D: usize>(
        n: usize,
        material: *const AmpmMaterial<T>,
        kernel: c_uint,
        h: T,
        dt: T,
        particles: *const AmpmParticles<T>,
        grid: *const AmpmGridSamples<T>,
        first_failed: *mut usize,
    ) -> AmpmStatus
    where
        Mat<T, D>: Matrix<Scalar = T, Vector = [T; D]>,
        DefaultSvd: SvdMethod<Mat<T, D>>,
    {
        guard(|| {
            let mat = tri!(read_material(material));
            let kernel = tri!(kernel_of(kernel).map_err(AmpmStatus::from));
            let ps = tri!(read_particles(n, particles, &mat));
            if grid.is_null() {
                return AmpmStatus::AMPM_ERR_NULL_POINTER;
            }
            let g = ptr::read_unaligned(grid);
            let thermal = mat.heat.is_some();
            if n > 0
                && (g.velocity.is_null()
                    || (thermal && (g.temperature.is_null() || g.temperature_old.is_null())))
            {
                return AmpmStatus::AMPM_ERR_NULL_POINTER;
            }
            let k = kernel.node_count(D);
            let st = check_size::<T>(n, k * D);
            if st != AmpmStatus::AMPM_OK {
                return st;
            }
            // Largest stencil: 4³ nodes.
            let mut vel = [[T::ZERO; D]; 64];
            let mut tn = [T::ZERO; 64];
            let mut to = [T::ZERO; 64];
            run(n, first_failed, |i| {
                let p = get::<T, D>(&ps, i, &mat)?;
                for r in 0..k {
                    vel[r] = rd_vec(g.velocity, k * i + r);
                    if thermal {
                        tn[r] = rd(g.temperature, k * i + r);
                        to[r] = rd(g.temperature_old, k * i + r);
                    }
                }
                let sample = GridSample {
                    velocity: &vel[..k],
                    temperature: thermal.then_some((&tn[..k], &to[..k])),
                };
                let (q, _) = g2p_update(&mat, kernel, h, dt, &sample, &p)?;
                put(&ps, i, &mat, &q);
                Ok(())
            })
        })
    }

    /// Force differential batch.
    pub(super) unsafe fn force_differential_batch<T: Real, const D: usize>(
        n: usize,
        material: *const AmpmMaterial<T>,
        kernel: c_uint,
        h: T,
        particles: *const AmpmParticles<T>,
        du: *const T,
        df: *mut T,
        first_failed: *mut usize,
    ) -> AmpmStatus
    where
        Mat<T, D>: Matrix<Scalar = T, Vector = [T; D]> + HessianDim,
        DefaultSvd: SvdMethod<Mat<T, D>>,
    {
        guard(|| {
            let mat = tri!(read_material(material));
            let kernel = tri!(kernel_of(kernel).map_err(AmpmStatus::from));
            let ps = tri!(read_particles(n, particles, &mat));
            if n > 0 && (du.is_null() || df.is_null()) {
                return AmpmStatus::AMPM_ERR_NULL_POINTER;
            }
            let k = kernel.node_count(D);
            let st = check_size::<T>(n, k * D);
            if st != AmpmStatus::AMPM_OK {
                return st;
            }
            let mut u = [[T::ZERO; D]; 64];
            let mut f = [[T::ZERO; D]; 64];
            run(n, first_failed, |i| {
                let p = get::<T, D>(&ps, i, &mat)?;
                for (r, ur) in u.iter_mut().enumerate().take(k) {
                    *ur = rd_vec(du, k * i + r);
                }
                force_differential(&mat, kernel, h, &p, &u[..k], &mut f[..k])?;
                for (r, fr) in f.iter().enumerate().take(k) {
                    wr_vec(df, k * i + r, fr);
                }
                Ok(())
            })
        })
    }

    /// Pressure batch.
    pub(super) unsafe fn pressure_batch<T: Real, const D: usize>(
        n: usize,
        material: *const AmpmMaterial<T>,
        dt: T,
        particles: *const AmpmParticles<T>,
        pressure: *mut T,
        coefficient: *mut T,
        first_failed: *mut usize,
    ) -> AmpmStatus
    where
        Mat<T, D>: Matrix<Scalar = T, Vector = [T; D]>,
    {
        guard(|| {
            let mat = tri!(read_material(material));
            let ps = tri!(read_particles(n, particles, &mat));
            let st = check_size::<T>(n, D * D);
            if st != AmpmStatus::AMPM_OK {
                return st;
            }
            run(n, first_failed, |i| {
                let p = get::<T, D>(&ps, i, &mat)?;
                let pr = if pressure.is_null() {
                    T::ZERO
                } else {
                    update::pressure(&mat, &p)?
                };
                let c = if coefficient.is_null() {
                    T::ZERO
                } else {
                    update::pressure_coefficient(&mat, &p, dt)?
                };
                if !pressure.is_null() {
                    wr(pressure, i, pr);
                }
                if !coefficient.is_null() {
                    wr(coefficient, i, c);
                }
                Ok(())
            })
        })
    }
}

/// Stencils of n particles (2D, f32): quadratic/cubic B-spline weights and gradients.
///
/// `kernel`: AMPM_KERNEL_*; `grid`: AMPM_GRID_COLLOCATED or a face axis 0..1; `h` > 0 (m);
/// `x`: n·2 positions (m). Writes `base` (n·2 int), `weight` (n·K^d) and, if not NULL,
/// `grad_weight` (n·K^d·2, 1/m), K^d = 9 (quadratic) or 27 (cubic), node order as in the module docs. Batch contract.
///
/// # Safety
/// Non-null pointers must be valid for the sizes above.
#[no_mangle]
pub unsafe extern "C" fn ampm_stencil_2d_f32(
    n: usize,
    kernel: c_uint,
    grid: c_int,
    h: f32,
    x: *const f32,
    base: *mut c_int,
    weight: *mut f32,
    grad_weight: *mut f32,
    first_failed: *mut usize,
) -> AmpmStatus {
    imp::stencil::<f32, 2>(
        n,
        kernel,
        grid,
        h,
        x,
        base,
        weight,
        grad_weight,
        first_failed,
    )
}

/// P2G of n particles (2D, f32, collocated grid, APIC): node masses, momenta, stress forces
/// −V0 P F_Eᵀ ∇w (P: augmented fixed corotated plus, unless AMPM_MODEL_PRESSURE_SOLVE, the
/// dilational part) and, with AMPM_MODEL_THERMAL, heat capacities and thermal energies.
///
/// Reads `particles` (not modified); writes `nodes` arrays (K^d = 9 (quadratic) or 27 (cubic)). Batch contract.
///
/// # Safety
/// Non-null pointers must be valid for the sizes in the struct docs.
#[no_mangle]
pub unsafe extern "C" fn ampm_p2g_2d_f32(
    n: usize,
    material: *const AmpmMaterialF32,
    kernel: c_uint,
    h: f32,
    particles: *const AmpmParticlesF32,
    nodes: *const AmpmP2gNodesF32,
    first_failed: *mut usize,
) -> AmpmStatus {
    imp::p2g_batch::<f32, 2>(n, material, kernel, h, particles, nodes, first_failed)
}

/// G2P and particle update of n particles (2D, f32, step `dt` s): temperature and phase
/// (PIC/FLIP, latent buffer), velocity and APIC affine matrix, position, F_E ← (I + dt∇v) F_E
/// with the remedy (I + dt/2 ∇v)², halving until det > 0, then the liquid projection or snow
/// plasticity, as the material says.
///
/// `grid`: node values gathered at each particle's collocated stencil (K^d = 9 (quadratic) or 27 (cubic)). A failed
/// particle's data is left as it was. Batch contract.
///
/// # Safety
/// Non-null pointers must be valid for the sizes in the struct docs.
#[no_mangle]
pub unsafe extern "C" fn ampm_g2p_update_2d_f32(
    n: usize,
    material: *const AmpmMaterialF32,
    kernel: c_uint,
    h: f32,
    dt: f32,
    particles: *const AmpmParticlesF32,
    grid: *const AmpmGridSamplesF32,
    first_failed: *mut usize,
) -> AmpmStatus {
    imp::g2p_update_batch::<f32, 2>(n, material, kernel, h, dt, particles, grid, first_failed)
}

/// Force differentials of n particles (2D, f32) for an implicit solve: with node
/// displacements `du` (m, n·K^d·2), δF_E = (Σ_j du_j ∇w_jᵀ) F_E and
/// `df` = −V0 (Ĉ:δF_E + δP_lambda) F_Eᵀ ∇w_i (N, n·K^d·2); δP_lambda only without
/// AMPM_MODEL_PRESSURE_SOLVE. K^d = 9 (quadratic) or 27 (cubic). Particles are not modified. Batch contract.
///
/// # Safety
/// Non-null pointers must be valid for the sizes above.
#[no_mangle]
pub unsafe extern "C" fn ampm_force_differential_2d_f32(
    n: usize,
    material: *const AmpmMaterialF32,
    kernel: c_uint,
    h: f32,
    particles: *const AmpmParticlesF32,
    du: *const f32,
    df: *mut f32,
    first_failed: *mut usize,
) -> AmpmStatus {
    imp::force_differential_batch::<f32, 2>(n, material, kernel, h, particles, du, df, first_failed)
}

/// Pressures and pressure-solve coefficients of n particles (2D, f32):
/// `pressure[p]` = −lambda (J_E − 1)/J_P (Pa; needs inv_lambda > 0) and
/// `coefficient[p]` = J_P inv_lambda/(dt J_E) (1/(Pa·s); 0 when incompressible), with the
/// hardened lambda. Either output may be NULL (not computed). Batch contract.
///
/// # Safety
/// Non-null pointers must be valid for n scalars.
#[no_mangle]
pub unsafe extern "C" fn ampm_pressure_2d_f32(
    n: usize,
    material: *const AmpmMaterialF32,
    dt: f32,
    particles: *const AmpmParticlesF32,
    pressure: *mut f32,
    coefficient: *mut f32,
    first_failed: *mut usize,
) -> AmpmStatus {
    imp::pressure_batch::<f32, 2>(
        n,
        material,
        dt,
        particles,
        pressure,
        coefficient,
        first_failed,
    )
}

/// Stencils of n particles (2D, f64): quadratic/cubic B-spline weights and gradients.
///
/// `kernel`: AMPM_KERNEL_*; `grid`: AMPM_GRID_COLLOCATED or a face axis 0..1; `h` > 0 (m);
/// `x`: n·2 positions (m). Writes `base` (n·2 int), `weight` (n·K^d) and, if not NULL,
/// `grad_weight` (n·K^d·2, 1/m), K^d = 9 (quadratic) or 27 (cubic), node order as in the module docs. Batch contract.
///
/// # Safety
/// Non-null pointers must be valid for the sizes above.
#[no_mangle]
pub unsafe extern "C" fn ampm_stencil_2d_f64(
    n: usize,
    kernel: c_uint,
    grid: c_int,
    h: f64,
    x: *const f64,
    base: *mut c_int,
    weight: *mut f64,
    grad_weight: *mut f64,
    first_failed: *mut usize,
) -> AmpmStatus {
    imp::stencil::<f64, 2>(
        n,
        kernel,
        grid,
        h,
        x,
        base,
        weight,
        grad_weight,
        first_failed,
    )
}

/// P2G of n particles (2D, f64, collocated grid, APIC): node masses, momenta, stress forces
/// −V0 P F_Eᵀ ∇w (P: augmented fixed corotated plus, unless AMPM_MODEL_PRESSURE_SOLVE, the
/// dilational part) and, with AMPM_MODEL_THERMAL, heat capacities and thermal energies.
///
/// Reads `particles` (not modified); writes `nodes` arrays (K^d = 9 (quadratic) or 27 (cubic)). Batch contract.
///
/// # Safety
/// Non-null pointers must be valid for the sizes in the struct docs.
#[no_mangle]
pub unsafe extern "C" fn ampm_p2g_2d_f64(
    n: usize,
    material: *const AmpmMaterialF64,
    kernel: c_uint,
    h: f64,
    particles: *const AmpmParticlesF64,
    nodes: *const AmpmP2gNodesF64,
    first_failed: *mut usize,
) -> AmpmStatus {
    imp::p2g_batch::<f64, 2>(n, material, kernel, h, particles, nodes, first_failed)
}

/// G2P and particle update of n particles (2D, f64, step `dt` s): temperature and phase
/// (PIC/FLIP, latent buffer), velocity and APIC affine matrix, position, F_E ← (I + dt∇v) F_E
/// with the remedy (I + dt/2 ∇v)², halving until det > 0, then the liquid projection or snow
/// plasticity, as the material says.
///
/// `grid`: node values gathered at each particle's collocated stencil (K^d = 9 (quadratic) or 27 (cubic)). A failed
/// particle's data is left as it was. Batch contract.
///
/// # Safety
/// Non-null pointers must be valid for the sizes in the struct docs.
#[no_mangle]
pub unsafe extern "C" fn ampm_g2p_update_2d_f64(
    n: usize,
    material: *const AmpmMaterialF64,
    kernel: c_uint,
    h: f64,
    dt: f64,
    particles: *const AmpmParticlesF64,
    grid: *const AmpmGridSamplesF64,
    first_failed: *mut usize,
) -> AmpmStatus {
    imp::g2p_update_batch::<f64, 2>(n, material, kernel, h, dt, particles, grid, first_failed)
}

/// Force differentials of n particles (2D, f64) for an implicit solve: with node
/// displacements `du` (m, n·K^d·2), δF_E = (Σ_j du_j ∇w_jᵀ) F_E and
/// `df` = −V0 (Ĉ:δF_E + δP_lambda) F_Eᵀ ∇w_i (N, n·K^d·2); δP_lambda only without
/// AMPM_MODEL_PRESSURE_SOLVE. K^d = 9 (quadratic) or 27 (cubic). Particles are not modified. Batch contract.
///
/// # Safety
/// Non-null pointers must be valid for the sizes above.
#[no_mangle]
pub unsafe extern "C" fn ampm_force_differential_2d_f64(
    n: usize,
    material: *const AmpmMaterialF64,
    kernel: c_uint,
    h: f64,
    particles: *const AmpmParticlesF64,
    du: *const f64,
    df: *mut f64,
    first_failed: *mut usize,
) -> AmpmStatus {
    imp::force_differential_batch::<f64, 2>(n, material, kernel, h, particles, du, df, first_failed)
}

/// Pressures and pressure-solve coefficients of n particles (2D, f64):
/// `pressure[p]` = −lambda (J_E − 1)/J_P (Pa; needs inv_lambda > 0) and
/// `coefficient[p]` = J_P inv_lambda/(dt J_E) (1/(Pa·s); 0 when incompressible), with the
/// hardened lambda. Either output may be NULL (not computed). Batch contract.
///
/// # Safety
/// Non-null pointers must be valid for n scalars.
#[no_mangle]
pub unsafe extern "C" fn ampm_pressure_2d_f64(
    n: usize,
    material: *const AmpmMaterialF64,
    dt: f64,
    particles: *const AmpmParticlesF64,
    pressure: *mut f64,
    coefficient: *mut f64,
    first_failed: *mut usize,
) -> AmpmStatus {
    imp::pressure_batch::<f64, 2>(
        n,
        material,
        dt,
        particles,
        pressure,
        coefficient,
        first_failed,
    )
}

/// Stencils of n particles (3D, f32): quadratic/cubic B-spline weights and gradients.
///
/// `kernel`: AMPM_KERNEL_*; `grid`: AMPM_GRID_COLLOCATED or a face axis 0..2; `h` > 0 (m);
/// `x`: n·3 positions (m). Writes `base` (n·3 int), `weight` (n·K^d) and, if not NULL,
/// `grad_weight` (n·K^d·3, 1/m), K^d = 27 (quadratic) or 64 (cubic), node order as in the module docs. Batch contract.
///
/// # Safety
/// Non-null pointers must be valid for the sizes above.
#[no_mangle]
pub unsafe extern "C" fn ampm_stencil_3d_f32(
    n: usize,
    kernel: c_uint,
    grid: c_int,
    h: f32,
    x: *const f32,
    base: *mut c_int,
    weight: *mut f32,
    grad_weight: *mut f32,
    first_failed: *mut usize,
) -> AmpmStatus {
    imp::stencil::<f32, 3>(
        n,
        kernel,
        grid,
        h,
        x,
        base,
        weight,
        grad_weight,
        first_failed,
    )
}

/// P2G of n particles (3D, f32, collocated grid, APIC): node masses, momenta, stress forces
/// −V0 P F_Eᵀ ∇w (P: augmented fixed corotated plus, unless AMPM_MODEL_PRESSURE_SOLVE, the
/// dilational part) and, with AMPM_MODEL_THERMAL, heat capacities and thermal energies.
///
/// Reads `particles` (not modified); writes `nodes` arrays (K^d = 27 (quadratic) or 64 (cubic)). Batch contract.
///
/// # Safety
/// Non-null pointers must be valid for the sizes in the struct docs.
#[no_mangle]
pub unsafe extern "C" fn ampm_p2g_3d_f32(
    n: usize,
    material: *const AmpmMaterialF32,
    kernel: c_uint,
    h: f32,
    particles: *const AmpmParticlesF32,
    nodes: *const AmpmP2gNodesF32,
    first_failed: *mut usize,
) -> AmpmStatus {
    imp::p2g_batch::<f32, 3>(n, material, kernel, h, particles, nodes, first_failed)
}

/// G2P and particle update of n particles (3D, f32, step `dt` s): temperature and phase
/// (PIC/FLIP, latent buffer), velocity and APIC affine matrix, position, F_E ← (I + dt∇v) F_E
/// with the remedy (I + dt/2 ∇v)², halving until det > 0, then the liquid projection or snow
/// plasticity, as the material says.
///
/// `grid`: node values gathered at each particle's collocated stencil (K^d = 27 (quadratic) or 64 (cubic)). A failed
/// particle's data is left as it was. Batch contract.
///
/// # Safety
/// Non-null pointers must be valid for the sizes in the struct docs.
#[no_mangle]
pub unsafe extern "C" fn ampm_g2p_update_3d_f32(
    n: usize,
    material: *const AmpmMaterialF32,
    kernel: c_uint,
    h: f32,
    dt: f32,
    particles: *const AmpmParticlesF32,
    grid: *const AmpmGridSamplesF32,
    first_failed: *mut usize,
) -> AmpmStatus {
    imp::g2p_update_batch::<f32, 3>(n, material, kernel, h, dt, particles, grid, first_failed)
}

/// Force differentials of n particles (3D, f32) for an implicit solve: with node
/// displacements `du` (m, n·K^d·3), δF_E = (Σ_j du_j ∇w_jᵀ) F_E and
/// `df` = −V0 (Ĉ:δF_E + δP_lambda) F_Eᵀ ∇w_i (N, n·K^d·3); δP_lambda only without
/// AMPM_MODEL_PRESSURE_SOLVE. K^d = 27 (quadratic) or 64 (cubic). Particles are not modified. Batch contract.
///
/// # Safety
/// Non-null pointers must be valid for the sizes above.
#[no_mangle]
pub unsafe extern "C" fn ampm_force_differential_3d_f32(
    n: usize,
    material: *const AmpmMaterialF32,
    kernel: c_uint,
    h: f32,
    particles: *const AmpmParticlesF32,
    du: *const f32,
    df: *mut f32,
    first_failed: *mut usize,
) -> AmpmStatus {
    imp::force_differential_batch::<f32, 3>(n, material, kernel, h, particles, du, df, first_failed)
}

/// Pressures and pressure-solve coefficients of n particles (3D, f32):
/// `pressure[p]` = −lambda (J_E − 1)/J_P (Pa; needs inv_lambda > 0) and
/// `coefficient[p]` = J_P inv_lambda/(dt J_E) (1/(Pa·s); 0 when incompressible), with the
/// hardened lambda. Either output may be NULL (not computed). Batch contract.
///
/// # Safety
/// Non-null pointers must be valid for n scalars.
#[no_mangle]
pub unsafe extern "C" fn ampm_pressure_3d_f32(
    n: usize,
    material: *const AmpmMaterialF32,
    dt: f32,
    particles: *const AmpmParticlesF32,
    pressure: *mut f32,
    coefficient: *mut f32,
    first_failed: *mut usize,
) -> AmpmStatus {
    imp::pressure_batch::<f32, 3>(
        n,
        material,
        dt,
        particles,
        pressure,
        coefficient,
        first_failed,
    )
}

/// Stencils of n particles (3D, f64): quadratic/cubic B-spline weights and gradients.
///
/// `kernel`: AMPM_KERNEL_*; `grid`: AMPM_GRID_COLLOCATED or a face axis 0..2; `h` > 0 (m);
/// `x`: n·3 positions (m). Writes `base` (n·3 int), `weight` (n·K^d) and, if not NULL,
/// `grad_weight` (n·K^d·3, 1/m), K^d = 27 (quadratic) or 64 (cubic), node order as in the module docs. Batch contract.
///
/// # Safety
/// Non-null pointers must be valid for the sizes above.
#[no_mangle]
pub unsafe extern "C" fn ampm_stencil_3d_f64(
    n: usize,
    kernel: c_uint,
    grid: c_int,
    h: f64,
    x: *const f64,
    base: *mut c_int,
    weight: *mut f64,
    grad_weight: *mut f64,
    first_failed: *mut usize,
) -> AmpmStatus {
    imp::stencil::<f64, 3>(
        n,
        kernel,
        grid,
        h,
        x,
        base,
        weight,
        grad_weight,
        first_failed,
    )
}

/// P2G of n particles (3D, f64, collocated grid, APIC): node masses, momenta, stress forces
/// −V0 P F_Eᵀ ∇w (P: augmented fixed corotated plus, unless AMPM_MODEL_PRESSURE_SOLVE, the
/// dilational part) and, with AMPM_MODEL_THERMAL, heat capacities and thermal energies.
///
/// Reads `particles` (not modified); writes `nodes` arrays (K^d = 27 (quadratic) or 64 (cubic)). Batch contract.
///
/// # Safety
/// Non-null pointers must be valid for the sizes in the struct docs.
#[no_mangle]
pub unsafe extern "C" fn ampm_p2g_3d_f64(
    n: usize,
    material: *const AmpmMaterialF64,
    kernel: c_uint,
    h: f64,
    particles: *const AmpmParticlesF64,
    nodes: *const AmpmP2gNodesF64,
    first_failed: *mut usize,
) -> AmpmStatus {
    imp::p2g_batch::<f64, 3>(n, material, kernel, h, particles, nodes, first_failed)
}

/// G2P and particle update of n particles (3D, f64, step `dt` s): temperature and phase
/// (PIC/FLIP, latent buffer), velocity and APIC affine matrix, position, F_E ← (I + dt∇v) F_E
/// with the remedy (I + dt/2 ∇v)², halving until det > 0, then the liquid projection or snow
/// plasticity, as the material says.
///
/// `grid`: node values gathered at each particle's collocated stencil (K^d = 27 (quadratic) or 64 (cubic)). A failed
/// particle's data is left as it was. Batch contract.
///
/// # Safety
/// Non-null pointers must be valid for the sizes in the struct docs.
#[no_mangle]
pub unsafe extern "C" fn ampm_g2p_update_3d_f64(
    n: usize,
    material: *const AmpmMaterialF64,
    kernel: c_uint,
    h: f64,
    dt: f64,
    particles: *const AmpmParticlesF64,
    grid: *const AmpmGridSamplesF64,
    first_failed: *mut usize,
) -> AmpmStatus {
    imp::g2p_update_batch::<f64, 3>(n, material, kernel, h, dt, particles, grid, first_failed)
}

/// Force differentials of n particles (3D, f64) for an implicit solve: with node
/// displacements `du` (m, n·K^d·3), δF_E = (Σ_j du_j ∇w_jᵀ) F_E and
/// `df` = −V0 (Ĉ:δF_E + δP_lambda) F_Eᵀ ∇w_i (N, n·K^d·3); δP_lambda only without
/// AMPM_MODEL_PRESSURE_SOLVE. K^d = 27 (quadratic) or 64 (cubic). Particles are not modified. Batch contract.
///
/// # Safety
/// Non-null pointers must be valid for the sizes above.
#[no_mangle]
pub unsafe extern "C" fn ampm_force_differential_3d_f64(
    n: usize,
    material: *const AmpmMaterialF64,
    kernel: c_uint,
    h: f64,
    particles: *const AmpmParticlesF64,
    du: *const f64,
    df: *mut f64,
    first_failed: *mut usize,
) -> AmpmStatus {
    imp::force_differential_batch::<f64, 3>(n, material, kernel, h, particles, du, df, first_failed)
}

/// Pressures and pressure-solve coefficients of n particles (3D, f64):
/// `pressure[p]` = −lambda (J_E − 1)/J_P (Pa; needs inv_lambda > 0) and
/// `coefficient[p]` = J_P inv_lambda/(dt J_E) (1/(Pa·s); 0 when incompressible), with the
/// hardened lambda. Either output may be NULL (not computed). Batch contract.
///
/// # Safety
/// Non-null pointers must be valid for n scalars.
#[no_mangle]
pub unsafe extern "C" fn ampm_pressure_3d_f64(
    n: usize,
    material: *const AmpmMaterialF64,
    dt: f64,
    particles: *const AmpmParticlesF64,
    pressure: *mut f64,
    coefficient: *mut f64,
    first_failed: *mut usize,
) -> AmpmStatus {
    imp::pressure_batch::<f64, 3>(
        n,
        material,
        dt,
        particles,
        pressure,
        coefficient,
        first_failed,
    )
}
