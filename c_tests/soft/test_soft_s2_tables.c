/* The S^2 table functions (s2_cospmls.h), helpers (s2_primitive.h) and per-order Legendre
 * sums (s2_legendreTransforms.h) against their formulas: sizes for bw = 1..40, tables
 * written exactly into SOFT-sized space (guard zones) with malloc'd pointer arrays released
 * by free(), naive tables and Pmm_L2 against the textbook associated Legendre recurrence,
 * bad arguments rejected with nothing written. Usage: test_soft_s2_tables */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <fftw3.h>

#include "makeweights.h"
#include "s2_cospmls.h"
#include "s2_legendreTransforms.h"
#include "s2_primitive.h"

#include "../check.h"
#include "s2_test_util.h"

#define EXACT_PI 3.14159265358979323846

/* The formulas of docs/conventions-s2.md (SOFT's sizes), written out as sums. */
static int row_size(int m, int l) {
    if (l < m) return 0;
    return (m % 2 == 0) ? l / 2 + 1 : (l - 1) / 2 + 1;
}
static int table_size(int m, int bw) {
    int l, s = 0;
    for (l = m; l < bw; l++) s += row_size(m, l);
    return s;
}
static int reduced_spharmonic(int bw, int m) {
    int i, s = 0;
    for (i = 0; i < m; i++) s += table_size(i, bw);
    return s;
}
static int reduced_naive(int bw, int m) {
    int i, s = 0;
    for (i = m; i < bw; i++) s += 2 * bw * (bw - i);
    return s;
}

static void check_sizes(void) {
    int bw, m, l, row;
    for (bw = 1; bw <= 40; bw++) {
        CHECK(Spharmonic_TableSize(bw) == (4 * bw * bw * bw + 6 * bw * bw - 8 * bw) / 24 + bw);
        CHECK(Spharmonic_TableSize(bw) >= reduced_spharmonic(bw, bw));
        for (m = 0; m <= bw; m++) {
            CHECK(TableSize(m, bw) == table_size(m, bw));
            CHECK(Reduced_SpharmonicTableSize(bw, m) == reduced_spharmonic(bw, m));
            CHECK(Reduced_Naive_TableSize(bw, m) == reduced_naive(bw, m));
        }
        for (m = 0; m < bw; m++) {
            int rows = 0;
            for (row = 0; row < bw + 2; row++) rows += Transpose_RowSize(row, m, bw);
            CHECK(rows == TableSize(m, bw));
        }
    }
    for (m = 0; m < 45; m++)
        for (l = 0; l < 45; l++) {
            int off = 0, i;
            CHECK(RowSize(m, l) == row_size(m, l));
            for (i = m; i < l; i++) off += row_size(m, i);
            CHECK(NewTableOffset(m, l) == off);
        }
    /* above bw = 512 the exact sum; sizes that do not fit in an int give -1 */
    CHECK(Spharmonic_TableSize(600) == Reduced_SpharmonicTableSize(600, 600));
    CHECK(Reduced_Naive_TableSize(2048, 0) == -1);
    /* invalid arguments */
    CHECK(TableSize(-1, 8) == -1 && TableSize(9, 8) == -1 && TableSize(0, 0) == -1);
    CHECK(Spharmonic_TableSize(0) == -1 && Spharmonic_TableSize(2049) == -1);
    CHECK(Reduced_SpharmonicTableSize(8, 9) == -1 && Reduced_Naive_TableSize(8, -1) == -1);
    CHECK(RowSize(-1, 3) == -1 && NewTableOffset(2, -1) == -1);
    CHECK(Transpose_RowSize(-1, 0, 8) == -1 && Transpose_RowSize(0, 0, 0) == -1);
}

/* Pt_l^m(cos t) from the unnormalised recurrence (l-m+1) P_{l+1} = (2l+1) x P_l - (l+m) P_{l-1},
 * P_m^m = (-1)^m (2m-1)!! sin^m t, then sqrt((2l+1)/2 (l-m)!/(l+m)!) (small l only). */
static double pt(int l, int m, double t) {
    double x = cos(t), pmm = 1.0, prev = 0.0, cur, ratio = 1.0;
    int i;
    for (i = 1; i <= m; i++) pmm *= -(2.0 * i - 1.0) * sin(t);
    cur = pmm;
    for (i = m; i < l; i++) {
        double next = ((2.0 * i + 1.0) * x * cur - (i + m) * prev) / (i - m + 1.0);
        prev = cur;
        cur = next;
    }
    for (i = l - m + 1; i <= l + m; i++) ratio /= i;
    return sqrt((2.0 * l + 1.0) / 2.0 * ratio) * cur;
}

static double theta(int j, int bw) { return EXACT_PI * (2 * j + 1) / (4.0 * bw); }

/* Largest deviation of a naive table of order m from Pt_l^m(cos theta_j). */
static double naive_error(const double *t, int bw, int m) {
    double worst = 0.0;
    int l, j;
    for (l = m; l < bw; l++)
        for (j = 0; j < 2 * bw; j++) {
            double d = fabs(t[(l - m) * 2 * bw + j] - pt(l, m, theta(j, bw)));
            if (!(d <= worst)) worst = d;
        }
    return worst;
}

static void check_tables(void) {
    int bws[5] = {1, 2, 3, 5, 8}, ib, ic, m;
    for (ib = 0; ib < 5; ib++) {
        int bw = bws[ib], cutoffs[3];
        cutoffs[0] = 0;
        cutoffs[1] = bw / 2;
        cutoffs[2] = bw;
        for (ic = 0; ic < 3; ic++) {
            int cutoff = cutoffs[ic], k;
            size_t size = (size_t)Reduced_Naive_TableSize(bw, cutoff) +
                          (size_t)Reduced_SpharmonicTableSize(bw, cutoff);
            double *space = guarded_alloc(size), *tspace = guarded_alloc(size);
            double *ws = guarded_alloc((size_t)(16 * bw));
            double **table = SemiNaive_Naive_Pml_Table(bw, cutoff, space, ws);
            double **ttable = Transpose_SemiNaive_Naive_Pml_Table(table, bw, cutoff, tspace, ws);
            size_t offset = 0;
            CHECK(table != NULL && ttable != NULL);
            if (!table || !ttable) return;
            CHECK(canaries_intact(space, size, size + GUARD));
            CHECK(canaries_intact(tspace, size, size + GUARD));
            CHECK(canaries_intact(ws, 0, (size_t)(16 * bw) + GUARD));
            for (k = 0; k <= bw; k++) {
                CHECK(table[k] == space + offset);
                CHECK(ttable[k] == tspace + offset);
                if (k < bw) {
                    if (k >= cutoff) {
                        CHECK(naive_error(table[k], bw, k) < 1e-14);
                        CHECK(memcmp(table[k], ttable[k],
                                     (size_t)(2 * bw * (bw - k)) * sizeof(double)) == 0);
                    }
                    offset += (size_t)(k < cutoff ? TableSize(k, bw) : 2 * bw * (bw - k));
                }
            }
            CHECK(offset == size);
            free(table);
            free(ttable);
            free(space);
            free(tspace);
            free(ws);
        }
        { /* the all-semi-naive tables: bw pointers, Spharmonic_TableSize doubles */
            size_t size = (size_t)Spharmonic_TableSize(bw);
            size_t used = (size_t)Reduced_SpharmonicTableSize(bw, bw);
            double *space = guarded_alloc(size), *tspace = guarded_alloc(size);
            double **table = Spharmonic_Pml_Table(bw, space, NULL);
            double **ttable = Transpose_Spharmonic_Pml_Table(table, bw, tspace, NULL);
            CHECK(table != NULL && ttable != NULL);
            if (!table || !ttable) return;
            for (m = 0; m < bw; m++) {
                CHECK(table[m] == space + Reduced_SpharmonicTableSize(bw, m));
                CHECK(ttable[m] == tspace + Reduced_SpharmonicTableSize(bw, m));
            }
            CHECK(canaries_intact(space, used, size + GUARD));
            CHECK(canaries_intact(tspace, used, size + GUARD));
            free(table);
            free(ttable);
            free(space);
            free(tspace);
        }
        for (m = 0; m < bw; m++) {
            size_t n = (size_t)(2 * bw * (bw - m)), t = (size_t)TableSize(m, bw);
            double *plm = guarded_alloc(n), *cos_t = guarded_alloc(t), *tr = guarded_alloc(t);
            double *ws = guarded_alloc((size_t)(16 * bw));
            PmlTableGen(bw, m, plm, ws);
            CHECK(naive_error(plm, bw, m) < 1e-14);
            CHECK(canaries_intact(plm, n, n + GUARD));
            CosPmlTableGen(bw, m, cos_t, ws);
            Transpose_CosPmlTableGen(bw, m, cos_t, tr);
            CHECK(canaries_intact(cos_t, t, t + GUARD) && canaries_intact(tr, t, t + GUARD));
            CHECK(canaries_intact(ws, 0, (size_t)(16 * bw) + GUARD));
            free(plm);
            free(cos_t);
            free(tr);
            free(ws);
        }
    }
    { /* bad arguments: NULL returned, nothing written */
        double *space = guarded_alloc(4096);
        CHECK(SemiNaive_Naive_Pml_Table(0, 0, space, NULL) == NULL);
        CHECK(SemiNaive_Naive_Pml_Table(8, 9, space, NULL) == NULL);
        CHECK(SemiNaive_Naive_Pml_Table(8, -1, space, NULL) == NULL);
        CHECK(SemiNaive_Naive_Pml_Table(8, 4, NULL, NULL) == NULL);
        CHECK(Transpose_SemiNaive_Naive_Pml_Table(NULL, 2049, 0, space, NULL) == NULL);
        CHECK(Spharmonic_Pml_Table(-3, space, NULL) == NULL);
        CHECK(Transpose_Spharmonic_Pml_Table(NULL, 4, NULL, NULL) == NULL);
        PmlTableGen(8, 8, space, NULL);
        PmlTableGen(8, -1, space, NULL);
        CosPmlTableGen(0, 0, space, NULL);
        Transpose_CosPmlTableGen(8, 9, space, space + 100);
        CHECK(canaries_intact(space, 0, 4096 + GUARD));
        free(space);
    }
}

static void check_primitives(void) {
    int m, l, i, n;
    double a[12], b[12], c[12], pts[16];
    int loc[2];
    unsigned long long seed = 5;
    for (m = 0; m < 10; m++)
        for (l = m; l < 12; l++) {
            double an = sqrt((2.0 * l + 1) * (2.0 * l + 3) / ((l + 1.0 - m) * (l + 1.0 + m)));
            double cn = l == 0 ? 0.0
                               : -sqrt((2.0 * l + 3) * (l - m) * (l + m) /
                                       ((2.0 * l - 1) * (l + 1.0 - m) * (l + 1.0 + m)));
            CHECK(fabs(L2_an(m, l) - an) <= 1e-15 * an);
            CHECK(fabs(L2_cn(m, l) - cn) <= 1e-15 * fabs(cn));
        }
    for (n = 1; n <= 16; n++) {
        double x[16];
        ArcCosEvalPts(n, pts);
        EvalPts(n, x);
        for (i = 0; i < n; i++) {
            CHECK(fabs(pts[i] - (2 * i + 1) * EXACT_PI / (2.0 * n)) <= 1e-15 * pts[i]);
            CHECK(fabs(x[i] - cos((2 * i + 1) * EXACT_PI / (2.0 * n))) <= 1e-15);
        }
    }
    ArcCosEvalPts(16, pts);
    for (m = 0; m < 12; m++) {
        double r[16];
        Pmm_L2(m, pts, 16, r);
        for (i = 0; i < 16; i++) CHECK(fabs(r[i] - pt(m, m, pts[i])) <= 1e-14);
    }
    for (i = 0; i < 12; i++) {
        a[i] = rnd(&seed);
        b[i] = rnd(&seed);
    }
    vec_add(a, b, c, 12);
    for (i = 0; i < 12; i++) CHECK(c[i] == a[i] + b[i]);
    vec_mul(-2.5, a, c, 12);
    for (i = 0; i < 12; i++) CHECK(c[i] == -2.5 * a[i]);
    vec_pt_mul(a, b, c, 12);
    for (i = 0; i < 12; i++) CHECK(c[i] == a[i] * b[i]);
    memcpy(c, a, sizeof a);
    vec_add(c, b, c, 12); /* in place */
    for (i = 0; i < 12; i++) CHECK(c[i] == a[i] + b[i]);
    { /* 3x3 and 4x4 in-place transposes */
        double t[16];
        for (n = 3; n <= 4; n++) {
            int j;
            for (i = 0; i < n * n; i++) t[i] = i;
            transpose(t, n);
            for (i = 0; i < n; i++)
                for (j = 0; j < n; j++) CHECK(t[i * n + j] == j * n + i);
        }
    }
    for (n = 1; n <= 12; n++)
        for (l = 0; l < n; l++)
            for (m = 0; m <= l; m++) {
                seanindex2(m, l, n, loc);
                CHECK(loc[0] == seanindex(m, l, n));
                CHECK(loc[1] == (m == 0 ? n * n + l : seanindex(-m, l, n)));
            }
    loc[0] = loc[1] = -5;
    seanindex2(3, 2, 8, loc);
    seanindex2(1, 8, 8, loc);
    seanindex2(1, 1, 8, NULL);
    CHECK(loc[0] == -5 && loc[1] == -5);
}

/* Naive_AnalysisX / Naive_SynthesizeX with a PmlTableGen table against direct sums. */
static void check_naive_sums(void) {
    const int bw = 6;
    double w[24], data[12], res[6], coeffs[6], out[12], table[2 * 6 * 6], copy[12];
    unsigned long long seed = 9;
    int m, l, j;
    makeweights(bw, w);
    for (m = 0; m < bw; m++) {
        PmlTableGen(bw, m, table, NULL);
        for (j = 0; j < 2 * bw; j++) data[j] = rnd(&seed);
        memcpy(copy, data, sizeof data);
        for (l = 0; l < bw; l++) res[l] = CANARY;
        Naive_AnalysisX(data, bw, m, w, res, table, NULL);
        CHECK(memcmp(copy, data, sizeof data) == 0);
        for (l = m; l < bw; l++) {
            double s = 0.0;
            for (j = 0; j < 2 * bw; j++) s += data[j] * w[j] * pt(l, m, theta(j, bw));
            CHECK(fabs(res[l - m] - s) <= 1e-14);
        }
        for (l = bw - m; l < bw; l++) CHECK(res[l] == CANARY);
        for (l = 0; l < bw - m; l++) coeffs[l] = rnd(&seed);
        Naive_SynthesizeX(coeffs, bw, m, out, table);
        for (j = 0; j < 2 * bw; j++) {
            double s = 0.0;
            for (l = m; l < bw; l++) s += coeffs[l - m] * pt(l, m, theta(j, bw));
            CHECK(fabs(out[j] - s) <= 1e-14);
        }
    }
    /* bad order: nothing written */
    for (l = 0; l < bw; l++) res[l] = CANARY;
    Naive_AnalysisX(data, bw, bw, w, res, table, NULL);
    Naive_SynthesizeX(coeffs, bw, -1, res, table);
    for (l = 0; l < bw; l++) CHECK(res[l] == CANARY);
}

int main(void) {
    check_sizes();
    check_tables();
    check_primitives();
    check_naive_sums();
    return finish("test_soft_s2_tables");
}
