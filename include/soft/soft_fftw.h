/*
 * so3fft SOFT 2.0 compatibility layer: soft_fftw.h, the forward and inverse SO(3) transforms.
 *
 * Written for so3fft from the specification of SOFT 2.0's interface (see docs/conventions.md);
 * no SOFT source or header text is used. Copyright (C) the so3fft authors.
 * SPDX-License-Identifier: GPL-2.0-or-later
 *
 * Include <fftw3.h> before this header, as with SOFT (it is included here if it was not).
 * Link with libso3fft_soft (-lso3fft_soft; pkg-config so3fft-soft; CMake so3fft::soft).
 */
#ifndef SO3FFT_SOFT_SOFT_FFTW_H
#define SO3FFT_SOFT_SOFT_FFTW_H

#ifndef FFTW3_H
#include <fftw3.h>
#endif

#ifdef __cplusplus
extern "C" {
#endif

/*
 * Forward SO(3) transform at bandwidth bw: data, (2bw)^3 samples f(alpha_j1, beta_k, gamma_j2)
 * at index k*(2bw)^2 + j1*(2bw) + j2, to coeffs, (4bw^3-bw)/3 coefficients in so3CoefLoc order.
 * weights: 2bw quadrature weights (makeweights2). flag = 1: real data (imaginary parts of data
 * zero); the output satisfies fhat(l,-m,-mp) = (-1)^(m-mp) conj(fhat(l,m,mp)). flag = 0 on
 * data whose imaginary parts are all exactly 0 takes the same real path.
 * The workspaces (workspace_cx, workspace_cx2: (2bw)^3; workspace_re: 24bw + 2bw^2) and the
 * FFTW plan *p1 are accepted for compatibility and not used. data is not modified.
 */
void Forward_SO3_Naive_fftw(int bw, fftw_complex *data, fftw_complex *coeffs,
                            fftw_complex *workspace_cx, fftw_complex *workspace_cx2,
                            double *workspace_re, double *weights, fftw_plan *p1, int flag);

/*
 * Inverse SO(3) transform: coeffs to data (layouts as above). flag = 1: real data; only the
 * blocks (0,0), (0,mp>0), (m>0, mp != -m) and (-m,m) for m>0 of coeffs are read, and the
 * imaginary parts of data are set to 0. flag = 0 on coefficients with that symmetry exactly
 * (every pair, fhat(l,0,0) real) takes the same real path. workspace_cx2 may be as small as 2bw entries (it is
 * not used, nor are the other workspaces and *p1). coeffs is not modified.
 */
void Inverse_SO3_Naive_fftw(int bw, fftw_complex *coeffs, fftw_complex *data,
                            fftw_complex *workspace_cx, fftw_complex *workspace_cx2,
                            double *workspace_re, fftw_plan *p1, int flag);

#ifdef __cplusplus
}
#endif

#endif /* SO3FFT_SOFT_SOFT_FFTW_H */
