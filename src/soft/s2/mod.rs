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

pub use primitive::{
    transpose, vec_add, vec_mul, vec_pt_mul, ArcCosEvalPts, EvalPts, L2_an, L2_cn, Naive_AnalysisX,
    Naive_SynthesizeX, Pmm_L2,
};
pub use tables::{
    CosPmlTableGen, NewTableOffset, PmlTableGen, Reduced_Naive_TableSize,
    Reduced_SpharmonicTableSize, RowSize, SemiNaive_Naive_Pml_Table, Spharmonic_Pml_Table,
    Spharmonic_TableSize, TableSize, Transpose_CosPmlTableGen, Transpose_RowSize,
    Transpose_SemiNaive_Naive_Pml_Table, Transpose_Spharmonic_Pml_Table,
};
pub(in crate::soft) use transforms::s2_plan_for;
pub use transforms::{FST_semi_fly, FST_semi_memo, InvFST_semi_fly, InvFST_semi_memo};
