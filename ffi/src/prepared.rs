//! C entry points of the combined kernel call, the prepared Hessian (prepare once per Newton
//! step, apply once per Krylov iteration) and the instruction-set choice of the batch calls.
//!
//! The per-type wrappers are rendered from `ffi/api/prepared.rs` into `generated/prepared.rs`
//! and delegate to the generic bodies in `crate::fast`; the instruction-set functions, which
//! exist once, are written here.

use crate::fast;
use crate::status::AmpmStatus;

pub use crate::generated::prepared::*;

/// `ampm_set_isa` / `ampm_isa`: one particle per lane, no SIMD (every CPU).
pub const AMPM_ISA_SCALAR: u32 = 0;
/// `ampm_set_isa` / `ampm_isa`: x86-64 AVX2 + FMA, 16 f32 or 8 f64 particles per step.
pub const AMPM_ISA_AVX2: u32 = 1;
/// `ampm_set_isa` / `ampm_isa`: x86-64 AVX-512 (F, VL, DQ, BW), 32 f32 or 16 f64 particles per step.
/// On CPUs that run 512-bit operations at the full rate of two 256-bit ones (AMD Zen 5 and
/// later, detected at run time), 3D f32 `ampm_p2g_*` and `ampm_force_apply_*` sum two node
/// channels per 512-bit register; elsewhere (Intel, where that measured slower) one per 256-bit
/// row. The results are the same bits either way, and the same as under AMPM_ISA_AVX2, but for
/// the sign of a zero: a node that held −0 and receives only zero contributions may become +0.
/// On AMD Zen 4 (family 19h, whose 512-bit operations take two 256-bit passes), f32
/// `ampm_p2g_*` works on 32 particles at a time instead of 64 (measured 1–4% faster there);
/// the same bits.
pub const AMPM_ISA_AVX512: u32 = 2;

/// Chooses the instruction set of every batch call (`AMPM_ISA_*`); by default the widest the
/// CPU supports, detected on first use. Under `AMPM_ISA_AVX512` the G2P calls
/// (`ampm_g2p_update_*`) run their AVX2 code, which is faster for them.
///
/// Returns `AMPM_ERR_INVALID_ARGUMENT` (and changes nothing) for a value this CPU does not
/// support. Results are identical on the AVX2 and AVX-512 paths; the scalar path agrees with
/// them to a few ulps times the conditioning of F. The choice is one process-wide value: set
/// it once at start-up, before other threads call the library.
#[no_mangle]
pub extern "C" fn ampm_set_isa(isa: u32) -> AmpmStatus {
    fast::set_isa(isa)
}

/// The instruction set the batch calls use (`AMPM_ISA_*`).
#[no_mangle]
pub extern "C" fn ampm_isa() -> u32 {
    fast::current_isa()
}
