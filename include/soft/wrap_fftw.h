/*
 * so3fft SOFT 2.0 compatibility layer: wrap_fftw.h, the self-contained (wrapped) transforms.
 *
 * Written for so3fft from the specification of SOFT 2.0's interface (see docs/conventions.md);
 * no SOFT source or header text is used. Copyright (C) the so3fft authors.
 * SPDX-License-Identifier: GPL-2.0-or-later
 *
 * Include <fftw3.h> before this header, as with SOFT (it is included here if it was not).
 * Link with libso3fft_soft (-lso3fft_soft; pkg-config so3fft-soft; CMake so3fft::soft).
 */
#ifndef SO3FFT_SOFT_WRAP_FFTW_H
#define SO3FFT_SOFT_WRAP_FFTW_H

#ifndef FFTW3_H
#include <fftw3.h>
#endif

#ifdef __cplusplus
extern "C" {
#endif

/*
 * Forward and inverse SO(3) transforms at bandwidth bw without caller-provided workspaces,
 * weights or plans: signal holds (2bw)^3 samples, coeffs (4bw^3-bw)/3 coefficients;
 * flag = 1 for real data (as in soft_fftw.h). Inputs are not modified.
 */
void Forward_SO3_Naive_fftw_W(int bw, fftw_complex *signal, fftw_complex *coeffs, int flag);
void Inverse_SO3_Naive_fftw_W(int bw, fftw_complex *coeffs, fftw_complex *signal, int flag);

/*
 * Rotational matching at bandwidth bw: the rotation g = Rz(alpha) Ry(beta) Rz(gamma) of the
 * SO(3) grid that maximises |C(g)|^2, C(g) = int sig(x) conj(pat(g^-1 x)) dx, i.e. the signal
 * is about the pattern rotated by g. sig, pat: (2bw)^2 samples on the S^2 grid, interleaved
 * complex (2 (2bw)^2 doubles) or, with isReal nonzero, real ((2bw)^2 doubles). Ties go to the
 * lowest grid index. Inputs are not modified.
 */
void softFFTWCor2(int bw, double *sig, double *pat, double *alpha, double *beta, double *gamma,
                  int isReal);

/*
 * Rotation of a function on the sphere at bandwidth bw: sigOut(x) = sigIn(g^-1 x),
 * g = Rz(alpha) Ry(beta) Rz(gamma). Samples as in softFFTWCor2 (interleaved complex, or real
 * with isReal nonzero; a real result keeps the real part). Works at every bandwidth.
 */
void s2RotateFFTW(int bw, double *sigIn, double *sigOut, double alpha, double beta, double gamma,
                  int isReal);

#ifdef __cplusplus
}
#endif

#endif /* SO3FFT_SOFT_WRAP_FFTW_H */
