/*
 * so3fft SOFT 2.0 compatibility layer: rotate_so3_fftw.h, rotation of functions on the
 * sphere: sigOut = Lambda(g) sigIn, (Lambda(g) f)(x) = f(g^-1 x), g = Rz(alpha) Ry(beta)
 * Rz(gamma).
 *
 * Written for so3fft from the specification of SOFT 2.0's interface (see
 * docs/conventions-s2.md); no SOFT source or header text is used. Copyright (C) the so3fft
 * authors.
 * SPDX-License-Identifier: GPL-2.0-or-later
 *
 * Link with libso3fft_soft (-lso3fft_soft; pkg-config so3fft-soft; CMake so3fft::soft).
 */
#ifndef SO3FFT_SOFT_ROTATE_SO3_FFTW_H
#define SO3FFT_SOFT_ROTATE_SO3_FFTW_H

#ifdef __cplusplus
extern "C" {
#endif

/*
 * Split samples of bandwidth bwIn ((2bwIn)^2 doubles each) rotated; degrees up to
 * min(degOut, bwIn-1) kept, the others zero; synthesised at bwOut into sigOutR/I
 * ((2bwOut)^2 each). Requires degOut < bwOut. Works at every bandwidth; scratch and the
 * tables are accepted and never read or written.
 */
void rotateFctFFTW(int bwIn, int bwOut, int degOut, double *sigInR, double *sigInI,
                   double *sigOutR, double *sigOutI, double alpha, double beta, double gamma,
                   double *scratch, double **spharmonic_pml_table,
                   double **transpose_spharmonic_pml_table);

/* As rotateFctFFTW, without scratch and tables. */
void rotateFctFFTWS(int bwIn, int bwOut, int degOut, double *sigInR, double *sigInI,
                    double *sigOutR, double *sigOutI, double alpha, double beta, double gamma);

/* As rotateFctFFTW, in place at bandwidth bw. */
void rotateFctFFTWS_mem(int bw, int degOut, double *sigR, double *sigI, double alpha,
                        double beta, double gamma);

#ifdef __cplusplus
}
#endif

#endif /* SO3FFT_SOFT_ROTATE_SO3_FFTW_H */
