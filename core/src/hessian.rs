//! Explicit Hessian matrices of Ψ̂ and the PSD-projected action Ĉ⁺:Z (issue 3).
