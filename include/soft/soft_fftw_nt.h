/*
 * so3fft SOFT 2.0 compatibility layer: soft_fftw_nt.h, the transforms with a single complex workspace.
 *
 * Written for so3fft from the specification of SOFT 2.0's interface (see docs/conventions.md);
 * no SOFT source or header text is used. Copyright (C) the so3fft authors.
 * SPDX-License-Identifier: GPL-2.0-or-later
 *
 * Include <fftw3.h> before this header, as with SOFT (it is included here if it was not).
 * Link with libso3fft_soft (-lso3fft_soft; pkg-config so3fft-soft; CMake so3fft::soft).
 */
#ifndef SO3FFT_SOFT_SOFT_FFTW_NT_H
#define SO3FFT_SOFT_SOFT_FFTW_NT_H

#ifndef FFTW3_H
#include <fftw3.h>
#endif

#ifdef __cplusplus
extern "C" {
#endif

/*
 * As Forward_SO3_Naive_fftw, with one complex workspace ((2bw)^3, not used). SOFT's version
 * may overwrite data; so3fft's never does.
 */
void Forward_SO3_Naive_fftw_nt(int bw, fftw_complex *data, fftw_complex *coeffs,
                               fftw_complex *workspace_cx, double *workspace_re,
                               double *weights, fftw_plan *p1, int flag);

/* As Inverse_SO3_Naive_fftw, with one complex workspace (not used). coeffs is not modified. */
void Inverse_SO3_Naive_fftw_nt(int bw, fftw_complex *coeffs, fftw_complex *data,
                               fftw_complex *workspace_cx, double *workspace_re,
                               fftw_plan *p1, int flag);

#ifdef __cplusplus
}
#endif

#endif /* SO3FFT_SOFT_SOFT_FFTW_NT_H */
