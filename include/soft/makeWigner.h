/*
 * so3fft SOFT 2.0 compatibility layer: makeWigner.h, the Wigner-d tables of the _pc transforms.
 *
 * Written for so3fft from the specification of SOFT 2.0's interface (see docs/conventions.md);
 * no SOFT source or header text is used. Copyright (C) the so3fft authors.
 * SPDX-License-Identifier: GPL-2.0-or-later
 *
 * Include <fftw3.h> before this header, as with SOFT (it is included here if it was not).
 * Link with libso3fft_soft (-lso3fft_soft; pkg-config so3fft-soft; CMake so3fft::soft).
 */
#ifndef SO3FFT_SOFT_MAKEWIGNER_H
#define SO3FFT_SOFT_MAKEWIGNER_H

#ifdef __cplusplus
extern "C" {
#endif

/*
 * Wigner-d tables for Forward_SO3_Naive_fftw_pc (genWigAll) and Inverse_SO3_Naive_fftw_pc
 * (genWigAllTrans). wigners must hold (bw*bw*(bw*bw + 3*bw + 2))/3 doubles; exactly that many
 * are written (sqrt((2l+1)/2) d^l_{m1,m2}(beta_k) for 0 <= m1 <= m2 < bw, l = m2..bw-1,
 * k < 2bw; transposed blocks for genWigAllTrans). workspace is not used. Both also prepare
 * the cached so3fft plan of bandwidth bw, so set-up cost is paid here.
 */
void genWigAll(int bw, double *wigners, double *workspace);
void genWigAllTrans(int bw, double *wigners, double *workspace);

#ifdef __cplusplus
}
#endif

#endif /* SO3FFT_SOFT_MAKEWIGNER_H */
