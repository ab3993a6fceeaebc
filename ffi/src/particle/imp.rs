//! The generic bodies of the particle entry points: C structs to core views, whole-call checks,
//! the batch contract, no panic across the boundary.

use super::{
    AmpmChannel, AmpmConstChannel, AmpmForceView, AmpmG2pView, AmpmMaterial, AmpmNodeBox,
    AmpmP2gView, AmpmParticles, AmpmPhaseParams,
};
use super::{
    AMPM_KERNEL_CUBIC, AMPM_KERNEL_QUADRATIC, AMPM_MODEL_PHASE_CHANGE, AMPM_MODEL_PLASTIC,
    AMPM_MODEL_PRESSURE_SOLVE, AMPM_MODEL_PSD_HESSIAN, AMPM_MODEL_THERMAL,
};
use crate::abi::batch_call;
use crate::fast::isa;
use crate::status::AmpmStatus;
use ampm_core::kernel::batch::{BatchReal, BatchStatus};
use ampm_core::kernel::{Dim, LaneDim};
use ampm_core::particle::transfer::force::{self, ForceView};
use ampm_core::particle::transfer::g2p::{self, G2pArgs, G2pView};
use ampm_core::particle::transfer::p2g::{self, P2gArgs, P2gView};
use ampm_core::particle::transfer::{self, Channel, FirstFailure, NodeBox, Particles, Reads};
use ampm_core::particle::{
    update, Definiteness, Dilation, Grid, Heat, Kernel, Material, Particle, PhaseParams, Snow,
    Stencil,
};
use ampm_core::polar::{DefaultSvd, SvdMethod};
use ampm_core::{Error, Mat, Matrix, Real};
use core::ffi::{c_int, c_uint};
use core::ptr;

/// `Err(status)` returns at once.
type Call<T> = Result<T, AmpmStatus>;

/// The status and first failed index of a core batch, for [`batch_call`].
fn done(s: BatchStatus) -> (AmpmStatus, usize) {
    let st = match s.error {
        None => AmpmStatus::AMPM_OK,
        Some(e) => e.into(),
    };
    (st, s.first_failed)
}

fn kernel_of(k: c_uint) -> Call<Kernel> {
    match k {
        AMPM_KERNEL_QUADRATIC => Ok(Kernel::Quadratic),
        AMPM_KERNEL_CUBIC => Ok(Kernel::Cubic),
        _ => Err(AmpmStatus::AMPM_ERR_INVALID_ARGUMENT),
    }
}

fn grid_of<const D: usize>(g: c_int) -> Call<Grid> {
    match g {
        -1 => Ok(Grid::Collocated),
        a if a >= 0 && (a as usize) < D => Ok(Grid::Face(a as usize)),
        _ => Err(AmpmStatus::AMPM_ERR_INVALID_ARGUMENT),
    }
}

fn phase_params<T: Copy>(p: &AmpmPhaseParams<T>) -> PhaseParams<T> {
    PhaseParams {
        mu: p.mu,
        inv_lambda: p.inv_lambda,
        heat_capacity: p.heat_capacity,
        conductivity: p.conductivity,
    }
}

/// The core material of a C material (flags checked here, values per particle).
unsafe fn material_of<T: Real>(m: *const AmpmMaterial<T>) -> Call<Material<T>> {
    if m.is_null() {
        return Err(AmpmStatus::AMPM_ERR_NULL_POINTER);
    }
    let m = ptr::read_unaligned(m);
    let known = AMPM_MODEL_PLASTIC
        | AMPM_MODEL_THERMAL
        | AMPM_MODEL_PHASE_CHANGE
        | AMPM_MODEL_PRESSURE_SOLVE
        | AMPM_MODEL_PSD_HESSIAN;
    let thermal = m.model & AMPM_MODEL_THERMAL != 0;
    let phase_change = m.model & AMPM_MODEL_PHASE_CHANGE != 0;
    if m.model & !known != 0 || (phase_change && !thermal) {
        return Err(AmpmStatus::AMPM_ERR_INVALID_ARGUMENT);
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

/// `n·per` scalars of `T` must be addressable.
fn check_size<T>(n: usize, per: usize) -> Call<()> {
    match n.checked_mul(per * core::mem::size_of::<T>()) {
        Some(b) if b <= isize::MAX as usize => Ok(()),
        _ => Err(AmpmStatus::AMPM_ERR_INVALID_ARGUMENT),
    }
}

/// The particle arrays, with the ones `reads` and the material need checked non-null.
unsafe fn particles_of<T: Real>(
    n: usize,
    p: *const AmpmParticles<T>,
    reads: Reads,
    mat: &Material<T>,
    d: usize,
) -> Call<Particles<T>> {
    if p.is_null() {
        return Err(AmpmStatus::AMPM_ERR_NULL_POINTER);
    }
    check_size::<T>(n, d * d)?;
    let p = ptr::read_unaligned(p);
    let ps = Particles {
        x: p.x,
        v: p.v,
        affine: p.affine,
        f_e: p.f_e,
        f_p: p.f_p,
        mass: p.mass,
        volume0: p.volume0,
        temperature: p.temperature,
        latent: p.latent,
        phase: p.phase,
    };
    if n > 0 && !ps.has(reads, mat) {
        return Err(AmpmStatus::AMPM_ERR_NULL_POINTER);
    }
    Ok(ps)
}

fn nodes_of<const D: usize>(b: &AmpmNodeBox) -> Call<NodeBox<D>> {
    let mut nb = NodeBox {
        lo: [0; D],
        dims: [0; D],
    };
    for a in 0..D {
        if b.dims[a] < 0 {
            return Err(AmpmStatus::AMPM_ERR_INVALID_ARGUMENT);
        }
        nb.lo[a] = b.lo[a];
        nb.dims[a] = b.dims[a];
    }
    Ok(nb)
}

fn stride<const D: usize>(s: &[isize; 3]) -> [isize; D] {
    let mut o = [0; D];
    o.copy_from_slice(&s[..D]);
    o
}

fn out<T, const D: usize>(c: &AmpmChannel<T>) -> Channel<*mut T, D> {
    Channel {
        data: c.data,
        stride: stride(&c.stride),
    }
}

fn inp<T, const D: usize>(c: &AmpmConstChannel<T>) -> Channel<*const T, D> {
    Channel {
        data: c.data,
        stride: stride(&c.stride),
    }
}

unsafe fn read<S: Copy>(p: *const S) -> Call<S> {
    if p.is_null() {
        Err(AmpmStatus::AMPM_ERR_NULL_POINTER)
    } else {
        Ok(ptr::read_unaligned(p))
    }
}

fn finite_h<T: Real>(h: T) -> Call<()> {
    if !h.is_finite() {
        Err(AmpmStatus::AMPM_ERR_NON_FINITE)
    } else if h <= T::ZERO {
        Err(AmpmStatus::AMPM_ERR_INVALID_ARGUMENT)
    } else {
        Ok(())
    }
}

/// P2G batch.
pub(crate) unsafe fn p2g<T: BatchReal, const D: usize>(
    material: *const AmpmMaterial<T>,
    kernel: c_uint,
    grid: c_int,
    h: T,
    impulse_dt: T,
    n: usize,
    particles: *const AmpmParticles<T>,
    view: *const AmpmP2gView<T>,
    first_failed: *mut usize,
) -> AmpmStatus
where
    Dim<D>: LaneDim<D>,
    Mat<T, D>: Matrix<Scalar = T, Vector = [T; D]>,
{
    batch_call(first_failed, || {
        let mat = material_of(material)?;
        let ps = particles_of(n, particles, Reads::ALL, &mat, D)?;
        let v = read(view)?;
        let args = P2gArgs {
            kernel: kernel_of(kernel)?,
            grid: grid_of::<D>(grid)?,
            h,
            impulse_dt,
        };
        finite_h(h)?;
        let view = P2gView {
            nodes: nodes_of::<D>(&v.nodes)?,
            mass: out(&v.mass),
            momentum: core::array::from_fn(|a| out(&v.momentum[a])),
            force: core::array::from_fn(|a| out(&v.force[a])),
            heat_capacity: out(&v.heat_capacity),
            thermal_energy: out(&v.thermal_energy),
            conductivity: out(&v.conductivity),
        };
        Ok(done(p2g::p2g(isa(), &mat, &args, n, &ps, &view)))
    })
}

fn g2p_view<T, const D: usize>(v: &AmpmG2pView<T>) -> Call<G2pView<T, D>> {
    Ok(G2pView {
        nodes: nodes_of::<D>(&v.nodes)?,
        velocity: core::array::from_fn(|a| inp(&v.velocity[a])),
        temperature: inp(&v.temperature),
        temperature_old: inp(&v.temperature_old),
    })
}

/// G2P + update batch; `faces` non-null selects the MAC form.
pub(crate) unsafe fn g2p_update<T: BatchReal, const D: usize>(
    material: *const AmpmMaterial<T>,
    kernel: c_uint,
    h: T,
    dt: T,
    n: usize,
    particles: *const AmpmParticles<T>,
    view: *const AmpmG2pView<T>,
    faces: *const AmpmG2pView<T>,
    mac: bool,
    first_failed: *mut usize,
) -> AmpmStatus
where
    Mat<T, D>: Matrix<Scalar = T, Vector = [T; D]>,
    DefaultSvd: SvdMethod<Mat<T, D>>,
{
    batch_call(first_failed, || {
        let mat = material_of(material)?;
        let ps = particles_of(n, particles, Reads::ALL, &mat, D)?;
        let args = G2pArgs {
            kernel: kernel_of(kernel)?,
            h,
            dt,
        };
        finite_h(h)?;
        if !dt.is_finite() {
            return Err(AmpmStatus::AMPM_ERR_NON_FINITE);
        }
        if dt <= T::ZERO {
            return Err(AmpmStatus::AMPM_ERR_INVALID_ARGUMENT);
        }
        let heat = mat.heat.is_some();
        let empty = AmpmG2pView {
            nodes: AmpmNodeBox {
                lo: [0; 3],
                dims: [0; 3],
            },
            velocity: [AmpmConstChannel {
                data: ptr::null(),
                stride: [0; 3],
            }; 3],
            temperature: AmpmConstChannel {
                data: ptr::null(),
                stride: [0; 3],
            },
            temperature_old: AmpmConstChannel {
                data: ptr::null(),
                stride: [0; 3],
            },
        };
        let cv = if mac && !heat && view.is_null() {
            empty
        } else {
            read(view)?
        };
        let cview = g2p_view::<T, D>(&cv)?;
        let null = |c: &Channel<*const T, D>| c.data.is_null();
        if heat && (null(&cview.temperature) || null(&cview.temperature_old)) {
            return Err(AmpmStatus::AMPM_ERR_NULL_POINTER);
        }
        let fv: Option<[G2pView<T, D>; D]> = if mac {
            if faces.is_null() {
                return Err(AmpmStatus::AMPM_ERR_NULL_POINTER);
            }
            let mut fs = [cview; D];
            for (a, f) in fs.iter_mut().enumerate() {
                *f = g2p_view::<T, D>(&ptr::read_unaligned(faces.add(a)))?;
                if null(&f.velocity[a]) {
                    return Err(AmpmStatus::AMPM_ERR_NULL_POINTER);
                }
            }
            Some(fs)
        } else {
            if cview.velocity.iter().any(null) {
                return Err(AmpmStatus::AMPM_ERR_NULL_POINTER);
            }
            None
        };
        Ok(done(g2p::g2p_update(
            isa(),
            &mat,
            &args,
            n,
            &ps,
            &cview,
            fv.as_ref(),
        )))
    })
}

/// Node range of a set of particles.
pub(crate) unsafe fn node_range<T: Real, const D: usize>(
    kernel: c_uint,
    grid: c_int,
    h: T,
    n: usize,
    x: *const T,
    lo: *mut i32,
    hi: *mut i32,
    first_failed: *mut usize,
) -> AmpmStatus {
    batch_call(first_failed, || {
        let kernel = kernel_of(kernel)?;
        let grid = grid_of::<D>(grid)?;
        if x.is_null() || lo.is_null() || hi.is_null() {
            return Err(AmpmStatus::AMPM_ERR_NULL_POINTER);
        }
        if n == 0 {
            return Err(AmpmStatus::AMPM_ERR_INVALID_ARGUMENT);
        }
        check_size::<T>(n, D)?;
        // `[T; D]` has the layout of D consecutive scalars.
        let xs = core::slice::from_raw_parts(x.cast::<[T; D]>(), n);
        match transfer::node_range(kernel, grid, h, xs) {
            Ok((l, u)) => {
                for a in 0..D {
                    ptr::write_unaligned(lo.add(a), l[a]);
                    ptr::write_unaligned(hi.add(a), u[a]);
                }
                Ok((AmpmStatus::AMPM_OK, n))
            }
            Err((i, e)) => Ok((e.into(), i)),
        }
    })
}

/// Force-differential prepare.
pub(crate) unsafe fn force_prepare<T: BatchReal, const D: usize>(
    material: *const AmpmMaterial<T>,
    n: usize,
    particles: *const AmpmParticles<T>,
    slots: *mut T,
    first_failed: *mut usize,
) -> AmpmStatus
where
    Dim<D>: LaneDim<D>,
    Mat<T, D>: Matrix<Scalar = T, Vector = [T; D]>,
{
    batch_call(first_failed, || {
        let mat = material_of(material)?;
        let ps = particles_of(n, particles, Reads::DEFORMATION, &mat, D)?;
        check_size::<T>(n, ampm_core::particle::implicit::slot_len(D))?;
        if n > 0 && slots.is_null() {
            return Err(AmpmStatus::AMPM_ERR_NULL_POINTER);
        }
        Ok(done(force::prepare::<T, D>(isa(), &mat, n, &ps, slots)))
    })
}

/// Force-differential apply.
pub(crate) unsafe fn force_apply<T: BatchReal, const D: usize>(
    kernel: c_uint,
    h: T,
    n: usize,
    x: *const T,
    slots: *const T,
    view: *const AmpmForceView<T>,
    first_failed: *mut usize,
) -> AmpmStatus
where
    Mat<T, D>: Matrix<Scalar = T, Vector = [T; D]>,
{
    batch_call(first_failed, || {
        let kernel = kernel_of(kernel)?;
        finite_h(h)?;
        let v = read(view)?;
        check_size::<T>(n, ampm_core::particle::implicit::slot_len(D))?;
        let fv = ForceView {
            nodes: nodes_of::<D>(&v.nodes)?,
            du: core::array::from_fn(|a| inp(&v.du[a])),
            df: core::array::from_fn(|a| out(&v.df[a])),
        };
        let missing = fv.du.iter().any(|c| c.data.is_null())
            || fv.df.iter().any(|c| c.data.is_null())
            || (n > 0 && (x.is_null() || slots.is_null()));
        if missing {
            return Err(AmpmStatus::AMPM_ERR_NULL_POINTER);
        }
        Ok(done(force::apply::<T, D>(
            isa(),
            kernel,
            h,
            n,
            x,
            slots,
            &fv,
        )))
    })
}

/// Runs `k` for every particle under the batch contract: the first failure and its index.
fn run(n: usize, mut k: impl FnMut(usize) -> Result<(), Error>) -> (AmpmStatus, usize) {
    let mut first = FirstFailure::new(n);
    for i in 0..n {
        first.note(i, k(i));
    }
    done(first.status())
}

#[inline]
unsafe fn rd_vec<T: Real, const D: usize>(p: *const T, i: usize) -> [T; D] {
    core::array::from_fn(|a| ptr::read_unaligned(p.add(D * i + a)))
}

/// Stencil batch.
pub(crate) unsafe fn stencil<T: Real, const D: usize>(
    kernel: c_uint,
    grid: c_int,
    h: T,
    n: usize,
    x: *const T,
    base: *mut c_int,
    weight: *mut T,
    grad_weight: *mut T,
    first_failed: *mut usize,
) -> AmpmStatus {
    batch_call(first_failed, || {
        let kernel = kernel_of(kernel)?;
        let grid = grid_of::<D>(grid)?;
        let k = kernel.node_count(D);
        if n > 0 && (x.is_null() || base.is_null() || weight.is_null()) {
            return Err(AmpmStatus::AMPM_ERR_NULL_POINTER);
        }
        check_size::<T>(n, k * D)?;
        Ok(run(n, |i| {
            let s = Stencil::<T, D>::new(kernel, grid, h, &rd_vec(x, i))?;
            for a in 0..D {
                ptr::write_unaligned(base.add(D * i + a), s.base[a]);
            }
            for r in 0..k {
                let nd = s.node(r);
                ptr::write_unaligned(weight.add(k * i + r), nd.weight);
                if !grad_weight.is_null() {
                    for a in 0..D {
                        ptr::write_unaligned(grad_weight.add((k * i + r) * D + a), nd.grad[a]);
                    }
                }
            }
            Ok(())
        }))
    })
}

/// Pressure batch.
pub(crate) unsafe fn pressure<T: Real, const D: usize>(
    material: *const AmpmMaterial<T>,
    dt: T,
    n: usize,
    particles: *const AmpmParticles<T>,
    pressure: *mut T,
    coefficient: *mut T,
    first_failed: *mut usize,
) -> AmpmStatus
where
    Mat<T, D>: Matrix<Scalar = T, Vector = [T; D]>,
{
    batch_call(first_failed, || {
        let mat = material_of(material)?;
        let ps = particles_of(n, particles, Reads::DEFORMATION, &mat, D)?;
        Ok(run(n, |i| {
            let p: Particle<T, D> = ps.get(i, Reads::DEFORMATION, &mat)?;
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
                ptr::write_unaligned(pressure.add(i), pr);
            }
            if !coefficient.is_null() {
                ptr::write_unaligned(coefficient.add(i), c);
            }
            Ok(())
        }))
    })
}
