//! Polar-only method: Higham–Noferini 2016 (dominant eigenvector of a 4×4 symmetric matrix).
