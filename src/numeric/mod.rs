//! Arithmetic beyond plain doubles: double-double values ([`Dd`]) and numbers with an
//! extended exponent ([`Ext`], [`ExtDd`]), from which the Wigner-d tables and quadrature
//! weights are built with one rounding each.

mod double_double;
mod elem;
#[cfg(test)]
pub(crate) mod exact;
mod ext;

pub(crate) use double_double::{sin_cos_dd, Dd, PI_DD};
pub use elem::Elem;
pub use ext::Ext;
pub(crate) use ext::{frexp, ldexp, ExtDd};
