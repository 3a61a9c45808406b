/* Registration codes' call sequences through the SOFT layer, as they are written in the wild:
 *
 *  A. real signals, zero-padded output grid: one real FST_semi_memo (dataformat 1) per
 *     signal with SOFT's tables and client FFTW plans, so3CombineCoef_fftw(bw, bw + pad,
 *     bw - 1, ...), Inverse_SO3_Naive_fftw(bw + pad, ..., flag = 1), the grid index decoded
 *     as [beta][alpha][gamma];
 *  B. complex signals with the client's own FFTW plans (an r2r REDFT10 plan and a guru split
 *     DFT) and SemiNaive_Naive_Pml_Table tables, a degree limit of bwIn/2 - 1, the S^2
 *     coefficients read directly with the client's own copy of the seanindex formula.
 *
 * The signal is the pattern rotated (s2RotateFFTW) by a rotation of the output grid; each
 * sequence must find exactly that grid point. In B the per-degree power of signal and
 * pattern, read through the client's index formula, must agree (rotations keep it). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <fftw3.h>

#include "makeweights.h"
#include "s2_cospmls.h"
#include "s2_semi_memo.h"
#include "so3_correlate_fftw.h"
#include "soft_fftw.h"
#include "utils_so3.h"
#include "wrap_fftw.h"

static int g_failures;

#define CHECK(cond)                                                                      \
    do {                                                                                 \
        if (!(cond)) {                                                                   \
            fprintf(stderr, "%s:%d: check failed: %s\n", __FILE__, __LINE__, #cond);     \
            g_failures++;                                                                \
        }                                                                                \
    } while (0)

static const double PI_ = 3.14159265358979323846;

/* The client's own copy of the seanindex formula. */
static int my_seanindex(int m, int l, int bw) {
    int bigL = bw - 1;
    if (m >= 0) return m * (bigL + 1) - ((m * (m - 1)) / 2) + (l - m);
    return ((bigL * (bigL + 3)) / 2) + 1 + ((bigL + m) * (bigL + m + 1) / 2) + (l - abs(m));
}

static double rnd(unsigned long long *s) {
    *s = *s * 6364136223846793005ULL + 1442695040888963407ULL;
    return (double)(*s >> 11) / 9007199254740992.0 - 0.5;
}

/* A random band-limited function of bandwidth bw sampled into re/im (real if `real`). */
static void random_function(int bw, int real, unsigned long long seed, double *re, double *im) {
    int n = bw * bw, m, l;
    double *cr = (double *)calloc((size_t)n, sizeof(double));
    double *ci = (double *)calloc((size_t)n, sizeof(double));
    for (l = 0; l < bw; l++)
        for (m = -l; m <= l; m++) {
            cr[my_seanindex(m, l, bw)] = rnd(&seed);
            ci[my_seanindex(m, l, bw)] = real && m == 0 ? 0.0 : rnd(&seed);
        }
    /* dataformat 1 reads only m >= 0 and takes the rest as (-1)^m conj(f(l,m)) */
    InvFST_semi_memo(cr, ci, re, im, bw, NULL, NULL, real ? 1 : 0, bw, NULL, NULL);
    free(cr);
    free(ci);
}

/* Grid index of the largest |C|^2 (strict >, from 0). */
static long argmax(fftw_complex *c, long n) {
    long i, at = 0;
    double best = 0.0;
    for (i = 0; i < n; i++) {
        double v = c[i][0] * c[i][0] + c[i][1] * c[i][1];
        if (v > best) {
            best = v;
            at = i;
        }
    }
    return at;
}

/* One registration; `real` selects sequence A (with `pad`) or B (degree limit bw/2 - 1). */
static void registration(int bw, int real, int pad, int ii, int jj, int kk) {
    int bout = bw + pad, n = 2 * bw, i;
    int deglim = real ? bw - 1 : bw / 2 - 1;
    long ng = 8L * bout * bout * bout, at;
    double alpha = PI_ * jj / bout, beta = PI_ * (2 * ii + 1) / (4.0 * bout), gamma = PI_ * kk / bout;
    double *patR = (double *)calloc((size_t)(n * n), sizeof(double));
    double *patI = (double *)calloc((size_t)(n * n), sizeof(double));
    double *sigR = (double *)calloc((size_t)(n * n), sizeof(double));
    double *sigI = (double *)calloc((size_t)(n * n), sizeof(double));
    double *inter = (double *)calloc((size_t)(4 * n * n), sizeof(double));
    double *weights = (double *)malloc(sizeof(double) * 4 * bw);
    double *sigCoefR = (double *)malloc(sizeof(double) * bw * bw);
    double *sigCoefI = (double *)malloc(sizeof(double) * bw * bw);
    double *patCoefR = (double *)malloc(sizeof(double) * bw * bw);
    double *patCoefI = (double *)malloc(sizeof(double) * bw * bw);
    double *workspace = (double *)malloc(sizeof(double) * (8 * bw * bw + 10 * bw));
    double *tablespace =
        (double *)malloc(sizeof(double) * (Reduced_Naive_TableSize(bw, bw) +
                                           Reduced_SpharmonicTableSize(bw, bw)));
    double *tableworkspace = (double *)malloc(sizeof(double) * (16 * bw));
    fftw_complex *so3Coef = (fftw_complex *)fftw_malloc(sizeof(fftw_complex) *
                                                        (size_t)totalCoeffs_so3(bout));
    fftw_complex *so3Sig = (fftw_complex *)fftw_malloc(sizeof(fftw_complex) * (size_t)ng);
    fftw_complex *ws1 = (fftw_complex *)fftw_malloc(sizeof(fftw_complex) * (size_t)ng);
    fftw_complex *ws2 = (fftw_complex *)fftw_malloc(sizeof(fftw_complex) * 2 * (size_t)bout);
    double *ws3 = (double *)malloc(sizeof(double) * (24 * bout + 2 * bout * bout));
    double **table;
    fftw_plan dct, fft, p1;
    fftw_iodim dims[1], howmany[1];

    /* the pattern, and the signal = the pattern rotated by the grid rotation (ii, jj, kk) */
    random_function(bw, real, 1234u + (unsigned)bw, patR, patI);
    for (i = 0; i < n * n; i++) {
        inter[2 * i] = patR[i];
        inter[2 * i + 1] = patI[i];
    }
    s2RotateFFTW(bw, inter, inter + 2 * n * n, alpha, beta, gamma, 0);
    for (i = 0; i < n * n; i++) {
        sigR[i] = inter[2 * n * n + 2 * i];
        sigI[i] = real ? 0.0 : inter[2 * n * n + 2 * i + 1];
    }

    /* the client's set-up: weights, tables, FFTW plans */
    makeweights(bw, weights);
    table = SemiNaive_Naive_Pml_Table(bw, bw, tablespace, tableworkspace);
    CHECK(table != NULL);
    dct = fftw_plan_r2r_1d(2 * bw, weights, patR, FFTW_REDFT10, FFTW_ESTIMATE);
    dims[0].n = 2 * bw;
    dims[0].is = 1;
    dims[0].os = 2 * bw;
    howmany[0].n = 2 * bw;
    howmany[0].is = 2 * bw;
    howmany[0].os = 1;
    fft = fftw_plan_guru_split_dft(1, dims, 1, howmany, patR, patI, workspace,
                                   workspace + 4 * bw * bw, FFTW_ESTIMATE);
    p1 = fftw_plan_dft_2d(2 * bout, 2 * bout, ws1, so3Sig, FFTW_BACKWARD, FFTW_ESTIMATE);
    CHECK(dct != NULL && fft != NULL && p1 != NULL);

    FST_semi_memo(sigR, sigI, sigCoefR, sigCoefI, bw, table, workspace, real, bw, &dct, &fft,
                  weights);
    FST_semi_memo(patR, patI, patCoefR, patCoefI, bw, table, workspace, real, bw, &dct, &fft,
                  weights);
    if (!real) {
        /* rotations keep the power of each degree: read through the client's own index */
        int l, m;
        for (l = 0; l < bw; l++) {
            double ps = 0.0, pp = 0.0;
            for (m = -l; m <= l; m++) {
                int k = my_seanindex(m, l, bw);
                ps += sigCoefR[k] * sigCoefR[k] + sigCoefI[k] * sigCoefI[k];
                pp += patCoefR[k] * patCoefR[k] + patCoefI[k] * patCoefI[k];
            }
            CHECK(fabs(ps - pp) < 1e-12 * (1.0 + pp));
        }
    }
    so3CombineCoef_fftw(bw, bout, deglim, sigCoefR, sigCoefI, patCoefR, patCoefI, so3Coef);
    Inverse_SO3_Naive_fftw(bout, so3Coef, so3Sig, ws1, ws2, ws3, &p1, real);
    at = argmax(so3Sig, ng);
    {
        long b = at / (4L * bout * bout), a = (at - b * 4L * bout * bout) / (2 * bout),
             g = at % (2 * bout);
        if (b != ii || a != jj || g != kk) {
            fprintf(stderr, "bw %d %s: found (%ld, %ld, %ld), planted (%d, %d, %d)\n", bw,
                    real ? "real, padded" : "complex, degree limit", b, a, g, ii, jj, kk);
            g_failures++;
        }
    }
    fftw_destroy_plan(dct);
    fftw_destroy_plan(fft);
    fftw_destroy_plan(p1);
    free(table);
    free(patR);
    free(patI);
    free(sigR);
    free(sigI);
    free(inter);
    free(weights);
    free(sigCoefR);
    free(sigCoefI);
    free(patCoefR);
    free(patCoefI);
    free(workspace);
    free(tablespace);
    free(tableworkspace);
    fftw_free(so3Coef);
    fftw_free(so3Sig);
    fftw_free(ws1);
    fftw_free(ws2);
    free(ws3);
}

int main(void) {
    registration(8, 1, 4, 5, 3, 17);   /* A: real, bw 8 on the bw 12 grid */
    registration(11, 1, 5, 20, 29, 2); /* A: odd bw, bw 16 grid */
    registration(12, 0, 0, 7, 4, 19);  /* B: complex, degree limit 5 */
    registration(9, 0, 0, 3, 11, 0);   /* B: odd bw, degree limit 3 */
    if (g_failures) {
        fprintf(stderr, "test_soft_registration: %d check(s) failed\n", g_failures);
        return 1;
    }
    printf("test_soft_registration: all checks passed\n");
    return 0;
}
