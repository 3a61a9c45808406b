//! SOFT 2.0's spherical-harmonic (S^2) entry points, on the native [`S2Plan`](crate::s2::S2Plan)
//! (docs/conventions-s2.md):
//!
//! - `transforms`: `FST_semi_memo`, `InvFST_semi_memo` (`s2_semi_memo.h`), `FST_semi_fly`,
//!   `InvFST_semi_fly` (`s2_semi_fly.h`);
//! - `tables`: the Legendre table sizes and table builders of `s2_cospmls.h`;
//! - `primitive`: the helpers of `s2_primitive.h` and the per-order Legendre sums of
//!   `s2_legendreTransforms.h`.
//!
//! The transforms ignore the caller's Legendre tables, FFTW plans and workspace (never read
//! or written); results do not depend on `cutoff`. The tables have SOFT's sizes and pointer
//! arrays from C `malloc` (the caller frees them with `free()`).

mod primitive;
mod tables;
mod transforms;

pub(in crate::soft) use transforms::s2_plan_for;
#[cfg(test)]
pub(in crate::soft) use transforms::FST_semi_memo;
