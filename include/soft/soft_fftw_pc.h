/*
 * so3fft SOFT 2.0 compatibility layer: soft_fftw_pc.h, the transforms with precomputed Wigner tables.
 *
 * Written for so3fft from the specification of SOFT 2.0's interface (see docs/conventions.md);
 * no SOFT source or header text is used. Copyright (C) the so3fft authors.
 * SPDX-License-Identifier: GPL-2.0-or-later
 *
 * Include <fftw3.h> before this header, as with SOFT (it is included here if it was not).
 * Link with libso3fft_soft (-lso3fft_soft; pkg-config so3fft-soft; CMake so3fft::soft).
 */
#ifndef SO3FFT_SOFT_SOFT_FFTW_PC_H
#define SO3FFT_SOFT_SOFT_FFTW_PC_H

#ifndef FFTW3_H
#include <fftw3.h>
#endif

#ifdef __cplusplus
extern "C" {
#endif

/*
 * As Forward_SO3_Naive_fftw; wigners is a table made by genWigAll (makeWigner.h). so3fft
 * accepts the table and does not read it (its plans keep their own tables).
 */
void Forward_SO3_Naive_fftw_pc(int bw, fftw_complex *data, fftw_complex *coeffs,
                               fftw_complex *workspace_cx, fftw_complex *workspace_cx2,
                               double *workspace_re, double *weights, fftw_plan *p1,
                               double *wigners, int flag);

/*
 * As Inverse_SO3_Naive_fftw; wignersTrans is a table made by genWigAllTrans (makeWigner.h),
 * accepted and not read.
 */
void Inverse_SO3_Naive_fftw_pc(int bw, fftw_complex *coeffs, fftw_complex *data,
                               fftw_complex *workspace_cx, fftw_complex *workspace_cx2,
                               double *workspace_re, fftw_plan *p1, double *wignersTrans,
                               int flag);

#ifdef __cplusplus
}
#endif

#endif /* SO3FFT_SOFT_SOFT_FFTW_PC_H */
