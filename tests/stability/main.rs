//! Stability contracts of every polar/SVD method × dim × precision on every family of `F`
//! (`tools/src/families/`), against the double-double reference (`tools/src/reference.rs`);
//! the reference itself; scale invariance; bounded iteration; and the run-time method choice
//! of the C ABI (`ffi/src/methods.rs`). One test binary; each module covers one part:
//!
//! 1. `contracts`: the stability contracts of every method on every family, and the accuracy
//!    of the double-double reference.
//! 2. `methods`: scale invariance, bounded iteration and the edge cases of single methods (QR
//!    small singular values, Higham–Noferini for `det F < 0`, the 2D closed form).
//! 3. `c_abi`: the run-time method choice of the C ABI: the `_ex` calls against the
//!    compile-time methods, invalid options, decompositions, batch failures.
mod c_abi;
mod contracts;
mod methods;
