//! Branch-free Jacobi on FᵀF with approximate Givens rotations (McAdams et al. 2011).
