//! The instruction sets of the batch kernels ([`Isa`]): what the CPU supports, detected at
//! run time, and two per-CPU choices of the particle transfers' AVX-512 build: whether they
//! join two eight-lane rows in one register, and how wide P2G's `f32` chunks are.

/// The instruction sets of the batch kernels, widest first. A value other than
/// [`Isa::SCALAR`] is a promise that the CPU supports it: create it with `Isa::detect` (with
/// the `std` feature) or, unsafely, with [`Isa::assume`].
///
/// With AVX-512 it also carries two choices of the particle transfers, both giving the same
/// bits (but for the sign of a zero node sum with joined rows), set per CPU by `Isa::detect`:
/// - [`Isa::joined_rows`], two eight-lane rows in one sixteen-lane register: on where 512-bit
///   operations run at the full rate of two 256-bit ones without slowing the rest (AMD Zen 5
///   and later), off elsewhere (the joined rows measured 7–13% slower on an Intel Xeon, and
///   P2G and apply 3–10% slower on AMD Zen 4, whose 512-bit operations take two 256-bit
///   passes);
/// - [`Isa::narrow_chunks`], P2G's `f32` chunks of two sixteen-lane vectors instead of four:
///   on for AMD Zen 4 (P2G + G2P 1–4% faster there), off elsewhere (four vectors measured
///   6–7% faster on an Intel Xeon, and 0–1.4% faster on AMD Zen 5).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Isa(IsaKind, bool, bool);

/// What an [`Isa`] names.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum IsaKind {
    /// One particle at a time (`f32`/`f64` lanes); every target.
    Scalar,
    /// x86-64 AVX2 + FMA: `f32×8`, `f64×4`.
    Avx2,
    /// x86-64 AVX-512 F, VL, DQ and BW (+ AVX2 + FMA): `f32×16`, `f64×8`. The particle
    /// transfers' eight-lane rows are built with VL (32 registers, k-masked moves; see
    /// `LaneOp::AVX512_VL`), the kernels with AVX-512F alone.
    Avx512,
}

impl Isa {
    /// The scalar path, available everywhere.
    pub const SCALAR: Isa = Isa(IsaKind::Scalar, false, false);

    /// What this value names.
    #[inline]
    #[must_use]
    pub fn kind(self) -> IsaKind {
        self.0
    }

    /// Short name for reports: "scalar", "avx2", "avx512".
    #[inline]
    #[must_use]
    pub fn name(self) -> &'static str {
        match self.0 {
            IsaKind::Scalar => "scalar",
            IsaKind::Avx2 => "avx2",
            IsaKind::Avx512 => "avx512",
        }
    }

    /// This instruction set, or AVX2 in place of AVX-512 (which implies it): for loops whose
    /// AVX-512 build is slower than their AVX2 build.
    #[inline]
    #[must_use]
    pub fn at_most_avx2(self) -> Isa {
        match self.0 {
            IsaKind::Avx512 => Isa(IsaKind::Avx2, false, false),
            _ => self,
        }
    }

    /// Whether the particle transfers (P2G, the force differential's apply) sum two eight-lane
    /// node rows in one sixteen-lane register: AVX-512 `f32` in 3D. The same bits either way,
    /// but for the sign of a zero node sum (see `particle/transfer/tile.rs`).
    #[inline]
    #[must_use]
    pub fn joined_rows(self) -> bool {
        self.1
    }

    /// This instruction set with joined rows on or off ([`Isa::joined_rows`]; always off for
    /// instruction sets other than AVX-512, whose instructions they use).
    #[inline]
    #[must_use]
    pub fn with_joined_rows(self, on: bool) -> Isa {
        Isa(self.0, on && self.0 == IsaKind::Avx512, self.2)
    }

    /// Whether P2G runs its `f32` chunks on two sixteen-lane vectors (32 lanes) instead of
    /// four (64): AVX-512 without joined rows (joined rows keep four vectors). The same bits
    /// either way: a particle's values do not depend on its chunk.
    #[inline]
    #[must_use]
    pub fn narrow_chunks(self) -> bool {
        self.2
    }

    /// This instruction set with narrow P2G chunks on or off ([`Isa::narrow_chunks`]; always
    /// off for instruction sets other than AVX-512).
    #[inline]
    #[must_use]
    pub fn with_narrow_chunks(self, on: bool) -> Isa {
        Isa(self.0, self.1, on && self.0 == IsaKind::Avx512)
    }

    /// An [`Isa`] of the given kind without checking the CPU (rows not joined, chunks not
    /// narrow).
    ///
    /// # Safety
    /// The CPU running every kernel called with the result must support the kind's
    /// instructions (AVX2 and FMA; for [`IsaKind::Avx512`] also AVX-512 F, VL, DQ and BW).
    #[inline]
    #[must_use]
    pub const unsafe fn assume(kind: IsaKind) -> Isa {
        Isa(kind, false, false)
    }

    /// The widest instruction set of this CPU (detected at run time). Detection runs `cpuid`,
    /// which a virtual machine traps (microseconds per call): detect once and keep the value.
    #[cfg(feature = "std")]
    #[inline]
    #[must_use]
    pub fn detect() -> Isa {
        Self::available().last().copied().unwrap_or(Isa::SCALAR)
    }

    /// Every instruction set this CPU supports, scalar first (for tests and benchmarks).
    #[cfg(feature = "std")]
    #[must_use]
    pub fn available() -> std::vec::Vec<Isa> {
        let mut v = std::vec![Isa::SCALAR];
        #[cfg(target_arch = "x86_64")]
        {
            if std::is_x86_feature_detected!("avx2") && std::is_x86_feature_detected!("fma") {
                v.push(Isa(IsaKind::Avx2, false, false));
                if std::is_x86_feature_detected!("avx512f")
                    && std::is_x86_feature_detected!("avx512vl")
                    && std::is_x86_feature_detected!("avx512dq")
                    && std::is_x86_feature_detected!("avx512bw")
                {
                    let family = amd_family();
                    // Zen 5 (1Ah) and later: joined rows; Zen 4 (19h): narrow chunks.
                    v.push(Isa(
                        IsaKind::Avx512,
                        family >= Some(0x1a),
                        family == Some(0x19),
                    ));
                }
            }
        }
        v
    }
}

/// The family of an AMD CPU (`cpuid` leaf 1, base plus extended family), `None` for other
/// vendors. AMD family 1Ah (Zen 5) runs 512-bit vector operations at the rate of two 256-bit
/// ones; family 19h (Zen 4) splits them into two 256-bit halves; Intel's server cores fuse two
/// ports for them.
#[cfg(all(feature = "std", target_arch = "x86_64"))]
fn amd_family() -> Option<u32> {
    use core::arch::x86_64::__cpuid;
    let (v, f) = (__cpuid(0), __cpuid(1));
    let amd = (v.ebx, v.edx, v.ecx) == (0x6874_7541, 0x6974_6e65, 0x444d_4163);
    let base = (f.eax >> 8) & 0xf;
    let family = if base == 0xf {
        base + ((f.eax >> 20) & 0xff)
    } else {
        base
    };
    amd.then_some(family)
}
