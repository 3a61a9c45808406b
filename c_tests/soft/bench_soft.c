/* Timing of the SOFT-layer entry points against the native so3fft C API on the same work.
 * Usage: bench_soft [B ...] (default 32 64 128). Median wall time of 5 interleaved runs.
 * The flag-0 calls run on complex data (the complex path) and, in the rows marked "real
 * data", on real samples / exactly symmetric coefficients in the same complex arrays (the
 * layer's automatic real paths); inputs are never modified, so each keeps its kind. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <fftw3.h>

#include "so3fft.h"

#include "csecond.h"
#include "makeweights.h"
#include "soft_fftw.h"
#include "utils_so3.h"
#include "wrap_fftw.h"

#include "soft_test_util.h"

#define RUNS 5
enum { NAT_F, NAT_I, SOFT_F0, SOFT_F0R, SOFT_F1, SOFT_I0, SOFT_I0R, SOFT_I1, W_F, W_I, NCASES };
static const char *names[NCASES] = {"native forward", "native inverse",
                                    "Forward_SO3_Naive_fftw flag 0",
                                    "Forward_SO3_Naive_fftw flag 0, real data",
                                    "Forward_SO3_Naive_fftw flag 1",
                                    "Inverse_SO3_Naive_fftw flag 0",
                                    "Inverse_SO3_Naive_fftw flag 0, real data",
                                    "Inverse_SO3_Naive_fftw flag 1",
                                    "Forward_SO3_Naive_fftw_W", "Inverse_SO3_Naive_fftw_W"};

static const int is_fwd[NCASES] = {1, 0, 1, 1, 1, 0, 0, 0, 1, 0};

static int cmp(const void *a, const void *b) {
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

int main(int argc, char **argv) {
    int defaults[3] = {32, 64, 128}, nb = argc > 1 ? argc - 1 : 3, ib;
    for (ib = 0; ib < nb; ib++) {
        int bw = argc > 1 ? atoi(argv[ib + 1]) : defaults[ib], r, c;
        size_t n3 = (size_t)8 * bw * bw * bw, nc = (size_t)totalCoeffs_so3(bw);
        fftw_complex *s = alloc_cx(n3), *co = alloc_cx(nc), *ws = alloc_cx(n3), *ws2 = alloc_cx(n3);
        /* inputs of fixed kind: complex samples and coefficients, real samples, symmetric
         * coefficients */
        fftw_complex *sc = alloc_cx(n3), *cc = alloc_cx(nc), *sr = alloc_cx(n3), *cr = alloc_cx(nc);
        double *wre = alloc_re((size_t)(24 * bw + 2 * bw * bw)), *w = alloc_re((size_t)(2 * bw));
        double t[NCASES][RUNS], t0;
        so3fft_plan p = so3fft_plan_both(bw, SO3FFT_MEASURE);
        fftw_plan dummy = NULL;
        makeweights2(bw, w);
        random_coeffs(bw, cc, 0, 3);
        random_coeffs(bw, cr, 1, 4);
        t0 = csecond();
        Inverse_SO3_Naive_fftw(bw, cc, sc, ws, ws2, wre, &dummy, 0); /* SOFT-layer plan set-up */
        printf("B = %d: SOFT-layer first call (plan set-up + inverse) %.3f s\n", bw, csecond() - t0);
        Inverse_SO3_Naive_fftw(bw, cr, sr, ws, ws2, wre, &dummy, 1); /* real samples */
        for (r = 0; r < RUNS; r++)
            for (c = 0; c < NCASES; c++) {
                t0 = csecond();
                switch (c) {
                case NAT_F: so3fft_execute_forward(p, sc, co); break;
                case NAT_I: so3fft_execute_inverse(p, cc, s); break;
                case SOFT_F0: Forward_SO3_Naive_fftw(bw, sc, co, ws, ws2, wre, w, &dummy, 0); break;
                case SOFT_F0R: Forward_SO3_Naive_fftw(bw, sr, co, ws, ws2, wre, w, &dummy, 0); break;
                case SOFT_F1: Forward_SO3_Naive_fftw(bw, sr, co, ws, ws2, wre, w, &dummy, 1); break;
                case SOFT_I0: Inverse_SO3_Naive_fftw(bw, cc, s, ws, ws2, wre, &dummy, 0); break;
                case SOFT_I0R: Inverse_SO3_Naive_fftw(bw, cr, s, ws, ws2, wre, &dummy, 0); break;
                case SOFT_I1: Inverse_SO3_Naive_fftw(bw, cr, s, ws, ws2, wre, &dummy, 1); break;
                case W_F: Forward_SO3_Naive_fftw_W(bw, sr, co, 1); break;
                default: Inverse_SO3_Naive_fftw_W(bw, cr, s, 1); break;
                }
                t[c][r] = csecond() - t0;
            }
        for (c = 0; c < NCASES; c++) {
            qsort(t[c], RUNS, sizeof(double), cmp);
            printf("  %-42s %8.4f s  (x%.2f native)\n", names[c], t[c][RUNS / 2],
                   t[c][RUNS / 2] / t[is_fwd[c] ? NAT_F : NAT_I][RUNS / 2]);
        }
        so3fft_destroy_plan(p);
        fftw_free(w);
        fftw_free(wre);
        fftw_free(ws2);
        fftw_free(ws);
        fftw_free(cr);
        fftw_free(sr);
        fftw_free(cc);
        fftw_free(sc);
        fftw_free(co);
        fftw_free(s);
    }
    return 0;
}
