//! What the process and the machine allow: memory and address-space headroom, stack size,
//! and a mutex that survives `fork()`.
//!
//! Everything here reads the operating system's state without allocating, so that it can
//! be asked exactly when an allocation might fail.

mod fork_lock;
mod memory;

pub(crate) use fork_lock::{ForkLock, ForkLockGuard};
pub(crate) use memory::{check_headroom, mem_available, mem_total};
