/*
 * so3fft SOFT 2.0 compatibility layer: makeweights.h, the quadrature weights.
 *
 * Written for so3fft from the specification of SOFT 2.0's interface (see docs/conventions.md);
 * no SOFT source or header text is used. Copyright (C) the so3fft authors.
 * SPDX-License-Identifier: GPL-2.0-or-later
 *
 * Include <fftw3.h> before this header, as with SOFT (it is included here if it was not).
 * Link with libso3fft_soft (-lso3fft_soft; pkg-config so3fft-soft; CMake so3fft::soft).
 */
#ifndef SO3FFT_SOFT_MAKEWEIGHTS_H
#define SO3FFT_SOFT_MAKEWEIGHTS_H

#ifdef __cplusplus
extern "C" {
#endif

/*
 * Quadrature weights of bandwidth bw, beta_j = pi(2j+1)/(4bw):
 * w_B(j) = (2/bw) sin(beta_j) sum_{i<bw} sin((2i+1) beta_j)/(2i+1), j < 2bw.
 * makeweights writes 4bw doubles: w[j] = w_B(j), w[j+2bw] = w_B(j) sin(beta_j).
 * makeweights2 writes 2bw doubles: w[j] = w_B(j) (the weights of the forward transforms).
 */
void makeweights(int bw, double *w);
void makeweights2(int bw, double *w);

#ifdef __cplusplus
}
#endif

#endif /* SO3FFT_SOFT_MAKEWEIGHTS_H */
