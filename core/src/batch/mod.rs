//! Structure-of-arrays batch kernels that the compiler vectorizes (issue 3).
