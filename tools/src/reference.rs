//! Double-double reference for R, Σ, Ψ̂, Â and Ĉ:Z (issue 3).
