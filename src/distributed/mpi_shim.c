/* The few MPI calls of so3fft's MPI exchange, compiled against the MPI installation's own
 * header, so their callers see only plain C types: communicators cross as their Fortran handles
 * (MPI_Comm_c2f / MPI_Comm_f2c), results as MPI error codes. Part of libso3fft_mpi, and of the
 * Rust crate with the feature `mpi`. */
#include "mpi_shim.h"

/* Doubles per MPI message: counts are `int`, so large blocks go in pieces of 1 GiB. */
#define SO3FFT_MPI_PIECE ((size_t)1 << 27)

int so3fft_mpi_initialized(int *flag) { return MPI_Initialized(flag); }

int so3fft_mpi_init_thread(int *provided) {
    return MPI_Init_thread(NULL, NULL, MPI_THREAD_SERIALIZED, provided);
}

int so3fft_mpi_finalize(void) { return MPI_Finalize(); }

MPI_Fint so3fft_mpi_comm_world(void) { return MPI_Comm_c2f(MPI_COMM_WORLD); }

int so3fft_mpi_rank(MPI_Fint comm, int *rank) { return MPI_Comm_rank(MPI_Comm_f2c(comm), rank); }

int so3fft_mpi_size(MPI_Fint comm, int *size) { return MPI_Comm_size(MPI_Comm_f2c(comm), size); }

int so3fft_mpi_max_u64(MPI_Fint comm, uint64_t *value) {
    return MPI_Allreduce(MPI_IN_PLACE, value, 1, MPI_UINT64_T, MPI_MAX, MPI_Comm_f2c(comm));
}

int so3fft_mpi_sendrecv(MPI_Fint comm, const double *send, size_t ns, int dest, double *recv,
                        size_t nr, int src) {
    MPI_Comm c = MPI_Comm_f2c(comm);
    size_t at_s = 0, at_r = 0;
    int tag = 0;
    /* Exactly ceil(n / piece) messages each way, none for an empty block: a side with nothing
     * left talks to MPI_PROC_NULL, so no empty message is left queued for a later exchange,
     * and both partners agree on the pieces (their lengths agree pairwise). */
    while (at_s < ns || at_r < nr) {
        size_t ks = ns - at_s < SO3FFT_MPI_PIECE ? ns - at_s : SO3FFT_MPI_PIECE;
        size_t kr = nr - at_r < SO3FFT_MPI_PIECE ? nr - at_r : SO3FFT_MPI_PIECE;
        int to = ks > 0 ? dest : MPI_PROC_NULL, from = kr > 0 ? src : MPI_PROC_NULL, got = 0;
        MPI_Status status;
        int err = MPI_Sendrecv(send + at_s, (int)ks, MPI_DOUBLE, to, tag, recv + at_r, (int)kr,
                               MPI_DOUBLE, from, tag, c, &status);
        if (err != MPI_SUCCESS) return err;
        if (kr > 0) {
            err = MPI_Get_count(&status, MPI_DOUBLE, &got);
            if (err != MPI_SUCCESS) return err;
            if ((size_t)got != kr) return MPI_ERR_TRUNCATE;
        }
        at_s += ks;
        at_r += kr;
        tag = (tag + 1) % 32768;
    }
    return MPI_SUCCESS;
}

