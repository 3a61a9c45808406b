/*
 * libso3fft_mpi: the distributed plans' C API over MPI (include/so3fft_mpi.h). libso3fft runs
 * the plans and takes the group of processes as a table of callbacks (its private so3fft_dist_*
 * entry points, src/capi/distributed.rs); this library fills the table with MPI calls
 * (mpi_shim.c) and defines the public so3fft_mpi_* names as forwarders. So libso3fft never links
 * MPI, and a program that does not use MPI never loads it. Built by CMake with -DSO3FFT_MPI=ON.
 *
 * Copyright (C) the so3fft authors.
 * SPDX-License-Identifier: GPL-2.0-or-later
 */
#include <stdint.h>

#include "mpi_shim.h"
#include "so3fft_mpi.h"

/* The public names; everything else in this library is hidden (-fvisibility=hidden). */
#define SO3FFT_MPI_EXPORT __attribute__((visibility("default")))

/* libso3fft's side; must match src/capi/distributed.rs. Callbacks return 0 or an MPI error code;
 * `group` returns SO3FFT_DIST_NOT_READY when MPI is not initialised. */
#define SO3FFT_DIST_NOT_READY (-1)
typedef struct so3fft_dist_exchange {
    void *context;
    int (*group)(void *context, int *rank, int *size);
    int (*sendrecv)(void *context, const double *send, size_t ns, int dest, double *recv,
                    size_t nr, int src);
    int (*max_u64)(void *context, uint64_t *value);
} so3fft_dist_exchange;

so3fft_mpi_plan so3fft_dist_plan_partial(const so3fft_shape *shape,
                                         const so3fft_partial_options *options,
                                         unsigned int flags, const so3fft_dist_exchange *exchange);
void so3fft_dist_destroy_plan(so3fft_mpi_plan p);
int so3fft_dist_local_pairs(so3fft_mpi_plan p, int *j0, int *j1);
ptrdiff_t so3fft_dist_local_num_samples(so3fft_mpi_plan p);
ptrdiff_t so3fft_dist_local_num_coeffs(so3fft_mpi_plan p);
ptrdiff_t so3fft_dist_local_workspace(so3fft_mpi_plan p);
int so3fft_dist_groups(so3fft_mpi_plan p);
ptrdiff_t so3fft_dist_coef_owner(so3fft_mpi_plan p, int l, int m, int mp, int *rank);
int so3fft_dist_forward(so3fft_mpi_plan p, so3fft_complex *samples, so3fft_complex *coeffs);
int so3fft_dist_inverse(so3fft_mpi_plan p, so3fft_complex *coeffs, so3fft_complex *samples);
int so3fft_dist_forward_real(so3fft_mpi_plan p, const double *samples, so3fft_complex *coeffs);
int so3fft_dist_inverse_real(so3fft_mpi_plan p, so3fft_complex *coeffs, double *samples);

/* The context is the communicator's Fortran handle, an integer. */
static MPI_Fint comm_of(void *context) { return (MPI_Fint)(intptr_t)context; }

static int group(void *context, int *rank, int *size) {
    int flag = 0, finalized = 0, err = so3fft_mpi_initialized(&flag);
    if (err != MPI_SUCCESS) return err;
    if (!flag) return SO3FFT_DIST_NOT_READY;
    err = MPI_Finalized(&finalized);
    if (err != MPI_SUCCESS) return err;
    if (finalized) return SO3FFT_DIST_NOT_READY;
    err = so3fft_mpi_rank(comm_of(context), rank);
    if (err != MPI_SUCCESS) return err;
    return so3fft_mpi_size(comm_of(context), size);
}

static int sendrecv(void *context, const double *send, size_t ns, int dest, double *recv,
                    size_t nr, int src) {
    return so3fft_mpi_sendrecv(comm_of(context), send, ns, dest, recv, nr, src);
}

static int max_u64(void *context, uint64_t *value) {
    return so3fft_mpi_max_u64(comm_of(context), value);
}

SO3FFT_MPI_EXPORT so3fft_mpi_plan so3fft_mpi_plan_partial_fortran(
    const so3fft_shape *shape, const so3fft_partial_options *options, unsigned int flags,
    int comm) {
    so3fft_dist_exchange exchange;
    exchange.context = (void *)(intptr_t)comm;
    exchange.group = group;
    exchange.sendrecv = sendrecv;
    exchange.max_u64 = max_u64;
    return so3fft_dist_plan_partial(shape, options, flags, &exchange);
}

SO3FFT_MPI_EXPORT void so3fft_mpi_destroy_plan(so3fft_mpi_plan p) { so3fft_dist_destroy_plan(p); }

SO3FFT_MPI_EXPORT int so3fft_mpi_local_pairs(so3fft_mpi_plan p, int *j0, int *j1) {
    return so3fft_dist_local_pairs(p, j0, j1);
}

SO3FFT_MPI_EXPORT ptrdiff_t so3fft_mpi_local_num_samples(so3fft_mpi_plan p) {
    return so3fft_dist_local_num_samples(p);
}

SO3FFT_MPI_EXPORT ptrdiff_t so3fft_mpi_local_num_coeffs(so3fft_mpi_plan p) {
    return so3fft_dist_local_num_coeffs(p);
}

SO3FFT_MPI_EXPORT ptrdiff_t so3fft_mpi_local_workspace(so3fft_mpi_plan p) {
    return so3fft_dist_local_workspace(p);
}

SO3FFT_MPI_EXPORT int so3fft_mpi_groups(so3fft_mpi_plan p) { return so3fft_dist_groups(p); }

SO3FFT_MPI_EXPORT ptrdiff_t so3fft_mpi_coef_owner(so3fft_mpi_plan p, int l, int m, int mp,
                                                  int *rank) {
    return so3fft_dist_coef_owner(p, l, m, mp, rank);
}

SO3FFT_MPI_EXPORT int so3fft_mpi_forward(so3fft_mpi_plan p, so3fft_complex *samples,
                                         so3fft_complex *coeffs) {
    return so3fft_dist_forward(p, samples, coeffs);
}

SO3FFT_MPI_EXPORT int so3fft_mpi_inverse(so3fft_mpi_plan p, so3fft_complex *coeffs,
                                         so3fft_complex *samples) {
    return so3fft_dist_inverse(p, coeffs, samples);
}

SO3FFT_MPI_EXPORT int so3fft_mpi_forward_real(so3fft_mpi_plan p, const double *samples,
                                              so3fft_complex *coeffs) {
    return so3fft_dist_forward_real(p, samples, coeffs);
}

SO3FFT_MPI_EXPORT int so3fft_mpi_inverse_real(so3fft_mpi_plan p, so3fft_complex *coeffs,
                                              double *samples) {
    return so3fft_dist_inverse_real(p, coeffs, samples);
}
