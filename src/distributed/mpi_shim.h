/* The few MPI calls of so3fft's MPI exchange (mpi_shim.c): communicators cross as their Fortran
 * handles, results as MPI error codes. Used by libso3fft_mpi (so3fft_mpi.c) and, through the
 * Cargo feature `mpi`, by the Rust crate's MpiExchange (src/distributed/mpi.rs). */
#ifndef SO3FFT_MPI_SHIM_H
#define SO3FFT_MPI_SHIM_H

#include <mpi.h>
#include <stddef.h>
#include <stdint.h>

int so3fft_mpi_initialized(int *flag);
int so3fft_mpi_init_thread(int *provided);
int so3fft_mpi_finalize(void);
MPI_Fint so3fft_mpi_comm_world(void);
int so3fft_mpi_rank(MPI_Fint comm, int *rank);
int so3fft_mpi_size(MPI_Fint comm, int *size);
int so3fft_mpi_max_u64(MPI_Fint comm, uint64_t *value);
/* Sends `ns` doubles to `dest` while receiving `nr` from `src`, in pieces. */
int so3fft_mpi_sendrecv(MPI_Fint comm, const double *send, size_t ns, int dest, double *recv,
                        size_t nr, int src);

#endif /* SO3FFT_MPI_SHIM_H */
