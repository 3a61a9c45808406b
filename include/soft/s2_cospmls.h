/*
 * so3fft SOFT 2.0 compatibility layer: s2_cospmls.h, sizes and builders of the Legendre
 * tables of the S^2 transforms.
 *
 * Written for so3fft from the specification of SOFT 2.0's interface (see
 * docs/conventions-s2.md); no SOFT source or header text is used. Copyright (C) the so3fft
 * authors.
 * SPDX-License-Identifier: GPL-2.0-or-later
 *
 * Link with libso3fft_soft (-lso3fft_soft; pkg-config so3fft-soft; CMake so3fft::soft).
 *
 * The sizes are SOFT's. The transforms of so3fft never read a table (any table, or NULL, may
 * be passed to them). Naive tables (orders m >= cutoff, and PmlTableGen) hold the normalised
 * Legendre functions Pt_l^m(cos theta_j), theta_j = pi(2j+1)/(4bw), at (l-m)*2bw + j; the
 * cosine-series tables (orders m < cutoff) are opaque and filled with zeros. The pointer
 * arrays returned come from malloc: release them with free(). Invalid arguments: one line on
 * stderr; the size functions return -1 (also when a size does not fit in an int), the table
 * functions NULL, and nothing is written.
 */
#ifndef SO3FFT_SOFT_S2_COSPMLS_H
#define SO3FFT_SOFT_S2_COSPMLS_H

#ifdef __cplusplus
extern "C" {
#endif

/* Doubles of the cosine-series table of order m: sum_{l=m}^{bw-1} RowSize(m, l). */
int TableSize(int m, int bw);

/* Doubles for Spharmonic_Pml_Table: floor((4bw^3 + 6bw^2 - 8bw)/24) + bw (bw <= 512),
 * sum_m TableSize(m, bw) above. */
int Spharmonic_TableSize(int bw);

/* Doubles of the cosine-series tables of the orders below m: sum_{i<m} TableSize(i, bw). */
int Reduced_SpharmonicTableSize(int bw, int m);

/* Doubles of the naive tables of the orders m..bw-1: bw (bw-m)(bw-m+1). */
int Reduced_Naive_TableSize(int bw, int m);

/* Offset of degree l's row in the cosine-series table of order m: sum_{i=m}^{l-1} RowSize(m, i). */
int NewTableOffset(int m, int l);

/* Row length of degree l in the cosine-series table of order m: 0 for l < m, l/2 + 1 for even m,
 * (l-1)/2 + 1 for odd m. */
int RowSize(int m, int l);

/* Row length of cosine index row in the transposed table of order m: the number of degrees
 * l < bw with l >= MAX(m, row + m%2) and l = row + m (mod 2). */
int Transpose_RowSize(int row, int m, int bw);

/* storeplm (2bw(bw-m) doubles) = Pt_l^m(cos theta_j) at (l-m)*2bw + j. workspace unused. */
void PmlTableGen(int bw, int m, double *storeplm, double *workspace);

/* Cosine-series table of order m: TableSize(m, bw) doubles (zeros). workspace unused. */
void CosPmlTableGen(int bw, int m, double *tablespace, double *workspace);

/* Transposed cosine-series table: TableSize(m, bw) doubles to result (zeros). */
void Transpose_CosPmlTableGen(int bw, int m, double *cos_pml_table, double *result);

/* bw pointers (malloc) into resultspace (Spharmonic_TableSize(bw) doubles). */
double **Spharmonic_Pml_Table(int bw, double *resultspace, double *workspace);
double **Transpose_Spharmonic_Pml_Table(double **spharmonic_pml_table, int bw,
                                        double *resultspace, double *workspace);

/* bw+1 pointers (malloc) into resultspace (Reduced_SpharmonicTableSize(bw, cutoff) +
 * Reduced_Naive_TableSize(bw, cutoff) doubles): orders m < cutoff cosine-series tables, the
 * others naive tables; 0 <= cutoff <= bw. workspace (16bw doubles in SOFT) unused. */
double **SemiNaive_Naive_Pml_Table(int bw, int m, double *resultspace, double *workspace);
double **Transpose_SemiNaive_Naive_Pml_Table(double **seminaive_naive_pml_table, int bw, int m,
                                             double *resultspace, double *workspace);

#ifdef __cplusplus
}
#endif

#endif /* SO3FFT_SOFT_S2_COSPMLS_H */
