/*
 * so3fft SOFT 2.0 compatibility layer: s2_legendreTransforms.h, per-order naive Legendre
 * transforms (the semi-naive ones, SemiNaiveReduced and InvSemiNaiveReduced, are not provided).
 *
 * Written for so3fft from the specification of SOFT 2.0's interface (see
 * docs/conventions-s2.md); no SOFT source or header text is used. Copyright (C) the so3fft
 * authors.
 * SPDX-License-Identifier: GPL-2.0-or-later
 *
 * Link with libso3fft_soft (-lso3fft_soft; pkg-config so3fft-soft; CMake so3fft::soft).
 */
#ifndef SO3FFT_SOFT_S2_LEGENDRETRANSFORMS_H
#define SO3FFT_SOFT_S2_LEGENDRETRANSFORMS_H

#ifdef __cplusplus
extern "C" {
#endif

/*
 * Order m (0 <= m < bw): result[l-m] = sum_{j<2bw} data[j] weights[j] plmtable[(l-m)*2bw + j],
 * l = m..bw-1. weights: from makeweights (the first 2bw values are read); plmtable: from
 * PmlTableGen (or a naive entry of SemiNaive_Naive_Pml_Table). workspace is not used.
 */
void Naive_AnalysisX(double *data, int bw, int m, double *weights, double *result,
                     double *plmtable, double *workspace);

/* Order m: result[j] = sum_{l=m}^{bw-1} coeffs[l-m] plmtable[(l-m)*2bw + j], j < 2bw. */
void Naive_SynthesizeX(double *coeffs, int bw, int m, double *result, double *plmtable);

#ifdef __cplusplus
}
#endif

#endif /* SO3FFT_SOFT_S2_LEGENDRETRANSFORMS_H */
