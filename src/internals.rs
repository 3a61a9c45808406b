//! Crate-internal kernels and stages, exposed for the measuring tools in `benches/`
//! (feature `internals`). Not part of the public API: no stability promise.

pub use crate::dwt::fixtures::{
    aligned, cluster_setup, grid_lanes, ClusterInputs, ClusterTables, FloatInputs,
};
pub use crate::dwt::lanes::Rec;
pub use crate::dwt::{forward, forward_parity, inverse, inverse_parity, parity_partial_len};
pub use crate::numeric::Ext;
pub use crate::simd::peak::fma_peak;
pub use crate::symmetry::cluster_pairs;
pub use crate::wigner::recurrence::{RecCoeffs, RecTables};
pub use crate::wigner::starts::{start_norms, BetaTables};
