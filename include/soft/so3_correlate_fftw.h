/*
 * so3fft SOFT 2.0 compatibility layer: so3_correlate_fftw.h, combining S^2 coefficients into SO(3) ones.
 *
 * Written for so3fft from the specification of SOFT 2.0's interface (see docs/conventions.md);
 * no SOFT source or header text is used. Copyright (C) the so3fft authors.
 * SPDX-License-Identifier: GPL-2.0-or-later
 *
 * Include <fftw3.h> before this header, as with SOFT (it is included here if it was not).
 * Link with libso3fft_soft (-lso3fft_soft; pkg-config so3fft-soft; CMake so3fft::soft).
 */
#ifndef SO3FFT_SOFT_SO3_CORRELATE_FFTW_H
#define SO3FFT_SOFT_SO3_CORRELATE_FFTW_H

#ifndef FFTW3_H
#include <fftw3.h>
#endif

#ifdef __cplusplus
extern "C" {
#endif

/*
 * SO(3) coefficients (bandwidth bwOut, (4bwOut^3-bwOut)/3 entries, all written) of the
 * correlation of a signal f and a pattern h given by their S^2 coefficients at bandwidth bwIn
 * (real and imaginary parts, bwIn^2 each, seanindex order):
 * so3Coef[so3CoefLoc(m1,m2,l,bwOut)] = 2pi sqrt(2/(2l+1)) (-1)^(m1+m2) f(l,-m1) conj(h(l,-m2))
 * for l <= degLim (< MIN(bwIn, bwOut)), 0 otherwise.
 */
void so3CombineCoef_fftw(int bwIn, int bwOut, int degLim, double *sigCoefR, double *sigCoefI,
                         double *patCoefR, double *patCoefI, fftw_complex *so3Coef);

/*
 * Index of the S^2 coefficient of order m and degree l at bandwidth bw: m >= 0:
 * m*bw - m(m-1)/2 + (l-m); m < 0: L(L+3)/2 + 1 + (L+m)(L+m+1)/2 + (l-|m|), L = bw-1.
 */
int seanindex(int m, int l, int bw);

#ifdef __cplusplus
}
#endif

#endif /* SO3FFT_SOFT_SO3_CORRELATE_FFTW_H */
