//! The integer matrices (entries in `{−2, …, 2}`, indexed by their base-5 digits) and the
//! signed permutations that map them onto each other: the orbits of the full integer families.

use super::Size;
use ampm_core::Mat;
use rand::Rng;
use rand_pcg::Pcg64;

// The docs link this.
#[cfg(doc)]
use super::generate;

/// The `i`-th signed permutation matrix of dimension `D` (`i < 2ᴰ·D!`): permutation
/// `i / 2ᴰ` in lexicographic order, sign bits `i % 2ᴰ` (bit `j` negates column `j`).
#[must_use]
pub fn signed_perm<const D: usize>(i: u8) -> Mat<f64, D> {
    let signs = usize::from(i) % (1 << D);
    let mut k = usize::from(i) >> D;
    // Lehmer code → permutation.
    let mut avail: Vec<usize> = (0..D).collect();
    let mut perm = [0usize; D];
    let mut fact: usize = (1..D).product();
    for (j, p) in perm.iter_mut().enumerate() {
        let idx = k / fact.max(1);
        k %= fact.max(1);
        *p = avail.remove(idx);
        if j + 1 < D {
            fact /= D - 1 - j;
        }
    }
    let mut m = Mat::<f64, D>::ZERO;
    for (j, &p) in perm.iter().enumerate() {
        m.cols[j][p] = if signs >> j & 1 == 1 { -1.0 } else { 1.0 };
    }
    m
}

/// Number of signed permutations of dimension `D`, `2ᴰ·D!`.
#[must_use]
pub fn signed_perm_count<const D: usize>() -> usize {
    (1 << D) * (1..=D).product::<usize>()
}

/// Index (base-5 digits of the entries + 2, column-major) of an integer matrix.
pub(super) fn integer_index<const D: usize>(m: &Mat<f64, D>) -> u64 {
    let mut idx = 0u64;
    for j in (0..D).rev() {
        for i in (0..D).rev() {
            idx = idx * 5 + (m.cols[j][i] + 2.0) as u64;
        }
    }
    idx
}

/// The integer matrix of index `idx < 5^(d²)`: base-5 digits minus 2, column-major.
pub(super) fn integer_matrix<const D: usize>(mut idx: u64) -> Mat<f64, D> {
    let mut m = Mat::<f64, D>::ZERO;
    for j in 0..D {
        for i in 0..D {
            m.cols[j][i] = (idx % 5) as f64 - 2.0;
            idx /= 5;
        }
    }
    m
}

/// Indices of the integer matrices of the reduced size: a seeded subset of 4 000 (in 2D all
/// 625). (The full size goes orbit by orbit, see [`generate`].)
pub(super) fn integer_indices<const D: usize>(size: Size, rng: &mut Pcg64) -> Vec<u64> {
    let total = 5u64.pow((D * D) as u32);
    match size {
        Size::Full => (0..total).collect(),
        Size::Reduced if total <= 4000 => (0..total).collect(),
        Size::Reduced => (0..4000).map(|_| rng.random_range(0..total)).collect(),
    }
}
