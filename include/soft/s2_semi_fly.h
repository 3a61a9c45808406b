/*
 * so3fft SOFT 2.0 compatibility layer: s2_semi_fly.h, spherical-harmonic transforms with
 * the Legendre functions computed on the fly.
 *
 * Written for so3fft from the specification of SOFT 2.0's interface (see
 * docs/conventions-s2.md); no SOFT source or header text is used. Copyright (C) the so3fft
 * authors.
 * SPDX-License-Identifier: GPL-2.0-or-later
 *
 * Include <fftw3.h> before this header, as with SOFT (it is included here if it was not).
 * Link with libso3fft_soft (-lso3fft_soft; pkg-config so3fft-soft; CMake so3fft::soft).
 */
#ifndef SO3FFT_SOFT_S2_SEMI_FLY_H
#define SO3FFT_SOFT_S2_SEMI_FLY_H

#ifndef FFTW3_H
#include <fftw3.h>
#endif

#ifdef __cplusplus
extern "C" {
#endif

/* Forward transform: as FST_semi_memo in s2_semi_memo.h, without a table. */
void FST_semi_fly(double *rdata, double *idata, double *rcoeffs, double *icoeffs, int bw,
                  double *workspace, int dataformat, int cutoff, fftw_plan *dctPlan,
                  fftw_plan *fftPlan, double *weights);

/* Inverse transform: as InvFST_semi_memo in s2_semi_memo.h, without a table. */
void InvFST_semi_fly(double *rcoeffs, double *icoeffs, double *rdata, double *idata, int bw,
                     double *workspace, int dataformat, int cutoff, fftw_plan *idctPlan,
                     fftw_plan *ifftPlan);

#ifdef __cplusplus
}
#endif

#endif /* SO3FFT_SOFT_S2_SEMI_FLY_H */
