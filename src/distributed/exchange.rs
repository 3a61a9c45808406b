//! [`Exchange`]: what a [`DistributedPlan`](super::DistributedPlan) needs of its group of
//! processes, and [`ThreadExchange`], its implementation among the threads of one process
//! (the MPI one is in `mpi.rs`).

use crate::error::{Error, Result};

/// What a distributed plan needs of its group of processes. Every method is collective:
/// all ranks call it, in the same order.
pub trait Exchange: Sync {
    /// This process's rank, `0 .. size`.
    fn rank(&self) -> usize;
    /// Number of ranks.
    fn size(&self) -> usize;
    /// Sends `send` to rank `dest` and receives into `recv` what rank `src` sends here (every
    /// rank calls it at once, each with its own pair; lengths agree pairwise: the callers
    /// compute them from the same plan).
    fn sendrecv(&self, send: &[f64], dest: usize, recv: &mut [f64], src: usize) -> Result<()>;
    /// The largest of the ranks' `value`s, on every rank.
    fn max(&self, value: u64) -> Result<u64>;
}

impl<T: Exchange + ?Sized> Exchange for &T {
    fn rank(&self) -> usize {
        (**self).rank()
    }
    fn size(&self) -> usize {
        (**self).size()
    }
    fn sendrecv(&self, send: &[f64], dest: usize, recv: &mut [f64], src: usize) -> Result<()> {
        (**self).sendrecv(send, dest, recv, src)
    }
    fn max(&self, value: u64) -> Result<u64> {
        (**self).max(value)
    }
}

/// An [`Exchange`] among threads of one process (for tests and for trying the distributed
/// layout without MPI): [`ThreadExchange::group`] makes the members, one per thread.
pub struct ThreadExchange {
    rank: usize,
    shared: std::sync::Arc<Shared>,
}

struct Shared {
    size: usize,
    barrier: std::sync::Barrier,
    mailbox: std::sync::Mutex<Vec<Vec<f64>>>,
    values: std::sync::Mutex<Vec<u64>>,
}

impl ThreadExchange {
    /// `size` members, rank `r` at index `r`; each must be used by its own thread.
    pub fn group(size: usize) -> Vec<ThreadExchange> {
        let shared = std::sync::Arc::new(Shared {
            size,
            barrier: std::sync::Barrier::new(size),
            mailbox: std::sync::Mutex::new(vec![Vec::new(); size * size]),
            values: std::sync::Mutex::new(vec![0; size]),
        });
        (0..size)
            .map(|rank| ThreadExchange {
                rank,
                shared: shared.clone(),
            })
            .collect()
    }
}

impl Exchange for ThreadExchange {
    fn rank(&self) -> usize {
        self.rank
    }

    fn size(&self) -> usize {
        self.shared.size
    }

    fn sendrecv(&self, send: &[f64], dest: usize, recv: &mut [f64], src: usize) -> Result<()> {
        let (p, me) = (self.shared.size, self.rank);
        {
            let mut mail = self
                .shared
                .mailbox
                .lock()
                .unwrap_or_else(|e| e.into_inner());
            mail[me * p + dest] = send.to_vec();
        }
        self.shared.barrier.wait();
        let data = {
            let mut mail = self
                .shared
                .mailbox
                .lock()
                .unwrap_or_else(|e| e.into_inner());
            std::mem::take(&mut mail[src * p + me])
        };
        self.shared.barrier.wait();
        if data.len() != recv.len() {
            return Err(Error::InvalidArgument(
                "exchange: message lengths differ".into(),
            ));
        }
        recv.copy_from_slice(&data);
        Ok(())
    }

    fn max(&self, value: u64) -> Result<u64> {
        self.shared.values.lock().unwrap_or_else(|e| e.into_inner())[self.rank] = value;
        self.shared.barrier.wait();
        let m = self
            .shared
            .values
            .lock()
            .unwrap_or_else(|e| e.into_inner())
            .iter()
            .copied()
            .max()
            .unwrap_or(0);
        self.shared.barrier.wait();
        Ok(m)
    }
}
