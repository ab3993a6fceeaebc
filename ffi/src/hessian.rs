//! C entry points of the Hessian matrices and the PSD-projected action (issue 3).
