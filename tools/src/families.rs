//! Families of deformation gradients with stated contracts (issue 3).
