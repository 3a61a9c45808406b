/* The automatic real paths of the SOFT layer, through SOFT's header names only (plus the
 * native so3fft API as the complex truth): clients that keep real data in complex arrays
 * (imaginary parts 0) and call the flag-0 transforms get the real-signal transforms, with
 * the complex transforms' results within the documented error; complex data stays complex.
 * (Which path ran is not visible here: on real data both give exactly symmetric
 * coefficients and imaginary parts exactly 0. The Rust tests in src/soft/real_paths_tests.rs
 * count the paths taken.)
 *
 *  1. Forward_SO3_Naive_fftw, flag 0, real samples: the native complex forward's
 *     coefficients, exactly symmetric.
 *  2. Inverse_SO3_Naive_fftw, flag 0, exactly symmetric coefficients: direct summation
 *     (B = 5) and the native complex inverse (B = 16), imaginary parts exactly 0.
 *  3. Complex inputs stay complex, which a wrong real path would show: one nonzero
 *     imaginary sample (the complex forward's coefficients, not symmetric), a NaN imaginary
 *     sample (NaN in the result; the real path never reads imaginary parts), one coefficient
 *     of a partner block the real inverse does not read off by one ulp (the complex result)
 *     or by 1e-3 (the complex result, imaginary parts not all 0) or NaN (NaN in the samples).
 *  4. A registration client's sequence: two FST_semi_memo of real functions (dataformat 0,
 *     idata 0), so3CombineCoef_fftw, Inverse_SO3_Naive_fftw flag 0: exactly symmetric SO(3)
 *     coefficients, samples with imaginary parts exactly 0, equal to the native complex
 *     inverse of the same coefficients within the documented error. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <fftw3.h>

#include "makeweights.h"
#include "s2_semi_memo.h"
#include "so3_correlate_fftw.h"
#include "soft_fftw.h"
#include "utils_so3.h"

#include "so3fft.h"

#include "soft_test_util.h"

/* Documented accuracy at these bandwidths: 1e-12 of the largest value. */
#define TOL 1e-12

static double max_abs(fftw_complex *a, size_t n) {
    double m = 0.0;
    size_t i;
    for (i = 0; i < n; i++) {
        double v = hypot(a[i][0], a[i][1]);
        if (v > m) m = v;
    }
    return m;
}

static int any_nonfinite(fftw_complex *a, size_t n) {
    size_t i;
    for (i = 0; i < n; i++)
        if (!isfinite(a[i][0]) || !isfinite(a[i][1])) return 1;
    return 0;
}

static int all_imag_zero(fftw_complex *a, size_t n) {
    size_t i;
    for (i = 0; i < n; i++)
        if (a[i][1] != 0.0) return 0;
    return 1;
}

/* Symmetry defect including Im fhat(l,0,0). */
static double full_defect(int bw, fftw_complex *c) {
    double d = symmetry_defect(bw, c);
    int l;
    for (l = 0; l < bw; l++) {
        double v = fabs(c[so3CoefLoc(0, 0, l, bw)][1]);
        if (v > d) d = v;
    }
    return d;
}

static void soft_forward(int bw, fftw_complex *data, fftw_complex *coeffs) {
    size_t n3 = (size_t)8 * bw * bw * bw;
    fftw_complex *ws = alloc_cx(n3), *ws2 = alloc_cx(n3);
    double *wre = alloc_re((size_t)(24 * bw + 2 * bw * bw)), *w = alloc_re((size_t)(4 * bw));
    fftw_plan p = client_plan(bw, ws, ws2, FFTW_BACKWARD);
    makeweights(bw, w);
    Forward_SO3_Naive_fftw(bw, data, coeffs, ws, ws2, wre, w, &p, 0);
    fftw_destroy_plan(p);
    fftw_free(w);
    fftw_free(wre);
    fftw_free(ws2);
    fftw_free(ws);
}

static void soft_inverse(int bw, fftw_complex *coeffs, fftw_complex *data) {
    size_t n3 = (size_t)8 * bw * bw * bw;
    fftw_complex *ws = alloc_cx(n3), *ws2 = alloc_cx((size_t)(2 * bw));
    double *wre = alloc_re((size_t)(24 * bw + 2 * bw * bw));
    fftw_plan p = client_plan(bw, ws, data, FFTW_FORWARD);
    Inverse_SO3_Naive_fftw(bw, coeffs, data, ws, ws2, wre, &p, 0);
    fftw_destroy_plan(p);
    fftw_free(wre);
    fftw_free(ws2);
    fftw_free(ws);
}

/* The native complex plan: the truth the real paths must reproduce. */
static so3fft_plan native_plan(int bw) {
    so3fft_plan p = so3fft_plan_both(bw, SO3FFT_ESTIMATE);
    if (!p) {
        fprintf(stderr, "so3fft_plan_both(%d): %s\n", bw, so3fft_last_error());
        exit(EXIT_FAILURE);
    }
    return p;
}

static void test_forward(int bw, unsigned long long seed) {
    size_t ns = (size_t)8 * bw * bw * bw, nc = (size_t)totalCoeffs_so3(bw), i;
    fftw_complex *s = alloc_cx(ns), *got = alloc_cx(nc), *want = alloc_cx(nc);
    so3fft_plan p = native_plan(bw);
    double scale;
    for (i = 0; i < ns; i++) {
        s[i][0] = rnd(&seed);
        s[i][1] = 0.0;
    }
    CHECK(so3fft_execute_forward(p, s, want) == SO3FFT_OK);
    scale = max_abs(want, nc);
    soft_forward(bw, s, got);
    CHECK_CLOSE(max_abs_diff(got, want, nc), TOL * scale, "flag-0 forward of real samples");
    CHECK(full_defect(bw, got) == 0.0);

    /* one nonzero imaginary part at a pseudo-random place: the complex forward */
    i = (size_t)((rnd(&seed) + 1.0) * 0.5 * (double)ns) % ns;
    s[i][1] = 0.25;
    CHECK(so3fft_execute_forward(p, s, want) == SO3FFT_OK);
    soft_forward(bw, s, got);
    CHECK_CLOSE(max_abs_diff(got, want, nc), TOL * scale, "flag-0 forward, one imaginary part");
    CHECK(full_defect(bw, got) > 1e-6);

    /* a NaN imaginary part: complex (the real path would not read it) */
    s[i][1] = NAN;
    soft_forward(bw, s, got);
    CHECK(any_nonfinite(got, nc));

    so3fft_destroy_plan(p);
    fftw_free(want);
    fftw_free(got);
    fftw_free(s);
}

static void test_inverse(int bw, unsigned long long seed, int direct) {
    size_t ns = (size_t)8 * bw * bw * bw, nc = (size_t)totalCoeffs_so3(bw);
    fftw_complex *c = alloc_cx(nc), *got = alloc_cx(ns), *want = alloc_cx(ns);
    double scale;
    int q;
    random_coeffs(bw, c, 1, seed);
    if (direct) {
        direct_inverse(bw, c, want);
    } else {
        so3fft_plan p = native_plan(bw);
        CHECK(so3fft_execute_inverse(p, c, want) == SO3FFT_OK);
        so3fft_destroy_plan(p);
    }
    scale = max_abs(want, ns);
    soft_inverse(bw, c, got);
    CHECK_CLOSE(max_abs_diff(got, want, ns), (direct ? 1e-11 : TOL) * scale,
                "flag-0 inverse of symmetric coefficients");
    CHECK(all_imag_zero(got, ns));

    /* fhat(bw-1, -1, -2), in a block the real inverse does not read, one ulp off: the
     * complex inverse (which gives these samples to rounding too; the Rust tests check
     * the path taken bit for bit) */
    q = so3CoefLoc(-1, -2, bw - 1, bw);
    c[q][0] = nextafter(c[q][0], 1e300);
    soft_inverse(bw, c, got);
    CHECK_CLOSE(max_abs_diff(got, want, ns), (direct ? 1e-11 : TOL) * scale,
                "flag-0 inverse, one ulp off");
    /* off by 1e-3: the complex inverse's nonzero imaginary parts (the real inverse, which
     * does not read that block, would give the symmetric coefficients' samples) */
    c[q][1] += 1e-3;
    if (direct) {
        direct_inverse(bw, c, want);
    } else {
        so3fft_plan p = native_plan(bw);
        CHECK(so3fft_execute_inverse(p, c, want) == SO3FFT_OK);
        so3fft_destroy_plan(p);
    }
    soft_inverse(bw, c, got);
    CHECK_CLOSE(max_abs_diff(got, want, ns), (direct ? 1e-11 : TOL) * scale,
                "flag-0 inverse, one partner off by 1e-3");
    CHECK(!all_imag_zero(got, ns));
    /* NaN there: complex, so NaN reaches the samples */
    c[q][0] = NAN;
    soft_inverse(bw, c, got);
    CHECK(any_nonfinite(got, ns));

    fftw_free(want);
    fftw_free(got);
    fftw_free(c);
}

/* The registration sequence of a SOFT client on real functions. */
static void test_registration(int bw, unsigned long long seed) {
    int n = 2 * bw, k;
    size_t s2 = (size_t)n * n, ns = (size_t)n * s2, nc = (size_t)totalCoeffs_so3(bw);
    double *r[2], *im[2], *cr[2], *ci[2], scale;
    fftw_complex *so3 = alloc_cx(nc), *got = alloc_cx(ns), *want = alloc_cx(ns);
    so3fft_plan p = native_plan(bw);
    for (k = 0; k < 2; k++) {
        size_t i;
        r[k] = alloc_re(s2);
        im[k] = alloc_re(s2);
        cr[k] = alloc_re((size_t)bw * bw);
        ci[k] = alloc_re((size_t)bw * bw);
        for (i = 0; i < s2; i++) {
            r[k][i] = rnd(&seed);
            im[k][i] = 0.0;
        }
        FST_semi_memo(r[k], im[k], cr[k], ci[k], bw, NULL, NULL, 0, bw, NULL, NULL, NULL);
    }
    so3CombineCoef_fftw(bw, bw, bw - 1, cr[0], ci[0], cr[1], ci[1], so3);
    CHECK(full_defect(bw, so3) == 0.0);
    CHECK(so3fft_execute_inverse(p, so3, want) == SO3FFT_OK);
    scale = max_abs(want, ns);
    soft_inverse(bw, so3, got);
    CHECK_CLOSE(max_abs_diff(got, want, ns), TOL * scale, "registration correlation");
    CHECK(all_imag_zero(got, ns));
    for (k = 0; k < 2; k++) {
        fftw_free(r[k]);
        fftw_free(im[k]);
        fftw_free(cr[k]);
        fftw_free(ci[k]);
    }
    so3fft_destroy_plan(p);
    fftw_free(want);
    fftw_free(got);
    fftw_free(so3);
}

int main(void) {
    test_forward(6, 1ULL);
    test_forward(16, 2ULL);
    test_inverse(5, 3ULL, 1);
    test_inverse(16, 4ULL, 0);
    test_registration(8, 5ULL);
    test_registration(16, 6ULL);
    return finish("test_soft_real_paths");
}
