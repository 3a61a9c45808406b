/*
 * so3fft SOFT 2.0 compatibility layer: utils_so3.h, sizes and index maps of the SO(3) arrays.
 *
 * Written for so3fft from the specification of SOFT 2.0's interface (see docs/conventions.md);
 * no SOFT source or header text is used. Copyright (C) the so3fft authors.
 * SPDX-License-Identifier: GPL-2.0-or-later
 *
 * Include <fftw3.h> before this header, as with SOFT (it is included here if it was not).
 * Link with libso3fft_soft (-lso3fft_soft; pkg-config so3fft-soft; CMake so3fft::soft).
 */
#ifndef SO3FFT_SOFT_UTILS_SO3_H
#define SO3FFT_SOFT_UTILS_SO3_H

#ifndef MAX
#define MAX(a, b) ((a) > (b) ? (a) : (b))
#endif
#ifndef MIN
#define MIN(a, b) ((a) < (b) ? (a) : (b))
#endif
#ifndef ABS
#define ABS(a) ((a) < 0 ? -(a) : (a))
#endif
#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

#ifdef __cplusplus
extern "C" {
#endif

/* Number of coefficients at bandwidth bw: (4bw^3 - bw)/3 (-1 if it does not fit in an int). */
int totalCoeffs_so3(int bw);

/* Number of coefficients of order m1 (all m2 and l): bw^2 - m1^2. */
int numCoeffs_so3(int bw, int m1);

/* Number of coefficients of the order pair (m1, m2): bw - MAX(|m1|, |m2|). */
int howMany_so3(int m1, int m2, int bw);

/*
 * Start of the data of order pair (m1, m2) in the FFT'd, order-major sample array (orders in
 * FFT order, m mod 2bw; 2bw beta values per pair): 2bw * (2bw * (m1 mod 2bw) + (m2 mod 2bw)).
 */
int sampLoc_so3(int m1, int m2, int bw);

/* Index of the first coefficient (l = MAX(|m1|,|m2|)) of the block (m1, m2). */
int coefLoc_so3(int m1, int m2, int bw);

/*
 * Index of fhat(l, m, mp) in the coefficient array of bandwidth bw (m pairs with alpha,
 * mp with gamma); -1 if the coefficient does not exist.
 */
int so3CoefLoc(int m, int mp, int l, int bw);

#ifdef __cplusplus
}
#endif

#endif /* SO3FFT_SOFT_UTILS_SO3_H */
