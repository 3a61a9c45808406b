/*
 * so3fft: distributed plans over MPI -- C API of libso3fft_mpi (-lso3fft_mpi -lso3fft, and MPI).
 *
 * Copyright (C) the so3fft authors.
 * SPDX-License-Identifier: GPL-2.0-or-later
 *
 *   so3fft_mpi_plan p = so3fft_mpi_plan_partial(&shape, &options, SO3FFT_ESTIMATE, comm);
 *   so3fft_mpi_inverse(p, local_coeffs, local_samples);    (collective)
 *   so3fft_mpi_forward(p, local_samples, local_coeffs);    (collective)
 *   so3fft_mpi_destroy_plan(p);
 *
 * Each rank holds the beta slices j0 .. j1 and 2 B_grid - j1 .. 2 B_grid - j0 of the samples
 * (so3fft_mpi_local_pairs) and the coefficients of a run of clusters of order pairs
 * (so3fft_mpi_coef_owner). Planners and executes are collective: every rank calls them, and
 * an error on any rank is an error on every rank. See docs/distributed.md.
 */
#ifndef SO3FFT_MPI_H
#define SO3FFT_MPI_H

#include <mpi.h>

#include "so3fft.h"

#ifdef __cplusplus
extern "C" {
#endif

/* A distributed plan: a pointer to an opaque object. */
typedef struct so3fft_mpi_plan_s *so3fft_mpi_plan;

/* so3fft_mpi_plan_partial with the communicator's Fortran handle (MPI_Comm_c2f). */
so3fft_mpi_plan so3fft_mpi_plan_partial_fortran(const so3fft_shape *shape,
                                                const so3fft_partial_options *options,
                                                unsigned int flags, int comm);

/* Plans the transforms of `shape` over the ranks of `comm` (collective; MPI initialised, at
 * least MPI_THREAD_SERIALIZED where several threads call MPI). `options` as for
 * so3fft_plan_partial, without a beta selection. NULL on error, on every rank. */
static inline so3fft_mpi_plan so3fft_mpi_plan_partial(const so3fft_shape *shape,
                                                      const so3fft_partial_options *options,
                                                      unsigned int flags, MPI_Comm comm) {
    return so3fft_mpi_plan_partial_fortran(shape, options, flags, (int)MPI_Comm_c2f(comm));
}

/* Destroys a distributed plan (not collective); NULL is a no-op. */
void so3fft_mpi_destroy_plan(so3fft_mpi_plan p);

/* This rank's lane pairs j0 .. j1 (either pointer may be NULL). */
int so3fft_mpi_local_pairs(so3fft_mpi_plan p, int *j0, int *j1);

/* Samples this rank holds: 2 (j1 - j0) n_alpha n_gamma. */
ptrdiff_t so3fft_mpi_local_num_samples(so3fft_mpi_plan p);

/* Coefficients this rank holds. */
ptrdiff_t so3fft_mpi_local_num_coeffs(so3fft_mpi_plan p);

/* Bytes this rank's transforms hold besides its arrays (known before the first transform
 * allocates them): lane-row buffers and exchange blocks. */
ptrdiff_t so3fft_mpi_local_workspace(so3fft_mpi_plan p);

/* Groups of pairs a transform runs in, chosen to fit options->max_workspace on every rank
 * (1: results bitwise those of a single-process plan of the same shape). */
int so3fft_mpi_groups(so3fft_mpi_plan p);

/* Index of fhat(l, m, mp) in the coefficients of rank *rank (written if rank != NULL);
 * SO3FFT_EINVAL if the shape does not hold it. */
ptrdiff_t so3fft_mpi_coef_owner(so3fft_mpi_plan p, int l, int m, int mp, int *rank);

/* Forward (collective): local samples to local coefficients. */
int so3fft_mpi_forward(so3fft_mpi_plan p, so3fft_complex *samples, so3fft_complex *coeffs);

/* Inverse (collective): local coefficients to local samples. */
int so3fft_mpi_inverse(so3fft_mpi_plan p, so3fft_complex *coeffs, so3fft_complex *samples);

/* Forward of real samples (collective; plan made with SO3FFT_REAL). */
int so3fft_mpi_forward_real(so3fft_mpi_plan p, const double *samples, so3fft_complex *coeffs);

/* Inverse to real samples (collective; plan made with SO3FFT_REAL). */
int so3fft_mpi_inverse_real(so3fft_mpi_plan p, so3fft_complex *coeffs, double *samples);

#ifdef __cplusplus
}
#endif

#endif /* SO3FFT_MPI_H */
