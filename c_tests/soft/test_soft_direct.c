/* SOFT-style client test: transforms against direct summation at small bandwidths (flag 0 and
 * 1), caller-supplied quadrature weights, the _pc tables, and so3CombineCoef_fftw against its
 * formula. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <fftw3.h>

#include "makeWigner.h"
#include "makeweights.h"
#include "so3_correlate_fftw.h"
#include "soft_fftw.h"
#include "soft_fftw_pc.h"
#include "utils_so3.h"

#include "soft_test_util.h"

static void direct_checks(int bw, int flag) {
    int n = 2 * bw, i;
    size_t n3 = (size_t)n * n * n, nc = (size_t)totalCoeffs_so3(bw);
    fftw_complex *c = alloc_cx(nc), *c2 = alloc_cx(nc), *c3 = alloc_cx(nc);
    fftw_complex *s = alloc_cx(n3), *sd = alloc_cx(n3);
    fftw_complex *ws_cx = alloc_cx(n3), *ws_cx2 = alloc_cx(n3);
    double *ws_re = alloc_re((size_t)(24 * bw + 2 * bw * bw));
    double *w4 = alloc_re((size_t)(4 * bw)), *w2 = alloc_re((size_t)(2 * bw));
    fftw_plan pf = client_plan(bw, ws_cx2, ws_cx, FFTW_BACKWARD);
    fftw_plan pi = client_plan(bw, ws_cx, s, FFTW_FORWARD);
    char what[64];

    random_coeffs(bw, c, flag, 1234u + (unsigned)bw);
    direct_inverse(bw, c, sd);
    Inverse_SO3_Naive_fftw(bw, c, s, ws_cx, ws_cx2, ws_re, &pi, flag);
    snprintf(what, sizeof what, "inverse vs direct sum, B=%d flag %d", bw, flag);
    CHECK_CLOSE(max_abs_diff(s, sd, n3), 1e-12, what);

    /* forward with makeweights (first 2B of 4B) and with makeweights2 */
    makeweights(bw, w4);
    makeweights2(bw, w2);
    for (i = 0; i < 2 * bw; i++) {
        double beta = M_PI * (2 * i + 1) / (4.0 * bw);
        CHECK(w4[i] == w2[i]);
        CHECK(fabs(w4[i + 2 * bw] - w2[i] * sin(beta)) <= 1e-16);
    }
    Forward_SO3_Naive_fftw(bw, sd, c2, ws_cx, ws_cx2, ws_re, w4, &pf, flag);
    snprintf(what, sizeof what, "forward of direct samples, B=%d flag %d", bw, flag);
    CHECK_CLOSE(max_abs_diff(c2, c, nc), 1e-12, what);

    /* caller's weights are honoured: doubling the weight of beta slice 1 alone equals adding
     * the forward transform of that slice once more */
    w2[1] *= 2.0;
    Forward_SO3_Naive_fftw(bw, sd, c2, ws_cx, ws_cx2, ws_re, w2, &pf, 0);
    {
        fftw_complex *only = alloc_cx(n3);
        memset(only, 0, n3 * sizeof(fftw_complex));
        memcpy(only + (size_t)n * n, sd + (size_t)n * n, (size_t)n * n * sizeof(fftw_complex));
        makeweights2(bw, w2);
        Forward_SO3_Naive_fftw(bw, only, c3, ws_cx, ws_cx2, ws_re, w2, &pf, 0);
        for (i = 0; i < (int)nc; i++) {
            c3[i][0] += c[i][0];
            c3[i][1] += c[i][1];
        }
        snprintf(what, sizeof what, "custom weights, B=%d", bw);
        CHECK_CLOSE(max_abs_diff(c2, c3, nc), 1e-12, what);
        fftw_free(only);
    }

    fftw_destroy_plan(pi);
    fftw_destroy_plan(pf);
    fftw_free(w2);
    fftw_free(w4);
    fftw_free(ws_re);
    fftw_free(ws_cx2);
    fftw_free(ws_cx);
    fftw_free(sd);
    fftw_free(s);
    fftw_free(c3);
    fftw_free(c2);
    fftw_free(c);
}

/* One block of the tables at `pos` against sqrt((2l+1)/2) d^l_{m1,m2}(beta_k): rows l (the
 * 2bw betas each) in `t`, the transpose in `tt`. Returns the position of the next block. */
static size_t check_block(int bw, const double *t, const double *tt, size_t pos, int m1, int m2,
                          double *worst) {
    int n = 2 * bw, lo = m1 > m2 ? m1 : m2, rows = bw - lo, l, k;
    for (l = lo; l < bw; l++)
        for (k = 0; k < n; k++) {
            double beta = M_PI * (2 * k + 1) / (4.0 * bw);
            double want = sqrt((2 * l + 1) / 2.0) * wigner_d(l, m1, m2, beta);
            double a = t[pos + (size_t)(l - lo) * n + k];
            double b = tt[pos + (size_t)k * rows + (l - lo)];
            if (fabs(a - want) > *worst) *worst = fabs(a - want);
            CHECK(a == b);
        }
    return pos + (size_t)rows * n;
}

/* genWigAll / genWigAllTrans write exactly bw^2 (bw+1)(bw+2)/3 doubles (allocated exactly,
 * so valgrind catches any overrun) holding sqrt((2l+1)/2) d^l_{m1,m2}(beta_k), in blocks
 * ordered as SOFT's makeWigner: (0,0); (m,m) for m = 1..bw-1; (m,0) for m = 1..bw-1; then
 * (m1,m2) for m1 = 1..bw-1, m2 = m1+1..bw-1. */
static void table_checks(int bw) {
    int m1, m2;
    size_t len = (size_t)(bw * bw * (bw * bw + 3 * bw + 2)) / 3, pos = 0;
    double *t = alloc_re(len), *tt = alloc_re(len), *ws = alloc_re((size_t)(24 * bw + 2 * bw * bw));
    double worst = 0.0;
    genWigAll(bw, t, ws);
    genWigAllTrans(bw, tt, ws);
    pos = check_block(bw, t, tt, pos, 0, 0, &worst);
    for (m1 = 1; m1 < bw; m1++) pos = check_block(bw, t, tt, pos, m1, m1, &worst);
    for (m1 = 1; m1 < bw; m1++) pos = check_block(bw, t, tt, pos, m1, 0, &worst);
    for (m1 = 1; m1 < bw; m1++)
        for (m2 = m1 + 1; m2 < bw; m2++) pos = check_block(bw, t, tt, pos, m1, m2, &worst);
    CHECK(pos == len);
    CHECK_CLOSE(worst, 1e-13, "genWigAll table values");
    fftw_free(ws);
    fftw_free(tt);
    fftw_free(t);
}

/* so3CombineCoef_fftw against its formula, and its use in a correlation-style pipeline. */
static void combine_checks(int bwIn, int bwOut, int degLim) {
    size_t nin = (size_t)bwIn * bwIn, nout = (size_t)totalCoeffs_so3(bwOut), i;
    double *fr = alloc_re(nin), *fi = alloc_re(nin), *hr = alloc_re(nin), *hi = alloc_re(nin);
    fftw_complex *out = alloc_cx(nout);
    unsigned long long seed = 99;
    int l, m1, m2;
    double worst = 0.0;
    for (i = 0; i < nin; i++) {
        fr[i] = rnd(&seed);
        fi[i] = rnd(&seed);
        hr[i] = rnd(&seed);
        hi[i] = rnd(&seed);
    }
    for (i = 0; i < nout; i++) out[i][0] = out[i][1] = NAN;
    so3CombineCoef_fftw(bwIn, bwOut, degLim, fr, fi, hr, hi, out);
    for (l = 0; l < bwOut; l++)
        for (m1 = -l; m1 <= l; m1++)
            for (m2 = -l; m2 <= l; m2++) {
                int o = so3CoefLoc(m1, m2, l, bwOut);
                double wr = 0.0, wi = 0.0;
                if (l <= degLim) {
                    int a = seanindex(-m1, l, bwIn), b = seanindex(-m2, l, bwIn);
                    double s = 2 * M_PI * sqrt(2.0 / (2 * l + 1)) * sgn(m1 + m2);
                    /* f * conj(h) */
                    wr = s * (fr[a] * hr[b] + fi[a] * hi[b]);
                    wi = s * (fi[a] * hr[b] - fr[a] * hi[b]);
                }
                if (fabs(out[o][0] - wr) > worst || out[o][0] != out[o][0]) worst = fabs(out[o][0] - wr);
                if (fabs(out[o][1] - wi) > worst || out[o][1] != out[o][1]) worst = fabs(out[o][1] - wi);
            }
    CHECK_CLOSE(worst, 1e-14, "so3CombineCoef_fftw");
    fftw_free(out);
    fftw_free(hi);
    fftw_free(hr);
    fftw_free(fi);
    fftw_free(fr);
}

int main(void) {
    direct_checks(3, 0);
    direct_checks(3, 1);
    direct_checks(5, 0);
    direct_checks(5, 1);
    table_checks(1);
    table_checks(4);
    table_checks(7);
    combine_checks(6, 6, 5);
    combine_checks(6, 4, 3);
    combine_checks(4, 7, 2);
    fftw_cleanup();
    return finish("test_soft_direct");
}
