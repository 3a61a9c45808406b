/*
 * so3fft SOFT 2.0 compatibility layer: rotate_so3_utils.h, rotation of S^2 coefficients.
 *
 * Written for so3fft from the specification of SOFT 2.0's interface (see
 * docs/conventions-s2.md); no SOFT source or header text is used. Copyright (C) the so3fft
 * authors.
 * SPDX-License-Identifier: GPL-2.0-or-later
 *
 * Link with libso3fft_soft (-lso3fft_soft; pkg-config so3fft-soft; CMake so3fft::soft).
 */
#ifndef SO3FFT_SOFT_ROTATE_SO3_UTILS_H
#define SO3FFT_SOFT_ROTATE_SO3_UTILS_H

#ifdef __cplusplus
extern "C" {
#endif

/*
 * S^2 coefficients (split, seanindex order) of bandwidth bwIn rotated by
 * g = Rz(alpha) Ry(beta) Rz(gamma): fhat'(l,m) = sum_m' D^l_{m,m'}(g) fhat(l,m'), into
 * cfrR/I of bandwidth bwOut; degrees up to min(degOut, bwIn-1), the others zero
 * (degOut < bwOut). scratch is not used.
 */
void rotateCoefAll(int bwIn, int bwOut, int degOut, double alpha, double beta, double gamma,
                   double *cfR, double *cfI, double *cfrR, double *cfrI, double *scratch);

#ifdef __cplusplus
}
#endif

#endif /* SO3FFT_SOFT_ROTATE_SO3_UTILS_H */
