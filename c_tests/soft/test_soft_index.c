/* SOFT-style client test: index and size functions against their closed forms and the spot
 * values of docs/conventions.md, makeweights against the weight formula, and the no-error-channel behaviour on
 * invalid input (nothing written, one line on stderr). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <fftw3.h>

#include "csecond.h"
#include "makeweights.h"
#include "so3_correlate_fftw.h"
#include "soft_fftw.h"
#include "utils_so3.h"
#include "wrap_fftw.h"

#include "soft_test_util.h"

/* so3CoefLoc by the closed form of docs/conventions.md (64-bit). */
static long long closed_form(int m, int mp, int l, int bw) {
    long long B = bw, a = ABS(m), T = (4 * B * B * B - B) / 3, row, off = 0, k;
    if (m >= 0)
        row = m * B * B - (long long)(m - 1) * m * (2 * m - 1) / 6;
    else
        row = T - (a * B * B - a * (a + 1) * (2 * a + 1) / 6);
    if (mp >= 0) {
        for (k = 0; k < mp; k++) off += B - MAX(a, k);
    } else {
        off = B * B - (long long)m * m;
        for (k = mp; k <= -1; k++) off -= B - MAX(a, -k);
    }
    return row + off + (l - MAX(a, ABS(mp)));
}

static void layout_checks(int bw) {
    int l, m, mp, expect = 0, t = totalCoeffs_so3(bw);
    char *seen = (char *)calloc((size_t)t, 1);
    CHECK(t == (4 * bw * bw * bw - bw) / 3);
    for (m = -(bw - 1); m < bw; m++) {
        int cnt = 0;
        CHECK(numCoeffs_so3(bw, m) == bw * bw - m * m);
        for (mp = -(bw - 1); mp < bw; mp++) {
            CHECK(howMany_so3(m, mp, bw) == bw - MAX(ABS(m), ABS(mp)));
            CHECK(coefLoc_so3(m, mp, bw) == so3CoefLoc(m, mp, MAX(ABS(m), ABS(mp)), bw));
            CHECK(sampLoc_so3(m, mp, bw) ==
                  2 * bw * (2 * bw * ((m + 2 * bw) % (2 * bw)) + (mp + 2 * bw) % (2 * bw)));
            cnt += howMany_so3(m, mp, bw);
            for (l = MAX(ABS(m), ABS(mp)); l < bw; l++) {
                int i = so3CoefLoc(m, mp, l, bw);
                CHECK((long long)i == closed_form(m, mp, l, bw));
                CHECK(i >= 0 && i < t);
                if (i >= 0 && i < t) {
                    CHECK(!seen[i]);
                    seen[i] = 1;
                }
            }
        }
        CHECK(cnt == numCoeffs_so3(bw, m));
    }
    /* blocks in SOFT's order: (0,0), (0,1), ..., (0,-1), (1,0), ... each contiguous */
    for (m = 0; m < 2 * bw - 1; m++) {
        int mm = m < bw ? m : m - (2 * bw - 1);
        for (mp = 0; mp < 2 * bw - 1; mp++) {
            int mmp = mp < bw ? mp : mp - (2 * bw - 1);
            CHECK(coefLoc_so3(mm, mmp, bw) == expect);
            expect += howMany_so3(mm, mmp, bw);
        }
    }
    CHECK(expect == t);
    free(seen);
}

int main(void) {
    int bw, m, l, k, i;

    /* docs/conventions.md spot values, listed there as (M, M', l) */
    CHECK(so3CoefLoc(0, 0, 0, 256) == 0);
    CHECK(so3CoefLoc(0, 0, 255, 256) == 255);
    CHECK(so3CoefLoc(0, 1, 1, 256) == 256);
    CHECK(so3CoefLoc(0, -1, 1, 256) == 65281);
    CHECK(so3CoefLoc(1, 0, 1, 256) == 65536);
    CHECK(so3CoefLoc(-1, 0, 1, 256) == 22304001);
    CHECK(so3CoefLoc(-1, -1, 255, 256) == 22369535);
    CHECK(totalCoeffs_so3(256) == 22369536);
    for (bw = 1; bw <= 9; bw++) layout_checks(bw);
    layout_checks(32);

    /* seanindex: m >= 0 blocks by increasing m, then m = -(bw-1) .. -1; l fastest */
    for (bw = 1; bw <= 8; bw++) {
        k = 0;
        for (m = 0; m < bw; m++)
            for (l = m; l < bw; l++) CHECK(seanindex(m, l, bw) == k++);
        for (m = -(bw - 1); m < 0; m++)
            for (l = -m; l < bw; l++) CHECK(seanindex(m, l, bw) == k++);
        CHECK(k == bw * bw);
    }

    /* weights: the formula of docs/conventions.md, and they integrate sin(beta) exactly (sum = 2) */
    for (bw = 1; bw <= 16; bw *= 2) {
        double *w = alloc_re((size_t)(4 * bw)), sum = 0.0;
        makeweights(bw, w);
        for (k = 0; k < 2 * bw; k++) {
            double beta = M_PI * (2 * k + 1) / (4.0 * bw), s = 0.0;
            for (i = 0; i < bw; i++) s += sin((2 * i + 1) * beta) / (2 * i + 1);
            CHECK(fabs(w[k] - 2.0 / bw * sin(beta) * s) <= 1e-15);
            CHECK(fabs(w[k + 2 * bw] - w[k] * sin(beta)) <= 1e-15);
            sum += w[k];
        }
        CHECK(fabs(sum - 2.0) <= 1e-13);
        fftw_free(w);
    }

    /* invalid input: nothing is written, -1 from int functions */
    {
        fftw_complex *a = alloc_cx(64), *b = alloc_cx(64);
        double wsent[4] = {7.0, 7.0, 7.0, 7.0};
        for (i = 0; i < 64; i++) b[i][0] = b[i][1] = 42.0;
        memset(a, 0, 64 * sizeof(fftw_complex));
        fprintf(stderr, "(the following error lines are expected)\n");
        Forward_SO3_Naive_fftw_W(0, a, b, 0);
        Inverse_SO3_Naive_fftw_W(-3, a, b, 1);
        Forward_SO3_Naive_fftw_W(2, NULL, b, 0);
        Forward_SO3_Naive_fftw_W(2, b, b, 0); /* in place: overlapping, refused */
        for (i = 0; i < 64; i++) CHECK(b[i][0] == 42.0 && b[i][1] == 42.0);
        makeweights(0, wsent);
        for (i = 0; i < 4; i++) CHECK(wsent[i] == 7.0);
        CHECK(so3CoefLoc(2, 0, 1, 4) == -1);
        CHECK(so3CoefLoc(0, 0, 4, 4) == -1);
        CHECK(seanindex(3, 2, 4) == -1);
        CHECK(totalCoeffs_so3(2048) == -1); /* does not fit in an int */
        fftw_free(b);
        fftw_free(a);
    }

    {
        double t0 = csecond(), t1 = csecond();
        CHECK(t0 > 1e9 && t1 >= t0);
    }
    return finish("test_soft_index");
}
