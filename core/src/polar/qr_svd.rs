//! Implicit-shifted QR SVD on F itself (Gast, Fu, Jiang, Teran 2016).
