/* Helpers shared by the C tests of so3fft's SOFT 2.0 compatibility layer. The tests are
 * written the way SOFT clients are: <fftw3.h> first, then SOFT's header names. */
#ifndef SO3FFT_SOFT_TEST_UTIL_H
#define SO3FFT_SOFT_TEST_UTIL_H

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <fftw3.h>

#include "utils_so3.h"

#include "../check.h"

#define CHECK_CLOSE(err, tol, what)                                                    \
    do {                                                                               \
        double e_ = (err);                                                             \
        if (!(e_ <= (tol))) {                                                          \
            fprintf(stderr, "%s:%d: %s: error %.3e > %.1e\n", __FILE__, __LINE__,      \
                    (what), e_, (double)(tol));                                        \
            g_failures++;                                                              \
        }                                                                              \
    } while (0)

static inline void *xmalloc(size_t bytes) {
    void *p = fftw_malloc(bytes);
    if (!p) {
        fprintf(stderr, "fftw_malloc(%lu) failed\n", (unsigned long)bytes);
        exit(EXIT_FAILURE);
    }
    return p;
}

static inline fftw_complex *alloc_cx(size_t n) { return (fftw_complex *)xmalloc(n * sizeof(fftw_complex)); }
static inline double *alloc_re(size_t n) { return (double *)xmalloc(n * sizeof(double)); }

static inline fftw_complex *dup_cx(fftw_complex *a, size_t n) {
    fftw_complex *c = alloc_cx(n);
    memcpy(c, a, n * sizeof(fftw_complex));
    return c;
}

static inline double max_abs_diff(fftw_complex *a, fftw_complex *b, size_t n) {
    double m = 0.0;
    size_t i;
    for (i = 0; i < n; i++) {
        double d = hypot(a[i][0] - b[i][0], a[i][1] - b[i][1]);
        if (!(d <= m)) m = d; /* NaN propagates */
    }
    return m;
}

/* (-1)^k */
static inline double sgn(int k) { return (k % 2 == 0) ? 1.0 : -1.0; }

static inline double fact(int n) {
    double f = 1.0;
    int i;
    for (i = 2; i <= n; i++) f *= i;
    return f;
}

/* Wigner small d^l_{m,mp}(beta) (Edmonds; d^1_{1,0} = -sin(b)/sqrt 2) by the explicit sum
 * (exact enough for the small degrees used here). */
static inline double wigner_d(int l, int m, int mp, double beta) {
    double c = cos(beta / 2.0), s = sin(beta / 2.0), sum = 0.0;
    int k;
    for (k = 0; k <= 2 * l; k++) {
        int a = l + mp - k, b = k, cc = m - mp + k, d = l - m - k;
        if (a < 0 || cc < 0 || d < 0) continue;
        sum += sgn(m - mp + k) / (fact(a) * fact(b) * fact(cc) * fact(d)) *
               pow(c, 2 * l + mp - m - 2 * k) * pow(s, m - mp + 2 * k);
    }
    return sqrt(fact(l + m) * fact(l - m) * fact(l + mp) * fact(l - mp)) * sum;
}

/* Direct inverse: f(alpha_j1, beta_k, gamma_j2) = sum fhat Dt^l_{m,mp}, layout of docs/conventions.md. */
static inline void direct_inverse(int bw, fftw_complex *coeffs, fftw_complex *out) {
    int n = 2 * bw, k, j1, j2, l, m, mp;
    for (k = 0; k < n; k++) {
        double beta = M_PI * (2 * k + 1) / (4.0 * bw);
        for (j1 = 0; j1 < n; j1++) {
            for (j2 = 0; j2 < n; j2++) {
                double re = 0.0, im = 0.0;
                double alpha = M_PI * j1 / bw, gamma = M_PI * j2 / bw;
                for (l = 0; l < bw; l++)
                    for (m = -l; m <= l; m++)
                        for (mp = -l; mp <= l; mp++) {
                            int i = so3CoefLoc(m, mp, l, bw);
                            double d = sqrt((2 * l + 1) / 2.0) / (2 * M_PI) *
                                       wigner_d(l, m, mp, beta);
                            double ph = -(m * alpha + mp * gamma);
                            double cr = cos(ph) * d, ci = sin(ph) * d;
                            re += coeffs[i][0] * cr - coeffs[i][1] * ci;
                            im += coeffs[i][0] * ci + coeffs[i][1] * cr;
                        }
                out[(k * n + j1) * n + j2][0] = re;
                out[(k * n + j1) * n + j2][1] = im;
            }
        }
    }
}

/* Random coefficients; with real != 0, symmetric ones (those of a real signal). */
static inline void random_coeffs(int bw, fftw_complex *c, int real, unsigned long long seed) {
    int l, m, mp, t = totalCoeffs_so3(bw);
    for (l = 0; l < t; l++) {
        c[l][0] = rnd(&seed);
        c[l][1] = rnd(&seed);
    }
    if (!real) return;
    for (l = 0; l < bw; l++) {
        c[so3CoefLoc(0, 0, l, bw)][1] = 0.0;
        for (m = -l; m <= l; m++)
            for (mp = -l; mp <= l; mp++) {
                int p = so3CoefLoc(m, mp, l, bw), q = so3CoefLoc(-m, -mp, l, bw);
                if (p < q) {
                    c[q][0] = sgn(m - mp) * c[p][0];
                    c[q][1] = -sgn(m - mp) * c[p][1];
                }
            }
    }
}

/* Is block (m, mp) one of those a real (flag = 1) inverse reads? */
static inline int real_block_read(int m, int mp) {
    if (m == 0) return mp >= 0;
    if (m > 0) return mp != -m;
    return mp == -m;
}

/* Largest violation of fhat(l,-m,-mp) = (-1)^(m-mp) conj(fhat(l,m,mp)) (0 when exact). */
static inline double symmetry_defect(int bw, fftw_complex *c) {
    double worst = 0.0;
    int l, m, mp;
    for (l = 0; l < bw; l++)
        for (m = -l; m <= l; m++)
            for (mp = -l; mp <= l; mp++) {
                int p = so3CoefLoc(m, mp, l, bw), q = so3CoefLoc(-m, -mp, l, bw);
                double dr = fabs(c[q][0] - sgn(m - mp) * c[p][0]);
                double di = fabs(c[q][1] + sgn(m - mp) * c[p][1]);
                if (dr > worst) worst = dr;
                if (di > worst) worst = di;
            }
    return worst;
}

/* The plan a SOFT client makes on its workspaces: batched 2-D FFTs over the beta slices. */
static inline fftw_plan client_plan(int bw, fftw_complex *in, fftw_complex *out, int sign) {
    int n[2];
    n[0] = 2 * bw;
    n[1] = 2 * bw;
    return fftw_plan_many_dft(2, n, 2 * bw, in, NULL, 1, 4 * bw * bw, out, NULL, 1,
                              4 * bw * bw, sign, FFTW_ESTIMATE);
}

#endif /* SO3FFT_SOFT_TEST_UTIL_H */
