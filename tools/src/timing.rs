//! Wall-clock time per particle: the median over repetitions of one pass over a batch.
//!
//! One pass calls the kernel once per particle of the batch (inputs and results through
//! `std::hint::black_box`, so nothing is hoisted or dropped); the time of a pass divided by
//! the batch size is one sample, and the median of the samples is reported (robust to the
//! other processes sharing this machine's two cores). The first pass warms caches and the
//! branch predictors and is discarded. Single-threaded: the whole report runs on one core.

use std::time::Instant;

/// Median nanoseconds per particle of `pass`, which processes `n` particles, over `reps`
/// timed passes (after one untimed warm-up pass).
#[must_use]
#[inline]
pub fn median_ns_per_particle(n: usize, reps: usize, mut pass: impl FnMut()) -> f64 {
    pass();
    let mut samples: Vec<f64> = (0..reps.max(1))
        .map(|_| {
            let t = Instant::now();
            pass();
            t.elapsed().as_secs_f64() * 1e9 / n.max(1) as f64
        })
        .collect();
    samples.sort_by(f64::total_cmp);
    let m = samples.len();
    if m % 2 == 1 {
        samples[m / 2]
    } else {
        0.5 * (samples[m / 2 - 1] + samples[m / 2])
    }
}
