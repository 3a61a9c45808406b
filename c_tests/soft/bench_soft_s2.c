/* Timing of the complex S^2 transforms through the SOFT API (FST_semi_memo and
 * InvFST_semi_memo, dataformat 0, cutoff bw, split arrays, client tables and workspace), the
 * split <-> interleaved conversion included. Usage: bench_soft_s2 [B ...] (default 256 512);
 * threads from SO3FFT_SOFT_THREADS. Median wall time of 9 interleaved runs, against SOFT 2.0's
 * one-thread times on the development machine (ms): B = 256: 17 / 9, B = 512: 83 / 56. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <fftw3.h>

#include "csecond.h"
#include "makeweights.h"
#include "s2_cospmls.h"
#include "s2_semi_memo.h"

#include "../check.h"

#define RUNS 9

static int cmp(const void *a, const void *b) {
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

static double *alloc_doubles(size_t n) {
    double *p = (double *)malloc(n * sizeof(double));
    if (!p) {
        fprintf(stderr, "malloc failed\n");
        exit(EXIT_FAILURE);
    }
    return p;
}

int main(int argc, char **argv) {
    int defaults[2] = {256, 512}, nb = argc > 1 ? argc - 1 : 2, ib;
    for (ib = 0; ib < nb; ib++) {
        int bw = argc > 1 ? atoi(argv[ib + 1]) : defaults[ib], r;
        size_t ns = 4 * (size_t)bw * bw, nc = (size_t)bw * bw, i;
        double soft_f = bw == 256 ? 17e-3 : bw == 512 ? 83e-3 : 0.0;
        double soft_i = bw == 256 ? 9e-3 : bw == 512 ? 56e-3 : 0.0;
        double *rdata = alloc_doubles(ns), *idata = alloc_doubles(ns);
        double *rc = alloc_doubles(nc), *ic = alloc_doubles(nc);
        double *ws = alloc_doubles(8 * nc + 10 * (size_t)bw);
        double *weights = alloc_doubles(4 * (size_t)bw);
        double *space = alloc_doubles((size_t)Reduced_SpharmonicTableSize(bw, bw));
        double *tspace = alloc_doubles((size_t)Reduced_SpharmonicTableSize(bw, bw));
        double **table, **ttable, tf[RUNS], ti[RUNS], t0;
        fftw_plan none = NULL;
        unsigned long long seed = 1;
        makeweights(bw, weights);
        table = SemiNaive_Naive_Pml_Table(bw, bw, space, NULL);
        ttable = Transpose_SemiNaive_Naive_Pml_Table(table, bw, bw, tspace, NULL);
        for (i = 0; i < ns; i++) {
            rdata[i] = rnd(&seed);
            idata[i] = rnd(&seed);
        }
        t0 = csecond();
        FST_semi_memo(rdata, idata, rc, ic, bw, table, ws, 0, bw, &none, &none, weights);
        printf("B = %d: first call (plan set-up + forward) %.3f s\n", bw, csecond() - t0);
        for (r = 0; r < RUNS; r++) {
            t0 = csecond();
            FST_semi_memo(rdata, idata, rc, ic, bw, table, ws, 0, bw, &none, &none, weights);
            tf[r] = csecond() - t0;
            t0 = csecond();
            InvFST_semi_memo(rc, ic, rdata, idata, bw, ttable, ws, 0, bw, &none, &none);
            ti[r] = csecond() - t0;
        }
        qsort(tf, RUNS, sizeof(double), cmp);
        qsort(ti, RUNS, sizeof(double), cmp);
        printf("  FST_semi_memo    %8.2f ms", tf[RUNS / 2] * 1e3);
        if (soft_f > 0) printf("  (SOFT / this: %.2f)", soft_f / tf[RUNS / 2]);
        printf("\n  InvFST_semi_memo %8.2f ms", ti[RUNS / 2] * 1e3);
        if (soft_i > 0) printf("  (SOFT / this: %.2f)", soft_i / ti[RUNS / 2]);
        printf("\n");
        free(table);
        free(ttable);
        free(space);
        free(tspace);
        free(weights);
        free(ws);
        free(rc);
        free(ic);
        free(rdata);
        free(idata);
    }
    return 0;
}
