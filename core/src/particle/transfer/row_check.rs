//! A test harness: runs a check with the row type of an instruction set (its
//! [`LaneOp::run_rows`]) and the node count per axis of the check's kernel.

use crate::kernel::batch::{BatchStatus, LaneOp};
use crate::lane::Lane;
use crate::particle::Kernel;
use crate::scalar::Real;

/// A check that runs on a row type `R` with `K` nodes per axis.
pub(crate) trait RowCheck<T> {
    /// The kernel whose node count the check runs with.
    fn kernel(&self) -> Kernel;
    /// The check on row type `R`, `K` nodes per axis.
    fn rows<R: Lane<Scalar = T>, const K: usize>(&mut self);
}

/// A [`RowCheck`] as a [`LaneOp`], for `dispatch`.
pub(crate) struct ByRows<'a, C>(pub &'a mut C);

impl<T: Real, C: RowCheck<T>> LaneOp<T> for ByRows<'_, C> {
    fn run<V: Lane<Scalar = T>>(&mut self) -> BatchStatus {
        BatchStatus {
            first_failed: 0,
            error: None,
        }
    }

    fn run_rows<V: Lane<Scalar = T>, R: Lane<Scalar = T>>(&mut self) -> BatchStatus {
        match self.0.kernel() {
            Kernel::Quadratic => self.0.rows::<R, 3>(),
            Kernel::Cubic => self.0.rows::<R, 4>(),
        }
        self.run::<V>()
    }
}
