/*
 * so3fft SOFT 2.0 compatibility layer: s2_semi_memo.h, spherical-harmonic transforms with
 * precomputed Legendre tables.
 *
 * Written for so3fft from the specification of SOFT 2.0's interface (see
 * docs/conventions-s2.md); no SOFT source or header text is used. Copyright (C) the so3fft
 * authors.
 * SPDX-License-Identifier: GPL-2.0-or-later
 *
 * Include <fftw3.h> before this header, as with SOFT (it is included here if it was not).
 * Link with libso3fft_soft (-lso3fft_soft; pkg-config so3fft-soft; CMake so3fft::soft).
 */
#ifndef SO3FFT_SOFT_S2_SEMI_MEMO_H
#define SO3FFT_SOFT_S2_SEMI_MEMO_H

#ifndef FFTW3_H
#include <fftw3.h>
#endif

#ifdef __cplusplus
extern "C" {
#endif

/*
 * Forward transform: samples rdata + i idata ((2bw)^2 each; theta_j = pi(2j+1)/(4bw) slowest,
 * phi_k = pi k/bw fastest) to coefficients rcoeffs + i icoeffs (bw^2 each, seanindex order):
 * fhat(l,m) = (pi/bw) sum_{j,k} w_B(j) f_jk conj(Y_l^m(theta_j, phi_k)), Y_l^m orthonormal with
 * the Condon-Shortley phase. dataformat 0: complex; 1: real (orders m >= 0 computed from
 * rdata + i idata, then fhat(l,-m) = (-1)^m conj(fhat(l,m))). cutoff (0..bw) does not change
 * the result. The table, workspace, plans and weights (from makeweights) are accepted and not
 * read; rdata and idata are not modified. Invalid arguments: one line on stderr, nothing written.
 */
void FST_semi_memo(double *rdata, double *idata, double *rcoeffs, double *icoeffs, int bw,
                   double **seminaive_naive_table, double *workspace, int dataformat, int cutoff,
                   fftw_plan *dctPlan, fftw_plan *fftPlan, double *weights);

/*
 * Inverse transform: coefficients rcoeffs + i icoeffs to samples rdata + i idata,
 * f_jk = sum_{l<bw} sum_{|m|<=l} fhat(l,m) Y_l^m(theta_j, phi_k). dataformat 1: only orders
 * m >= 0 are read, fhat(l,-m) taken as (-1)^m conj(fhat(l,m)); Im fhat(l,0) is kept, so idata
 * is (1/sqrt(2pi)) sum_l Im fhat(l,0) Pt_l^0(cos theta_j) (0 when those parts are 0). Both
 * outputs are always written; the inputs are not modified; cutoff, table, workspace and plans
 * as for FST_semi_memo.
 */
void InvFST_semi_memo(double *rcoeffs, double *icoeffs, double *rdata, double *idata, int bw,
                      double **transpose_seminaive_naive_table, double *workspace, int dataformat,
                      int cutoff, fftw_plan *idctPlan, fftw_plan *ifftPlan);

#ifdef __cplusplus
}
#endif

#endif /* SO3FFT_SOFT_S2_SEMI_MEMO_H */
