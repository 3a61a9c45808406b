/* bench_soft_registration: one rotational correlation of two real functions on the sphere,
 * timed as a SOFT 2.0 registration client runs it (scan registration codes such as
 * fsregistration or TAMS), against the native so3fft real pipeline doing the same work.
 *
 *   make bench_soft_registration          (CMake target, EXCLUDE_FROM_ALL)
 *   ./bench_soft_registration [-r REPS] [bw ...]        (default bw 16 32 64 128)
 *
 * The client half uses SOFT's API only, the way such clients are written: real data in
 * SOFT's split complex arrays (imaginary parts all 0), SOFT's tables (SemiNaive_Naive_Pml_Table,
 * makeweights) and the client's own FFTW plans and workspaces, made once; then per
 * correlation two FST_semi_memo (dataformat 0), so3CombineCoef_fftw (degLim bw - 1),
 * Inverse_SO3_Naive_fftw with flag 0 (complex) and the client's own copy of the real parts
 * of the SO(3) grid into its array, followed by an argmax there. The native half is
 * so3fft_correlate_real_argmax on the same real samples (plan made once with SO3FFT_REAL |
 * SO3FFT_MEASURE): the grid and its argmax, taken while the grid is computed.
 *
 * Each repetition runs both, alternating which goes first; a first call of each is made and
 * discarded before timing (the SOFT layer plans on it). Printed per bandwidth: medians of
 * the wall times over the repetitions (default 31 below bw 64, 11 at 64, 7 above), their
 * ratio (SOFT-API client / native), and the grid point both found.
 *
 * The signal is the pattern (a random band-limited real function, evaluated directly, no
 * library involved) rotated by a rotation of the grid, so the maximum of the correlation is
 * known: every call of either half must find exactly that grid point, else the program
 * exits with status 1.
 *
 * Environment: SO3FFT_SOFT_THREADS=n sets the threads of the SOFT layer's cached plans
 * (default all cores) and is also given to the native plan, so both run with the same
 * threads; SO3FFT_ISA=avx2|avx512|scalar picks the kernels of both.
 *
 * The client half uses nothing but SOFT 2.0's API: compiled with -DBENCH_SOFT_CLIENT_ONLY
 * the native half is left out, and the program builds against any library with SOFT's
 * headers and functions (so the same client can be timed on another SOFT implementation). */
#define _POSIX_C_SOURCE 200112L

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include <fftw3.h>

#include "makeweights.h"
#include "s2_cospmls.h"
#include "s2_semi_memo.h"
#include "so3_correlate_fftw.h"
#include "soft_fftw.h"
#include "utils_so3.h"

#ifndef BENCH_SOFT_CLIENT_ONLY
#include "so3fft.h"
#endif

#define MAX_REPS 101

static const double PI_ = 3.14159265358979323846;

static double now(void) {
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static int cmp(const void *a, const void *b) {
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

static double median(double *t, int n) {
    qsort(t, (size_t)n, sizeof(double), cmp);
    return n % 2 ? t[n / 2] : 0.5 * (t[n / 2 - 1] + t[n / 2]);
}

static void *xmalloc(size_t bytes) {
    void *p = fftw_malloc(bytes);
    if (!p) {
        fprintf(stderr, "bench_soft_registration: out of memory (%lu bytes)\n",
                (unsigned long)bytes);
        exit(EXIT_FAILURE);
    }
    return p;
}

static double rnd(unsigned long long *s) {
    *s = *s * 6364136223846793005ULL + 1442695040888963407ULL;
    return (double)(*s >> 11) / 9007199254740992.0 - 0.5;
}

/* ----------------------------------------------------------------------------------------
 * The test functions: h(x) = sum_{l < bw, 0 <= m <= l} P_l^m(cos theta) (a cos m phi +
 * b sin m phi) with orthonormal associated Legendre functions and random a, b (b = 0 for
 * m = 0): a real function of bandwidth bw, evaluated at any point by the recurrences.
 * ---------------------------------------------------------------------------------------- */
typedef struct {
    int bw;
    double *a, *b;     /* coefficients, index m * bw + l */
    double *ra, *rb;   /* recurrence: P_l = ra (z P_{l-1} - rb P_{l-2}) */
    double *mm;        /* sqrt((2m+1)/(2m)) */
} bandlimited;

static void bl_init(bandlimited *f, int bw, unsigned long long seed) {
    int m, l;
    size_t n = (size_t)bw * (size_t)bw;
    f->bw = bw;
    f->a = (double *)xmalloc(n * sizeof(double));
    f->b = (double *)xmalloc(n * sizeof(double));
    f->ra = (double *)xmalloc(n * sizeof(double));
    f->rb = (double *)xmalloc(n * sizeof(double));
    f->mm = (double *)xmalloc((size_t)bw * sizeof(double));
    for (m = 0; m < bw; m++) {
        f->mm[m] = m > 0 ? sqrt((2.0 * m + 1.0) / (2.0 * m)) : 0.0;
        for (l = 0; l < bw; l++) {
            size_t i = (size_t)m * bw + l;
            double L = l, M = m;
            f->a[i] = l >= m ? rnd(&seed) : 0.0;
            f->b[i] = l >= m && m > 0 ? rnd(&seed) : 0.0;
            f->ra[i] = l > m ? sqrt((4.0 * L * L - 1.0) / (L * L - M * M)) : 0.0;
            f->rb[i] = l > m + 1 ? sqrt(((L - 1.0) * (L - 1.0) - M * M) /
                                        (4.0 * (L - 1.0) * (L - 1.0) - 1.0))
                                 : 0.0;
        }
    }
}

static void bl_free(bandlimited *f) {
    fftw_free(f->a);
    fftw_free(f->b);
    fftw_free(f->ra);
    fftw_free(f->rb);
    fftw_free(f->mm);
}

/* h at the unit vector (x, y, z). */
static double bl_eval(const bandlimited *f, double x, double y, double z) {
    int bw = f->bw, m, l;
    double s = sqrt(fmax(0.0, 1.0 - z * z)), phi = atan2(y, x);
    double pmm = 1.0 / sqrt(4.0 * PI_), val = 0.0;
    for (m = 0; m < bw; m++) {
        const double *a = f->a + (size_t)m * bw, *b = f->b + (size_t)m * bw;
        const double *ra = f->ra + (size_t)m * bw, *rb = f->rb + (size_t)m * bw;
        double p2, p1, sa, sb;
        if (m > 0) pmm *= f->mm[m] * s;
        if (fabs(pmm) < 1e-250) break; /* the orders left add less than 1e-100 */
        p1 = pmm;
        sa = a[m] * p1;
        sb = b[m] * p1;
        p2 = 0.0;
        for (l = m + 1; l < bw; l++) {
            double p = ra[l] * (z * p1 - rb[l] * p2);
            p2 = p1;
            p1 = p;
            sa += a[l] * p;
            sb += b[l] * p;
        }
        val += sa * cos(m * phi) + sb * sin(m * phi);
    }
    return val;
}

/* Samples of h(g^-1 x) on the S^2 grid of bandwidth bw (theta_j = pi (2j+1)/(4bw),
 * phi_k = pi k / bw, at j 2bw + k), g = Rz(alpha) Ry(beta) Rz(gamma). */
static void sample_rotated(const bandlimited *f, double alpha, double beta, double gamma,
                           double *out) {
    int n = 2 * f->bw, j, k, r, c;
    double ca = cos(alpha), sa = sin(alpha), cb = cos(beta), sb = sin(beta);
    double cg = cos(gamma), sg = sin(gamma), g[3][3];
    double rz1[3][3], ry[3][3], rz2[3][3], t[3][3];
    memset(rz1, 0, sizeof rz1);
    memset(ry, 0, sizeof ry);
    memset(rz2, 0, sizeof rz2);
    rz1[0][0] = ca; rz1[0][1] = -sa; rz1[1][0] = sa; rz1[1][1] = ca; rz1[2][2] = 1.0;
    ry[0][0] = cb; ry[0][2] = sb; ry[1][1] = 1.0; ry[2][0] = -sb; ry[2][2] = cb;
    rz2[0][0] = cg; rz2[0][1] = -sg; rz2[1][0] = sg; rz2[1][1] = cg; rz2[2][2] = 1.0;
    for (r = 0; r < 3; r++)
        for (c = 0; c < 3; c++)
            t[r][c] = ry[r][0] * rz2[0][c] + ry[r][1] * rz2[1][c] + ry[r][2] * rz2[2][c];
    for (r = 0; r < 3; r++)
        for (c = 0; c < 3; c++)
            g[r][c] = rz1[r][0] * t[0][c] + rz1[r][1] * t[1][c] + rz1[r][2] * t[2][c];
    for (j = 0; j < n; j++) {
        double th = PI_ * (2 * j + 1) / (2.0 * n);
        for (k = 0; k < n; k++) {
            double ph = PI_ * k / (0.5 * n);
            double x = sin(th) * cos(ph), y = sin(th) * sin(ph), z = cos(th);
            /* g^-1 x = g^T x */
            double u = g[0][0] * x + g[1][0] * y + g[2][0] * z;
            double v = g[0][1] * x + g[1][1] * y + g[2][1] * z;
            double w = g[0][2] * x + g[1][2] * y + g[2][2] * z;
            out[j * n + k] = bl_eval(f, u, v, w);
        }
    }
}

/* ----------------------------------------------------------------------------------------
 * The SOFT client: its arrays, tables and FFTW plans, and one correlation.
 * ---------------------------------------------------------------------------------------- */
typedef struct {
    int bw;
    long ng;
    double *sigR, *sigI, *patR, *patI;          /* S^2 samples, (2bw)^2 each */
    double *sigCoefR, *sigCoefI, *patCoefR, *patCoefI; /* bw^2 each */
    double *weights, *s2ws, *tablespace, *tablews, **table;
    fftw_complex *so3Coef, *so3Sig, *ws1, *ws2;
    double *ws3;
    double *grid;                               /* the client's copy of the result */
    fftw_plan dct, fft, p1;
} client;

static void client_init(client *c, int bw) {
    int n = 2 * bw;
    long ng = 8L * bw * bw * bw;
    size_t s2 = (size_t)n * n, nc = (size_t)totalCoeffs_so3(bw);
    int na[2], inembed[2], onembed[2];
    fftw_iodim dims[1], howmany[1];
    memset(c, 0, sizeof *c);
    c->bw = bw;
    c->ng = ng;
    c->sigR = (double *)xmalloc(s2 * sizeof(double));
    c->sigI = (double *)xmalloc(s2 * sizeof(double));
    c->patR = (double *)xmalloc(s2 * sizeof(double));
    c->patI = (double *)xmalloc(s2 * sizeof(double));
    c->sigCoefR = (double *)xmalloc((size_t)bw * bw * sizeof(double));
    c->sigCoefI = (double *)xmalloc((size_t)bw * bw * sizeof(double));
    c->patCoefR = (double *)xmalloc((size_t)bw * bw * sizeof(double));
    c->patCoefI = (double *)xmalloc((size_t)bw * bw * sizeof(double));
    c->weights = (double *)xmalloc((size_t)(4 * bw) * sizeof(double));
    c->s2ws = (double *)xmalloc((size_t)(8 * bw * bw + 10 * bw) * sizeof(double));
    c->tablespace = (double *)xmalloc(
        (size_t)(Reduced_Naive_TableSize(bw, bw) + Reduced_SpharmonicTableSize(bw, bw)) *
        sizeof(double));
    c->tablews = (double *)xmalloc((size_t)(16 * bw) * sizeof(double));
    c->so3Coef = (fftw_complex *)xmalloc(nc * sizeof(fftw_complex));
    c->so3Sig = (fftw_complex *)xmalloc((size_t)ng * sizeof(fftw_complex));
    c->ws1 = (fftw_complex *)xmalloc((size_t)ng * sizeof(fftw_complex));
    c->ws2 = (fftw_complex *)xmalloc((size_t)n * sizeof(fftw_complex));
    c->ws3 = (double *)xmalloc((size_t)(12 * n + n * bw) * sizeof(double));
    c->grid = (double *)xmalloc((size_t)ng * sizeof(double));

    /* SOFT's tables and the client's FFTW plans (FFTW_ESTIMATE, as SOFT's manual asks) */
    makeweights(bw, c->weights);
    c->table = SemiNaive_Naive_Pml_Table(bw, bw, c->tablespace, c->tablews);
    c->dct = fftw_plan_r2r_1d(n, c->weights, c->tablews, FFTW_REDFT10, FFTW_ESTIMATE);
    dims[0].n = n;
    dims[0].is = 1;
    dims[0].os = n;
    howmany[0].n = n;
    howmany[0].is = n;
    howmany[0].os = 1;
    c->fft = fftw_plan_guru_split_dft(1, dims, 1, howmany, c->sigR, c->sigI, c->s2ws,
                                      c->s2ws + (size_t)n * n, FFTW_ESTIMATE);
    /* the inverse SO(3) transform's plan: n^2 FFTs of length n from ws1 into so3Sig */
    na[0] = 1;
    na[1] = n;
    inembed[0] = onembed[0] = n;
    inembed[1] = onembed[1] = n * n;
    c->p1 = fftw_plan_many_dft(2, na, n * n, c->ws1, inembed, 1, n, c->so3Sig, onembed, 1, n,
                               FFTW_FORWARD, FFTW_ESTIMATE);
    if (!c->table || !c->dct || !c->fft || !c->p1) {
        fprintf(stderr, "bench_soft_registration: SOFT tables or FFTW plans failed\n");
        exit(EXIT_FAILURE);
    }
}

static void client_free(client *c) {
    fftw_destroy_plan(c->dct);
    fftw_destroy_plan(c->fft);
    fftw_destroy_plan(c->p1);
    free(c->table);
    fftw_free(c->sigR);
    fftw_free(c->sigI);
    fftw_free(c->patR);
    fftw_free(c->patI);
    fftw_free(c->sigCoefR);
    fftw_free(c->sigCoefI);
    fftw_free(c->patCoefR);
    fftw_free(c->patCoefI);
    fftw_free(c->weights);
    fftw_free(c->s2ws);
    fftw_free(c->tablespace);
    fftw_free(c->tablews);
    fftw_free(c->so3Coef);
    fftw_free(c->so3Sig);
    fftw_free(c->ws1);
    fftw_free(c->ws2);
    fftw_free(c->ws3);
    fftw_free(c->grid);
}

/* One correlation as the client runs it; returns the grid index of the maximum. */
static long client_correlate(client *c) {
    int bw = c->bw;
    long i, at = 0;
    double best;
    FST_semi_memo(c->sigR, c->sigI, c->sigCoefR, c->sigCoefI, bw, c->table, c->s2ws, 0, bw,
                  &c->dct, &c->fft, c->weights);
    FST_semi_memo(c->patR, c->patI, c->patCoefR, c->patCoefI, bw, c->table, c->s2ws, 0, bw,
                  &c->dct, &c->fft, c->weights);
    so3CombineCoef_fftw(bw, bw, bw - 1, c->sigCoefR, c->sigCoefI, c->patCoefR, c->patCoefI,
                        c->so3Coef);
    Inverse_SO3_Naive_fftw(bw, c->so3Coef, c->so3Sig, c->ws1, c->ws2, c->ws3, &c->p1, 0);
    /* the client's copy of the (real) correlation, then its argmax */
    for (i = 0; i < c->ng; i++) c->grid[i] = c->so3Sig[i][0];
    best = c->grid[0];
    for (i = 1; i < c->ng; i++)
        if (c->grid[i] > best) {
            best = c->grid[i];
            at = i;
        }
    return at;
}

#ifndef BENCH_SOFT_CLIENT_ONLY
/* One correlation through the native real pipeline; returns the grid index of the maximum. */
static long native_correlate(so3fft_correlation p, int bw, const double *sig, const double *pat,
                             double *out) {
    ptrdiff_t at = so3fft_correlate_real_argmax(p, sig, pat, out, NULL);
    (void)bw;
    if (at < 0) {
        fprintf(stderr, "bench_soft_registration: so3fft_correlate_real_argmax: %s\n",
                so3fft_last_error());
        exit(EXIT_FAILURE);
    }
    return (long)at;
}
#endif

static int check(const char *who, int bw, long at, long want) {
    long n = 2L * bw;
    if (at == want) return 0;
    fprintf(stderr, "bw %d: %s found grid point (%ld, %ld, %ld), planted (%ld, %ld, %ld)\n", bw,
            who, at / (n * n), (at / n) % n, at % n, want / (n * n), (want / n) % n, want % n);
    return 1;
}

int main(int argc, char **argv) {
    int defaults[4] = {16, 32, 64, 128}, reps_arg = 0, first = 1, nb, ib, failures = 0;
    const char *env = getenv("SO3FFT_SOFT_THREADS");
    int threads = env ? atoi(env) : 0;
    if (argc > 2 && strcmp(argv[1], "-r") == 0) {
        reps_arg = atoi(argv[2]);
        if (reps_arg < 1 || reps_arg > MAX_REPS) {
            fprintf(stderr, "bench_soft_registration: -r takes 1..%d\n", MAX_REPS);
            return 2;
        }
        first = 3;
    }
    nb = argc > first ? argc - first : 4;
    printf("one correlation of two real functions, steady state, median wall time\n");
#ifndef BENCH_SOFT_CLIENT_ONLY
    printf("%5s %5s %16s %16s %8s  %s\n", "bw", "reps", "SOFT client ms", "native real ms",
           "ratio", "grid max (beta, alpha, gamma)");
#else
    printf("%5s %5s %16s  %s\n", "bw", "reps", "SOFT client ms", "grid max (beta, alpha, gamma)");
#endif
    for (ib = 0; ib < nb; ib++) {
        int bw = argc > first ? atoi(argv[first + ib]) : defaults[ib];
        int n = 2 * bw, reps, r, ii, jj, kk;
        long want, at;
        double tc[MAX_REPS], t0, first_client;
        bandlimited h;
        client c;
#ifndef BENCH_SOFT_CLIENT_ONLY
        double tn[MAX_REPS], first_native, *out;
        so3fft_correlation plan;
#endif
        if (bw < 2 || bw > 512) {
            fprintf(stderr, "bench_soft_registration: bandwidth %d outside 2..512\n", bw);
            return 2;
        }
        reps = reps_arg ? reps_arg : bw < 64 ? 31 : bw == 64 ? 11 : 7;
        /* the planted rotation, a grid point away from the poles and from 0 */
        ii = (3 * n) / 10;
        jj = (7 * n) / 11;
        kk = (2 * n) / 9 + 1;
        want = ((long)ii * n + jj) * n + kk;

        client_init(&c, bw);
        bl_init(&h, bw, 12345ULL + (unsigned long long)bw);
        sample_rotated(&h, 0.0, 0.0, 0.0, c.patR);
        sample_rotated(&h, PI_ * jj / bw, PI_ * (2 * ii + 1) / (4.0 * bw), PI_ * kk / bw,
                       c.sigR);
        memset(c.sigI, 0, sizeof(double) * (size_t)n * n);
        memset(c.patI, 0, sizeof(double) * (size_t)n * n);
        bl_free(&h);

        /* first calls (plans of the SOFT layer), checked and discarded */
        t0 = now();
        at = client_correlate(&c);
        first_client = now() - t0;
        failures += check("SOFT client", bw, at, want);
#ifndef BENCH_SOFT_CLIENT_ONLY
        plan = so3fft_plan_correlation(bw, 0, -1, SO3FFT_REAL | SO3FFT_MEASURE, threads);
        out = (double *)xmalloc((size_t)c.ng * sizeof(double));
        if (!plan) {
            fprintf(stderr, "bench_soft_registration: so3fft_plan_correlation: %s\n",
                    so3fft_last_error());
            return 1;
        }
        t0 = now();
        at = native_correlate(plan, bw, c.sigR, c.patR, out);
        first_native = now() - t0;
        failures += check("native", bw, at, want);
#endif
        for (r = 0; r < reps; r++) {
#ifndef BENCH_SOFT_CLIENT_ONLY
            int k;
            for (k = 0; k < 2; k++) {
                if ((r + k) % 2 == 0) {
                    t0 = now();
                    at = client_correlate(&c);
                    tc[r] = now() - t0;
                    failures += check("SOFT client", bw, at, want);
                } else {
                    t0 = now();
                    at = native_correlate(plan, bw, c.sigR, c.patR, out);
                    tn[r] = now() - t0;
                    failures += check("native", bw, at, want);
                }
            }
#else
            t0 = now();
            at = client_correlate(&c);
            tc[r] = now() - t0;
            failures += check("SOFT client", bw, at, want);
#endif
        }
#ifndef BENCH_SOFT_CLIENT_ONLY
        {
            double mc = median(tc, reps), mn = median(tn, reps);
            printf("%5d %5d %16.4f %16.4f %8.2f  (%d, %d, %d)   first calls %.1f / %.1f ms\n",
                   bw, reps, 1e3 * mc, 1e3 * mn, mc / mn, ii, jj, kk, 1e3 * first_client,
                   1e3 * first_native);
        }
        so3fft_destroy_correlation(plan);
        fftw_free(out);
#else
        printf("%5d %5d %16.4f  (%d, %d, %d)   first call %.1f ms\n", bw, reps,
               1e3 * median(tc, reps), ii, jj, kk, 1e3 * first_client);
#endif
        fflush(stdout);
        client_free(&c);
    }
    (void)threads;
    if (failures) {
        fprintf(stderr, "bench_soft_registration: %d correlation(s) missed the planted maximum\n",
                failures);
        return 1;
    }
    return 0;
}
