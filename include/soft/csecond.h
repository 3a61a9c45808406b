/*
 * so3fft SOFT 2.0 compatibility layer: csecond.h, a timer.
 *
 * Written for so3fft from the specification of SOFT 2.0's interface (see docs/conventions.md);
 * no SOFT source or header text is used. Copyright (C) the so3fft authors.
 * SPDX-License-Identifier: GPL-2.0-or-later
 *
 * Include <fftw3.h> before this header, as with SOFT (it is included here if it was not).
 * Link with libso3fft_soft (-lso3fft_soft; pkg-config so3fft-soft; CMake so3fft::soft).
 */
#ifndef SO3FFT_SOFT_CSECOND_H
#define SO3FFT_SOFT_CSECOND_H

#ifdef __cplusplus
extern "C" {
#endif

/* Wall-clock time in seconds (differences of two calls time a computation). */
double csecond(void);

#ifdef __cplusplus
}
#endif

#endif /* SO3FFT_SOFT_CSECOND_H */
