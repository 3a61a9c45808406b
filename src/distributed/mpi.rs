//! [`MpiExchange`]: the [`Exchange`] of a distributed plan over an MPI communicator
//! (feature `mpi`; the few MPI calls are in `mpi_shim.c`, compiled against the MPI
//! installation's header).

use super::exchange::Exchange;
use crate::error::{Error, Result};
use std::ffi::c_int;

extern "C" {
    fn so3fft_mpi_initialized(flag: *mut c_int) -> c_int;
    fn so3fft_mpi_init_thread(provided: *mut c_int) -> c_int;
    fn so3fft_mpi_finalize() -> c_int;
    fn so3fft_mpi_comm_world() -> c_int;
    fn so3fft_mpi_rank(comm: c_int, rank: *mut c_int) -> c_int;
    fn so3fft_mpi_size(comm: c_int, size: *mut c_int) -> c_int;
    fn so3fft_mpi_max_u64(comm: c_int, value: *mut u64) -> c_int;
    fn so3fft_mpi_sendrecv(
        comm: c_int,
        send: *const f64,
        ns: usize,
        dest: c_int,
        recv: *mut f64,
        nr: usize,
        src: c_int,
    ) -> c_int;
}

fn mpi_error(what: &str, code: c_int) -> Error {
    Error::Resources(format!("MPI: {what} failed with error code {code}"))
}

/// Initialises MPI for a program that has not (`MPI_THREAD_SERIALIZED`: the plans call MPI
/// from the thread that executes them); a no-op if MPI is initialised already.
pub fn mpi_init() -> Result<()> {
    let mut flag = 0;
    // SAFETY: MPI_Initialized may be called at any time; `flag` is a valid out-pointer.
    let e = unsafe { so3fft_mpi_initialized(&mut flag) };
    if e != 0 {
        return Err(mpi_error("MPI_Initialized", e));
    }
    if flag == 0 {
        let mut provided = 0;
        // SAFETY: MPI is not initialised yet (checked above); `provided` is valid.
        let e = unsafe { so3fft_mpi_init_thread(&mut provided) };
        if e != 0 {
            return Err(mpi_error("MPI_Init_thread", e));
        }
    }
    Ok(())
}

/// Finalises MPI (after the last distributed plan of the program is dropped).
pub fn mpi_finalize() -> Result<()> {
    // SAFETY: the caller's program is done with MPI (this function's contract in words).
    let e = unsafe { so3fft_mpi_finalize() };
    if e != 0 {
        return Err(mpi_error("MPI_Finalize", e));
    }
    Ok(())
}

/// An MPI communicator as a distributed plan's group of ranks.
pub struct MpiExchange {
    comm: c_int,
    rank: usize,
    size: usize,
}

impl MpiExchange {
    /// `MPI_COMM_WORLD` (MPI must be initialised: [`mpi_init`]).
    pub fn world() -> Result<MpiExchange> {
        // SAFETY: no arguments; returns the Fortran handle of MPI_COMM_WORLD.
        Self::from_fortran_handle(unsafe { so3fft_mpi_comm_world() })
    }

    /// The communicator with Fortran handle `comm` (`MPI_Comm_c2f` of a C communicator).
    pub fn from_fortran_handle(comm: c_int) -> Result<MpiExchange> {
        let mut flag = 0;
        // SAFETY: `flag` is a valid out-pointer.
        unsafe { so3fft_mpi_initialized(&mut flag) };
        if flag == 0 {
            return Err(Error::InvalidArgument("MPI is not initialised".into()));
        }
        let (mut rank, mut size) = (0, 0);
        // SAFETY: MPI is initialised; the out-pointers are valid.
        let e = unsafe { so3fft_mpi_rank(comm, &mut rank) };
        if e != 0 {
            return Err(mpi_error("MPI_Comm_rank", e));
        }
        // SAFETY: as above.
        let e = unsafe { so3fft_mpi_size(comm, &mut size) };
        if e != 0 {
            return Err(mpi_error("MPI_Comm_size", e));
        }
        Ok(MpiExchange {
            comm,
            rank: rank as usize,
            size: size as usize,
        })
    }
}

// SAFETY: the handle is an integer; MPI is called only from the thread that executes a plan
// (MPI_THREAD_SERIALIZED), never from the plan's workers.
unsafe impl Sync for MpiExchange {}

impl Exchange for MpiExchange {
    fn rank(&self) -> usize {
        self.rank
    }

    fn size(&self) -> usize {
        self.size
    }

    fn sendrecv(&self, send: &[f64], dest: usize, recv: &mut [f64], src: usize) -> Result<()> {
        // SAFETY: `send` and `recv` are valid for their lengths; MPI uses them during the
        // call only.
        let e = unsafe {
            so3fft_mpi_sendrecv(
                self.comm,
                send.as_ptr(),
                send.len(),
                dest as c_int,
                recv.as_mut_ptr(),
                recv.len(),
                src as c_int,
            )
        };
        if e != 0 {
            return Err(mpi_error("MPI_Sendrecv", e));
        }
        Ok(())
    }

    fn max(&self, value: u64) -> Result<u64> {
        let mut v = value;
        // SAFETY: `v` is a valid in/out value.
        let e = unsafe { so3fft_mpi_max_u64(self.comm, &mut v) };
        if e != 0 {
            return Err(mpi_error("MPI_Allreduce", e));
        }
        Ok(v)
    }
}
