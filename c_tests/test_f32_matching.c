/* The single-precision matching C API (so3fftf_correlation ...) against the double one on the
 * same data (the float samples widened to double):
 *  - the reference correlations of tests/data/s2 (signals that are their pattern rotated by a
 *    grid rotation), complex and real, and random signals on a finer grid with a degree limit,
 *    normalised: the grids agree to float rounding; the grid argmax, the fused argmax and the
 *    top peaks are the same points; refinement from the float plan lands within 1e-8 rad of
 *    the double refinement (it computes in double from the same samples);
 *  - top peaks planted on float grids: exact indices, values and angles;
 *  - bad arguments: the same error codes and messages as the double functions, nothing
 *    written;
 *  - nothing written behind the grids (guard values; valgrind checks the rest).
 * Usage: test_f32_matching <dir with the s2/ reference files>. */
#include "test_util.h"
#include "f32_twins.h"
#include "s2_reference.h"

/* A float grid against the double grid of the widened samples, relative L2. */
static const double AGREE = 1e-6;
/* A refined rotation from the float plan against the double plan's, per angle (radians). */
static const double REFINE = 1e-8;

/* Largest |a - b| over n doubles. */
static double max_diff(const double *a, const double *b, size_t n) {
    double m = 0.0;
    size_t i;
    for (i = 0; i < n; i++)
        if (!(fabs(a[i] - b[i]) <= m)) m = fabs(a[i] - b[i]);
    return m;
}

/* One correlation set-up in both precisions: `ns` samples per input (complex ones as
 * interleaved values), the float samples and the same values in double. */
typedef struct {
    const char *name;
    int L, B_out, deg_lim;
    unsigned flags;
    float *sig, *pat;
    ptrdiff_t expect; /* the grid argmax expected, or -1 */
} matching_case;

/* Number of float or double values of a real (1) or complex (2) array of n entries. */
static size_t values_of(size_t n, int real) { return real ? n : 2 * n; }

/* The correlation of `c` in both precisions: grids, argmax (plain and fused), top peaks and
 * refinement compared; the grid's relative error goes to *worst. */
static void compare(const matching_case *c, double *worst) {
    const int real = (c->flags & SO3FFT_REAL) != 0;
    const int bo = c->B_out ? c->B_out : c->L;
    const size_t ns = values_of(4 * (size_t)c->L * (size_t)c->L, real);
    so3fftf_correlation pf = so3fftf_plan_correlation(c->L, c->B_out, c->deg_lim, c->flags, 2);
    so3fft_correlation pd = so3fft_plan_correlation(c->L, c->B_out, c->deg_lim, c->flags, 2);
    ptrdiff_t n, at, at_d, fused_at, nf, nd, idx_f[4], idx_d[4];
    size_t ng;
    float *grid, *fused;
    double *sig_d = alloc_d(ns), *pat_d = alloc_d(ns), *grid_d;
    double af[3], ad[3], fa[3], e, vf = 0.0, vd = 0.0;
    double pf_angles[12], pd_angles[12], pf_values[4], pd_values[4];
    double mf[12], md[12], mvf[4], mvd[4];
    int k;

    CHECK(pf != NULL && pd != NULL);
    if (!pf || !pd) {
        fprintf(stderr, "%s: %s\n", c->name, so3fft_last_error());
        return;
    }
    n = so3fftf_correlation_grid_size(pf);
    CHECK(n == so3fft_correlation_grid_size(pd) && n == 8 * (ptrdiff_t)bo * bo * bo);
    CHECK_NO_ERR();
    ng = values_of((size_t)n, real);
    grid = alloc_f(ng), fused = alloc_f(ng), grid_d = alloc_d(ng);
    widen(c->sig, sig_d, ns);
    widen(c->pat, pat_d, ns);

    /* the grid, and its largest |C|^2 */
    if (real) {
        CHECK(so3fftf_correlate_real(pf, c->sig, c->pat, grid) == SO3FFT_OK);
        CHECK(so3fft_correlate_real(pd, sig_d, pat_d, grid_d) == SO3FFT_OK);
        at = so3fftf_grid_argmax_real(bo, grid, af);
        at_d = so3fft_grid_argmax_real(bo, grid_d, ad);
        fused_at = so3fftf_correlate_real_argmax(pf, c->sig, c->pat, fused, fa);
    } else {
        so3fftf_complex *s = (so3fftf_complex *)(void *)c->sig;
        so3fftf_complex *h = (so3fftf_complex *)(void *)c->pat;
        so3fftf_complex *g = (so3fftf_complex *)(void *)grid;
        CHECK(so3fftf_correlate(pf, s, h, g) == SO3FFT_OK);
        CHECK(so3fft_correlate(pd, (so3fft_complex *)(void *)sig_d,
                               (so3fft_complex *)(void *)pat_d,
                               (so3fft_complex *)(void *)grid_d) == SO3FFT_OK);
        at = so3fftf_grid_argmax(bo, g, af);
        at_d = so3fft_grid_argmax(bo, (so3fft_complex *)(void *)grid_d, ad);
        fused_at = so3fftf_correlate_argmax(pf, s, h, (so3fftf_complex *)(void *)fused, fa);
    }
    CHECK_NO_ERR();
    e = rel_f_d(grid, grid_d, ng);
    if (!(e < AGREE)) {
        fprintf(stderr, "%s: grid against f64: relative error %.3g (limit %.1g)\n", c->name, e,
                AGREE);
        g_failures++;
    }
    if (!(e <= *worst)) *worst = e;
    CHECK(at >= 0 && at == at_d && memcmp(af, ad, sizeof af) == 0);
    if (c->expect >= 0) CHECK(at == c->expect);
    /* the argmax found while the grid is computed: the same point and grid */
    CHECK(fused_at == at && memcmp(fa, af, sizeof af) == 0);
    CHECK(memcmp(fused, grid, ng * sizeof(float)) == 0);

    /* the top peaks of the float grid: those of the double grid (values to float rounding) */
    if (real) {
        nf = so3fftf_grid_top_peaks_real(bo, grid, 4, 0.3, pf_angles, pf_values, idx_f);
        nd = so3fft_grid_top_peaks_real(bo, grid_d, 4, 0.3, pd_angles, pd_values, idx_d);
    } else {
        nf = so3fftf_grid_top_peaks(bo, (so3fftf_complex *)(void *)grid, 4, 0.3, pf_angles,
                                    pf_values, idx_f);
        nd = so3fft_grid_top_peaks(bo, (so3fft_complex *)(void *)grid_d, 4, 0.3, pd_angles,
                                   pd_values, idx_d);
    }
    CHECK_NO_ERR();
    CHECK(nf >= 1 && nf == nd);
    if (nf >= 1 && nf == nd) {
        CHECK(memcmp(idx_f, idx_d, (size_t)nf * sizeof idx_f[0]) == 0);
        CHECK(memcmp(pf_angles, pd_angles, 3 * (size_t)nf * sizeof pf_angles[0]) == 0);
        CHECK(idx_f[0] == at);
        for (k = 0; k < nf; k++) CHECK(fabs(pf_values[k] - pd_values[k]) <= 1e-5 * pd_values[0]);
    }

    /* refinement: from the grid peak, and all top peaks at once */
    CHECK(so3fftf_correlation_refine(pf, c->sig, c->pat, af, &vf) == SO3FFT_OK);
    CHECK(so3fft_correlation_refine(pd, sig_d, pat_d, ad, &vd) == SO3FFT_OK);
    CHECK_NO_ERR();
    CHECK(max_diff(af, ad, 3) < REFINE);
    CHECK(vf > 0.0 && fabs(vf - vd) <= 1e-10 * vd);
    if (nf >= 1 && nf == nd) {
        memcpy(mf, pf_angles, 3 * (size_t)nf * sizeof mf[0]);
        memcpy(md, pd_angles, 3 * (size_t)nf * sizeof md[0]);
        /* beside the peak: both refinements move */
        mf[0] += 0.02, mf[1] -= 0.01, mf[2] += 0.015;
        md[0] += 0.02, md[1] -= 0.01, md[2] += 0.015;
        CHECK(so3fftf_correlation_refine_many(pf, c->sig, c->pat, (size_t)nf, mf, mvf) ==
              SO3FFT_OK);
        CHECK(so3fft_correlation_refine_many(pd, sig_d, pat_d, (size_t)nf, md, mvd) ==
              SO3FFT_OK);
        CHECK_NO_ERR();
        CHECK(max_diff(mf, md, 3 * (size_t)nf) < REFINE);
        for (k = 0; k < nf; k++) CHECK(fabs(mvf[k] - mvd[k]) <= 1e-10 * mvd[0]);
        /* the first start reaches the single refinement's peak */
        CHECK(max_diff(mf, af, 3) < 1e-7);
    }

    CHECK(untouched_f(grid + ng, GUARD) && untouched_f(fused + ng, GUARD));
    so3fftf_destroy_correlation(pf);
    so3fft_destroy_correlation(pd);
    CHECK_NO_ERR();
    free(grid), free(fused), free(grid_d), free(sig_d), free(pat_d);
}

/* The reference correlations (the signal a grid rotation of the pattern), rounded to float. */
static void reference_cases(const char *dir, double *worst) {
    static const char *files[] = {"cor_B8_complex.txt", "cor_B8_real.txt", "cor_B16_complex.txt",
                                  "cor_B16_real.txt"};
    size_t i, j;
    for (i = 0; i < sizeof files / sizeof files[0]; i++) {
        cor_case r;
        matching_case c;
        size_t ns;
        if (read_case(dir, files[i], &r) != 0) {
            fprintf(stderr, "%s: unreadable\n", files[i]);
            g_failures++;
            continue;
        }
        ns = 4 * (size_t)r.bw * (size_t)r.bw;
        memset(&c, 0, sizeof c);
        c.name = files[i];
        c.L = r.bw;
        c.deg_lim = -1;
        c.flags = r.is_real ? SO3FFT_REAL : 0;
        c.sig = alloc_f(2 * ns), c.pat = alloc_f(2 * ns);
        /* real samples: the real parts */
        for (j = 0; j < values_of(ns, r.is_real); j++) {
            c.sig[j] = (float)r.sig[r.is_real ? 2 * j : j];
            c.pat[j] = (float)r.pat[r.is_real ? 2 * j : j];
        }
        c.expect = (ptrdiff_t)r.ii * 4 * r.bw * r.bw + (ptrdiff_t)r.jj * 2 * r.bw + r.kk;
        compare(&c, worst);
        free(c.sig), free(c.pat), free(r.sig), free(r.pat);
    }
}

/* Random signal and pattern: a finer grid, a degree limit, normalised. */
static void random_cases(double *worst) {
    const int L = 8;
    const size_t ns = 4 * (size_t)L * (size_t)L;
    int real;
    for (real = 0; real < 2; real++) {
        matching_case c;
        unsigned long long seed = 77 + (unsigned long long)real;
        size_t j;
        memset(&c, 0, sizeof c);
        c.name = real ? "random real" : "random complex";
        c.L = L;
        c.B_out = 12;
        c.deg_lim = 5;
        c.flags = SO3FFT_NORMALIZED | (real ? SO3FFT_REAL : 0);
        c.sig = alloc_f(2 * ns), c.pat = alloc_f(2 * ns);
        for (j = 0; j < 2 * ns; j++) {
            c.sig[j] = (float)rnd(&seed);
            c.pat[j] = (float)rnd(&seed);
        }
        c.expect = -1;
        compare(&c, worst);
        free(c.sig), free(c.pat);
    }
}

/* Top peaks planted on a flat float grid (test_matching.c's): a larger value beside the
 * first makes that point no maximum; exact indices, values and angles, as in double. */
static void planted_peaks(void) {
    const int B = 4, n = 2 * B;
    const size_t total = (size_t)n * n * n;
    const size_t first = (size_t)(1 * n + 2) * n + 3, second = (size_t)(6 * n + 5) * n + 1;
    const size_t beside = (size_t)(1 * n + 3) * n + 3;
    const double pi = 3.14159265358979323846;
    so3fftf_complex *cg = (so3fftf_complex *)malloc(total * sizeof(so3fftf_complex));
    float *rg = alloc_f(total);
    size_t i;
    int real;
    if (!cg) exit(EXIT_FAILURE);
    for (i = 0; i < total; i++) {
        cg[i][0] = 0.1f;
        cg[i][1] = 0.0f;
        rg[i] = -0.1f;
    }
    cg[first][0] = 0.0f;
    cg[first][1] = 5.0f;
    rg[first] = -5.0f;
    cg[second][0] = 4.0f;
    rg[second] = 4.0f;
    cg[beside][0] = 3.0f;
    rg[beside] = 3.0f;
    for (real = 0; real < 2; real++) {
        double angles[6], values[2], a[3];
        ptrdiff_t idx[2];
        ptrdiff_t got = real ? so3fftf_grid_top_peaks_real(B, rg, 2, 0.1, angles, values, idx)
                             : so3fftf_grid_top_peaks(B, cg, 2, 0.1, angles, values, idx);
        CHECK_NO_ERR();
        CHECK(got == 2);
        CHECK(idx[0] == (ptrdiff_t)first && idx[1] == (ptrdiff_t)second);
        CHECK(values[0] == 25.0 && values[1] == 16.0);
        CHECK(fabs(angles[0] - 2 * pi / B) < 1e-15 && fabs(angles[1] - pi * 3 / (4 * B)) < 1e-15 &&
              fabs(angles[2] - 3 * pi / B) < 1e-15);
        /* the argmax is the first peak */
        CHECK((real ? so3fftf_grid_argmax_real(B, rg, a) : so3fftf_grid_argmax(B, cg, a)) ==
              (ptrdiff_t)first);
        CHECK(memcmp(a, angles, sizeof a) == 0);
        /* NULL for the optional outputs and the angles of the argmax, k = 0 */
        CHECK(so3fftf_grid_top_peaks(B, cg, 1, 0.0, angles, NULL, NULL) == 1);
        CHECK(so3fftf_grid_top_peaks_real(B, rg, 0, 0.0, angles, NULL, NULL) == 0);
        CHECK(so3fftf_grid_argmax_real(B, rg, NULL) == (ptrdiff_t)first);
        CHECK_NO_ERR();
    }
    free(cg), free(rg);
}

/* Compares an f32 correlation planner with its f64 twin: both NULL, the same code and
 * message. */
#define SAME_PLAN_FAILURE(code, fcall, dcall)                                               \
    SAME_NULL(code, so3fftf_correlation, fcall, so3fftf_destroy_correlation,                \
              so3fft_correlation, dcall, so3fft_destroy_correlation, 1)

/* Bad arguments: the same codes and messages in both precisions, nothing written. */
static void bad_arguments(void) {
    const int L = 4, B = 4;
    const size_t ns = 4 * (size_t)L * (size_t)L, ng = 8 * (size_t)B * B * B;
    so3fftf_correlation pf, pfr;
    so3fft_correlation pd, pdr;
    so3fftf_complex *s = (so3fftf_complex *)(void *)alloc_f(2 * ns);
    so3fftf_complex *g = (so3fftf_complex *)(void *)alloc_f(2 * ng + 2);
    float *r = alloc_f(ns), *rg = alloc_f(ng);
    so3fft_complex *sd = alloc_cx(ns), *gd = alloc_cx(ng + 1);
    double *rd = alloc_d(ns), *rgd = alloc_d(ng);
    char *raw = (char *)malloc((ng + 1) * sizeof(so3fft_complex));
    double a[6] = {0.1, 0.2, 0.3, 0.4, 0.5, 0.6}, ad[6], v[2], vd[2];
    ptrdiff_t idx[2], idxd[2];
    const size_t huge = (size_t)-1;
    size_t i;
    unsigned long long seed = 5;
    if (!raw) exit(EXIT_FAILURE);
    for (i = 0; i < 2 * ns; i++) (&s[0][0])[i] = (float)rnd(&seed);
    for (i = 0; i < ns; i++) r[i] = s[i][0];
    widen(&s[0][0], &sd[0][0], 2 * ns);
    widen(r, rd, ns);
    memcpy(ad, a, sizeof a);

    /* planners: bandwidths, degree limit, flags, threads */
    SAME_PLAN_FAILURE(SO3FFT_EBANDWIDTH, so3fftf_plan_correlation(0, 0, -1, 0, 1),
                      so3fft_plan_correlation(0, 0, -1, 0, 1));
    SAME_PLAN_FAILURE(SO3FFT_EBANDWIDTH,
                      so3fftf_plan_correlation(SO3FFT_MAX_BANDWIDTH + 1, 0, -1, 0, 1),
                      so3fft_plan_correlation(SO3FFT_MAX_BANDWIDTH + 1, 0, -1, 0, 1));
    SAME_PLAN_FAILURE(SO3FFT_EBANDWIDTH, so3fftf_plan_correlation(8, -3, -1, 0, 1),
                      so3fft_plan_correlation(8, -3, -1, 0, 1));
    SAME_PLAN_FAILURE(SO3FFT_EINVAL, so3fftf_plan_correlation(8, 0, -2, 0, 1),
                      so3fft_plan_correlation(8, 0, -2, 0, 1));
    SAME_PLAN_FAILURE(SO3FFT_EINVAL, so3fftf_plan_correlation(8, 4, 7, 0, 1),
                      so3fft_plan_correlation(8, 4, 7, 0, 1));
    SAME_PLAN_FAILURE(SO3FFT_EINVAL, so3fftf_plan_correlation(8, 0, -1, SO3FFT_DESTROY_INPUT, 1),
                      so3fft_plan_correlation(8, 0, -1, SO3FFT_DESTROY_INPUT, 1));
    SAME_PLAN_FAILURE(SO3FFT_EINVAL, so3fftf_plan_correlation(8, 0, -1, 1u << 20, 1),
                      so3fft_plan_correlation(8, 0, -1, 1u << 20, 1));
    SAME_PLAN_FAILURE(SO3FFT_EINVAL, so3fftf_plan_correlation(8, 0, -1, 0, -1),
                      so3fft_plan_correlation(8, 0, -1, 0, -1));

    /* NULL plan */
    so3fftf_destroy_correlation(NULL);
    CHECK_NO_ERR();
    SAME_CODE(SO3FFT_ENULL, so3fftf_correlation_grid_size(NULL),
              so3fft_correlation_grid_size(NULL));
    SAME_CODE(SO3FFT_ENULL, so3fftf_correlate(NULL, s, s + 1, g),
              so3fft_correlate(NULL, sd, sd + 1, gd));
    SAME_CODE(SO3FFT_ENULL, so3fftf_correlate_real(NULL, r, r, rg),
              so3fft_correlate_real(NULL, rd, rd, rgd));
    SAME_FAILURE(-1, SO3FFT_ENULL, so3fftf_correlate_argmax(NULL, s, s, g, a),
                 so3fft_correlate_argmax(NULL, sd, sd, gd, ad));
    SAME_FAILURE(-1, SO3FFT_ENULL, so3fftf_correlate_real_argmax(NULL, r, r, rg, NULL),
                 so3fft_correlate_real_argmax(NULL, rd, rd, rgd, NULL));
    SAME_CODE(SO3FFT_ENULL, so3fftf_correlation_refine(NULL, r, r, a, v),
              so3fft_correlation_refine(NULL, rd, rd, ad, vd));
    SAME_CODE(SO3FFT_ENULL, so3fftf_correlation_refine_many(NULL, r, r, 2, a, v),
              so3fft_correlation_refine_many(NULL, rd, rd, 2, ad, vd));
    CHECK(memcmp(a, ad, sizeof a) == 0);

    pf = so3fftf_plan_correlation(L, B, -1, 0, 1), pd = so3fft_plan_correlation(L, B, -1, 0, 1);
    pfr = so3fftf_plan_correlation(L, B, -1, SO3FFT_REAL, 1);
    pdr = so3fft_plan_correlation(L, B, -1, SO3FFT_REAL, 1);
    CHECK(pf && pd && pfr && pdr);
    if (!(pf && pd && pfr && pdr)) return;
    fill_sentinel_f(&g[0][0], 2 * ng + 2);
    fill_sentinel_f(rg, ng);

    /* NULL arrays */
    SAME_CODE(SO3FFT_ENULL, so3fftf_correlate(pf, NULL, s, g), so3fft_correlate(pd, NULL, sd, gd));
    SAME_CODE(SO3FFT_ENULL, so3fftf_correlate(pf, s, NULL, g), so3fft_correlate(pd, sd, NULL, gd));
    SAME_CODE(SO3FFT_ENULL, so3fftf_correlate(pf, s, s, NULL), so3fft_correlate(pd, sd, sd, NULL));
    SAME_CODE(SO3FFT_ENULL, so3fftf_correlate_real(pfr, NULL, r, rg),
              so3fft_correlate_real(pdr, NULL, rd, rgd));
    SAME_CODE(SO3FFT_ENULL, so3fftf_correlate_real(pfr, r, r, NULL),
              so3fft_correlate_real(pdr, rd, rd, NULL));
    SAME_FAILURE(-1, SO3FFT_ENULL, so3fftf_correlate_argmax(pf, s, NULL, g, a),
                 so3fft_correlate_argmax(pd, sd, NULL, gd, ad));
    SAME_FAILURE(-1, SO3FFT_ENULL, so3fftf_correlate_real_argmax(pfr, r, r, NULL, a),
                 so3fft_correlate_real_argmax(pdr, rd, rd, NULL, ad));
    SAME_CODE(SO3FFT_ENULL, so3fftf_correlation_refine(pfr, NULL, r, a, v),
              so3fft_correlation_refine(pdr, NULL, rd, ad, vd));
    SAME_CODE(SO3FFT_ENULL, so3fftf_correlation_refine(pf, &s[0][0], NULL, a, v),
              so3fft_correlation_refine(pd, &sd[0][0], NULL, ad, vd));
    SAME_CODE(SO3FFT_ENULL, so3fftf_correlation_refine(pfr, r, r, NULL, v),
              so3fft_correlation_refine(pdr, rd, rd, NULL, vd));

    /* the plan's kind of samples */
    SAME_CODE(SO3FFT_EINVAL, so3fftf_correlate_real(pf, r, r, rg),
              so3fft_correlate_real(pd, rd, rd, rgd));
    SAME_CODE(SO3FFT_EINVAL, so3fftf_correlate(pfr, s, s, g), so3fft_correlate(pdr, sd, sd, gd));
    SAME_FAILURE(-1, SO3FFT_EINVAL, so3fftf_correlate_real_argmax(pf, r, r, rg, a),
                 so3fft_correlate_real_argmax(pd, rd, rd, rgd, ad));

    /* overlapping and misaligned arrays */
    SAME_CODE(SO3FFT_EINVAL, so3fftf_correlate(pf, s, g + 3, g),
              so3fft_correlate(pd, sd, gd + 3, gd));
    SAME_CODE(SO3FFT_EINVAL, so3fftf_correlate_real(pfr, r, rg + 1, rg),
              so3fft_correlate_real(pdr, rd, rgd + 1, rgd));
    SAME_CODE_ONLY(SO3FFT_EINVAL,
                   so3fftf_correlate(pf, s, s, (so3fftf_complex *)(void *)(raw + 1)),
                   so3fft_correlate(pd, sd, sd, (so3fft_complex *)(void *)(raw + 4)), "4 bytes");
    SAME_CODE_ONLY(SO3FFT_EINVAL,
                   so3fftf_correlate_real(pfr, (const float *)(const void *)(raw + 2), r, rg),
                   so3fft_correlate_real(pdr, (const double *)(const void *)(raw + 4), rd, rgd),
                   "4 bytes");
    CHECK(untouched_f(&g[0][0], 2 * ng + 2) && untouched_f(rg, ng));

    /* refinement: peak counts, angles */
    SAME_CODE(SO3FFT_EINVAL, so3fftf_correlation_refine_many(pfr, r, r, huge, a, v),
              so3fft_correlation_refine_many(pdr, rd, rd, huge, ad, vd));
    a[4] = ad[4] = NAN;
    SAME_CODE(SO3FFT_EINVAL, so3fftf_correlation_refine_many(pfr, r, r, 2, a, v),
              so3fft_correlation_refine_many(pdr, rd, rd, 2, ad, vd));
    a[4] = ad[4] = 0.5;
    CHECK(so3fftf_correlation_refine_many(pfr, r, r, 0, a, NULL) == SO3FFT_OK);
    CHECK_NO_ERR();

    /* grid peaks: bandwidth, NULL arrays, separation, counts */
    SAME_FAILURE(-1, SO3FFT_EBANDWIDTH, so3fftf_grid_argmax(0, g, a),
                 so3fft_grid_argmax(0, gd, ad));
    SAME_FAILURE(-1, SO3FFT_EBANDWIDTH, so3fftf_grid_argmax_real(SO3FFT_MAX_BANDWIDTH + 1, rg, a),
                 so3fft_grid_argmax_real(SO3FFT_MAX_BANDWIDTH + 1, rgd, ad));
    SAME_FAILURE(-1, SO3FFT_ENULL, so3fftf_grid_argmax(B, NULL, a),
                 so3fft_grid_argmax(B, NULL, ad));
    SAME_FAILURE(-1, SO3FFT_ENULL, so3fftf_grid_argmax_real(B, NULL, a),
                 so3fft_grid_argmax_real(B, NULL, ad));
    SAME_FAILURE(-1, SO3FFT_ENULL, so3fftf_grid_top_peaks(B, NULL, 1, 0.0, a, NULL, NULL),
                 so3fft_grid_top_peaks(B, NULL, 1, 0.0, ad, NULL, NULL));
    SAME_FAILURE(-1, SO3FFT_ENULL, so3fftf_grid_top_peaks(B, g, 1, 0.0, NULL, v, idx),
                 so3fft_grid_top_peaks(B, gd, 1, 0.0, NULL, vd, idxd));
    SAME_FAILURE(-1, SO3FFT_EINVAL, so3fftf_grid_top_peaks(B, g, 1, NAN, a, NULL, NULL),
                 so3fft_grid_top_peaks(B, gd, 1, NAN, ad, NULL, NULL));
    SAME_FAILURE(-1, SO3FFT_EINVAL, so3fftf_grid_top_peaks_real(B, rg, 1, -0.5, a, NULL, NULL),
                 so3fft_grid_top_peaks_real(B, rgd, 1, -0.5, ad, NULL, NULL));
    SAME_FAILURE(-1, SO3FFT_EINVAL, so3fftf_grid_top_peaks_real(B, rg, huge, 0.0, a, NULL, NULL),
                 so3fft_grid_top_peaks_real(B, rgd, huge, 0.0, ad, NULL, NULL));
    SAME_FAILURE(-1, SO3FFT_EBANDWIDTH, so3fftf_grid_top_peaks_real(0, rg, 1, 0.0, a, v, idx),
                 so3fft_grid_top_peaks_real(0, rgd, 1, 0.0, ad, vd, idxd));

    /* the plans still work after all these errors; 4-byte alignment suffices for floats */
    CHECK(so3fftf_correlate_real(pfr, r, r, rg) == SO3FFT_OK);
    CHECK(so3fftf_correlate(pf, s, s, (so3fftf_complex *)(void *)((char *)g + 4)) == SO3FFT_OK);
    CHECK_NO_ERR();
    CHECK(untouched_f(&g[0][0] + 2 * ng + 1, GUARD + 1) && untouched_f(rg + ng, GUARD));

    so3fftf_destroy_correlation(pf), so3fftf_destroy_correlation(pfr);
    so3fft_destroy_correlation(pd), so3fft_destroy_correlation(pdr);
    free(s), free(g), free(r), free(rg), free(sd), free(gd), free(rd), free(rgd), free(raw);
}

int main(int argc, char **argv) {
    const char *dir = argc > 1 ? argv[1] : "tests/data";
    double worst = 0.0;
    reference_cases(dir, &worst);
    random_cases(&worst);
    printf("test_f32_matching: largest relative error of a grid against f64: %.2g\n", worst);
    planted_peaks();
    bad_arguments();
    return finish("test_f32_matching");
}
