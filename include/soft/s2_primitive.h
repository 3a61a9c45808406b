/*
 * so3fft SOFT 2.0 compatibility layer: s2_primitive.h, helpers of the S^2 transforms.
 *
 * Written for so3fft from the specification of SOFT 2.0's interface (see
 * docs/conventions-s2.md); no SOFT source or header text is used. Copyright (C) the so3fft
 * authors.
 * SPDX-License-Identifier: GPL-2.0-or-later
 *
 * Link with libso3fft_soft (-lso3fft_soft; pkg-config so3fft-soft; CMake so3fft::soft).
 * Nodes are computed with the exact pi (SOFT's library uses a 15-digit one).
 */
#ifndef SO3FFT_SOFT_S2_PRIMITIVE_H
#define SO3FFT_SOFT_S2_PRIMITIVE_H

#ifndef PI
#define PI 3.141592653589793
#endif

#ifdef __cplusplus
extern "C" {
#endif

/* Normalised recurrence Pt_{l+1}^m(x) = L2_an(m,l) x Pt_l^m(x) + L2_cn(m,l) Pt_{l-1}^m(x):
 * L2_an = sqrt((2l+1)(2l+3)/((l+1-m)(l+1+m))),
 * L2_cn = -sqrt((2l+3)(l-m)(l+m)/((2l-1)(l+1-m)(l+1+m))) (0 for l = 0). */
double L2_an(int m, int l);
double L2_cn(int m, int l);

/* result = data1 + data2, scalar * data1, data1 .* data2 (n values; result may be an input). */
void vec_add(double *data1, double *data2, double *result, int n);
void vec_mul(double scalar, double *data1, double *result, int n);
void vec_pt_mul(double *data1, double *data2, double *result, int n);

/* eval_pts[i] = (2i+1) pi/(2n), resp. its cosine, i < n. */
void ArcCosEvalPts(int n, double *eval_pts);
void EvalPts(int n, double *eval_pts);

/* result[i] = Pt_m^m(cos t) = (-1)^m sqrt((2m+1)/2 (2m)!)/(2^m m!) sin^m(t), t = eval_pts[i]
 * (angles), i < n. */
void Pmm_L2(int m, double *eval_pts, int n, double *result);

/* Index of the S^2 coefficient (l, m) at bandwidth bw (also in so3_correlate_fftw.h). */
int seanindex(int m, int l, int bw);

/* loc[0] = seanindex(m, l, bw), loc[1] = seanindex(-m, l, bw), for m > 0
 * (m = 0: loc[1] = bw^2 + l, as in SOFT). */
void seanindex2(int m, int l, int bw, int *loc);

/* Transposes the size x size matrix array in place. */
void transpose(double *array, int size);

#ifdef __cplusplus
}
#endif

#endif /* SO3FFT_SOFT_S2_PRIMITIVE_H */
