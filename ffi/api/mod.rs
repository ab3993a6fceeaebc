//! The description of the C entry points that exist once per dimension × precision: one [`Op`]
//! per op, which `ffi/tests/wrappers.rs` renders four times (`_2d_f32`, `_2d_f64`, `_3d_f32`,
//! `_3d_f64`) into `ffi/src/generated/<module>.rs`. cbindgen reads the rendered wrappers (it
//! does not expand macros, hence the rendering) and copies each doc into `include/ampm.h`, so
//! the doc of an op and its signature come from the same entry here.
//!
//! # How to add an op
//!
//! 1. Write its body once, generic over the scalar and the dimension, in the module that owns
//!    the op, visible to the crate (`pub(crate)`).
//! 2. Add an [`Op`] to the list of that module in `ffi/api/<module>.rs`:
//!
//!    ```ignore
//!    Op {
//!        name: "ahat", // the symbols ampm_ahat_2d_f32 … ampm_ahat_3d_f64
//!        doc: "
//!            Computes Â = ∂Ψ̂/∂F, the first Piola–Kirchhoff stress of … (first line: summary).
//!
//!            `mu` ≥ 0 (Pa); `f`: {DxD} column-major input; `out`: {DxD} stress (Pa).",
//!        params: &["mu: {T}", "f: *const {T}", "out: *mut {T}"],
//!        ret: "AmpmStatus",
//!        body: "fast::single::<{T}, {D}>(mu, f, ptr::null(), out, ptr::null_mut(), ptr::null_mut(), false)",
//!    },
//!    ```
//!
//!    A pointer the call only reads is `*const` (`const T *` in C); `*mut` is for what it
//!    writes. A new module needs its own file here with a [`Module`], an entry in [`MODULES`],
//!    and `pub use crate::generated::<module>::*;` in the module that owns it.
//! 3. Run `AMPM_BLESS=1 cargo test -p ampm-ffi --test wrappers`, which rewrites
//!    `ffi/src/generated/`, then `AMPM_BLESS=1 cargo test -p ampm-ffi --test header`, which
//!    regenerates `include/ampm.h` from it (two commands: the header is read from the rendered
//!    wrappers); commit them with the description. Without `AMPM_BLESS` both tests fail when a
//!    checked-in file differs from what its source gives.
//!
//! Placeholders `{NAME}` in `doc`, `params`, `ret` and `body`: `{D}` (2 or 3), `{T}` (f32 or
//! f64), `{sfx}` (the symbol suffix, e.g. `2d_f32`), the per-dimension values of [`DIM_VARS`]
//! and the paragraphs of [`TEXTS`]; `{{` and `}}` are literal braces. The renderer fails on an
//! unknown placeholder, on a parameter the doc does not name in backticks, on a doc that
//! mentions a Rust source file, and on a symbol defined twice. `doc` and `body` may span lines;
//! their common indentation is removed.

mod fields;
mod force;
mod hessian;
mod kernels;
mod kernels_batch;
mod methods;
mod particle;
mod prepared;

/// One C entry point per dimension × precision.
pub struct Op {
    /// The op's name: the symbols are `ampm_<name>_<2d|3d>_<f32|f64>`.
    pub name: &'static str,
    /// The doc comment, i.e. the header's documentation of the function. First line: one
    /// sentence saying what it computes; then the parameters, each named in backticks.
    pub doc: &'static str,
    /// The parameters, `"name: Rust type"`, in order.
    pub params: &'static [&'static str],
    /// The Rust return type (`AmpmStatus` for every call that can fail).
    pub ret: &'static str,
    /// The body: one call of the op's generic implementation.
    pub body: &'static str,
}

/// The ops rendered into one file, `ffi/src/generated/<name>.rs`.
pub struct Module {
    /// The module's name, as in `crate::generated::<name>`.
    pub name: &'static str,
    /// The generated file's module doc (Rust only; not in the header).
    pub doc: &'static str,
    /// The `use` paths the bodies and parameter types need.
    pub uses: &'static [&'static str],
    /// The ops, in the order of the header.
    pub ops: &'static [Op],
}

/// Every module, in the order of the header.
pub const MODULES: &[Module] = &[
    kernels::MODULE,
    kernels_batch::MODULE,
    prepared::MODULE,
    hessian::MODULE,
    methods::MODULE,
    particle::MODULE,
    force::MODULE,
    fields::MODULE,
];

/// Placeholders whose value depends on the dimension: `(name, in 2D, in 3D)`.
pub const DIM_VARS: &[(&str, &str, &str)] = &[
    // A d×d matrix and its number of scalars.
    ("DxD", "2×2", "3×3"),
    ("DD", "4", "9"),
    // The exponent a of Jᵃ in F̂ = JᵃF, a = −1/d.
    ("a", "−1/2", "−1/3"),
    // The explicit Hessian: a d²×d² matrix and its number of scalars.
    ("WxW", "4×4", "9×9"),
    ("WW", "16", "81"),
    // The index of the last singular value.
    ("last", "1", "2"),
    // Scalars of one prepared-Hessian slot (`ampm_hessian_len_*`).
    ("PREP", "18", "38"),
];

/// Placeholders for paragraphs shared by several docs: `(name, text)`. A text may hold other
/// placeholders; its common indentation is removed as in `doc`.
pub const TEXTS: &[(&str, &str)] = &[
    (
        "BATCH",
        "Batch call (see the batch contract at the top of this header): every valid particle is
        computed and a failed particle's outputs are left untouched; returns the first failure's
        status and writes its index (`n` if none) to `*first_failed` (may be NULL). Arrays may
        be NULL when `n` = 0.",
    ),
    (
        "OPTS",
        "`opts`: the polar/SVD method (see AmpmOptions), NULL for the defaults; an invalid
        choice is AMPM_ERR_INVALID_ARGUMENT.",
    ),
];
