/* The single-precision C API (so3fftf_*):
 *  - S^2 round trips (complex and real) at several bandwidths: inverse of random band-limited
 *    coefficients then forward gives them back to single-precision rounding;
 *  - agreement with the double-precision so3fft_s2_* on the same data;
 *  - limited plans, and the _many executes bitwise equal to single calls;
 *  - single-precision FFTW's wisdom: export, forget, import (string and file), kept apart
 *    from the double-precision store;
 *  - bad arguments: the same error codes and messages as the double-precision functions,
 *    nothing written. */
#define _POSIX_C_SOURCE 200809L
#include <unistd.h>

#include "test_util.h"
#include "f32_twins.h"

/* Tolerance of a single-precision result, relative L2 (docs/precision.md). */
static const double TOL = 1e-5;

/* Random coefficients in float, and the same values in double. */
static void random_coeffs(so3fftf_complex *c, so3fft_complex *d, size_t n, unsigned long long seed) {
    size_t i;
    for (i = 0; i < n; i++) {
        c[i][0] = (float)rnd(&seed);
        c[i][1] = (float)rnd(&seed);
    }
    widen(&c[0][0], &d[0][0], 2 * n);
}

/* Makes `c` the coefficients of a real function: fhat(l,0) real,
 * fhat(l,-m) = (-1)^m conj(fhat(l,m)). */
static void make_real(so3fftf_complex *c, int b) {
    int l, m;
    for (l = 0; l < b; l++) {
        c[so3fft_s2_coef_index(b, l, 0)][1] = 0.0f;
        for (m = 1; m <= l; m++) {
            ptrdiff_t pos = so3fft_s2_coef_index(b, l, m), neg = so3fft_s2_coef_index(b, l, -m);
            float sg = (m % 2) ? -1.0f : 1.0f;
            c[neg][0] = sg * c[pos][0];
            c[neg][1] = -sg * c[pos][1];
        }
    }
}

/* Round trips at bandwidth b and agreement with the double-precision plan; the largest
 * relative error seen goes to *worst. */
static void round_trips(int b, int nthreads, double *worst) {
    size_t ns = so3fft_s2_num_samples(b), nc = so3fft_s2_num_coeffs(b);
    so3fftf_s2_plan pf = so3fftf_plan_s2(b, SO3FFT_ESTIMATE, nthreads);
    so3fft_s2_plan pd = so3fft_plan_s2(b, SO3FFT_ESTIMATE, nthreads);
    so3fftf_complex *c = alloc_cf(nc), *back = alloc_cf(nc), *s = alloc_cf(ns);
    so3fft_complex *cd = alloc_cx(nc), *backd = alloc_cx(nc), *sd = alloc_cx(ns);
    float *r = alloc_f(ns);
    double *rd = alloc_d(ns), e[8];
    int i;

    CHECK(pf != NULL && pd != NULL);
    if (!pf || !pd) {
        fprintf(stderr, "B = %d: %s\n", b, so3fft_last_error());
        return;
    }
    CHECK(so3fftf_s2_get_bandwidth(pf) == b);
    CHECK_NO_ERR();

    /* complex: the coefficients back, the samples and the coefficients as in double */
    random_coeffs(c, cd, nc, 100 + (unsigned long long)b);
    CHECK(so3fftf_s2_execute_inverse(pf, c, s) == SO3FFT_OK);
    CHECK(so3fftf_s2_execute_forward(pf, s, back) == SO3FFT_OK);
    CHECK(so3fft_s2_execute_inverse(pd, cd, sd) == SO3FFT_OK);
    e[0] = rel_cf_cd(back, cd, nc);
    e[1] = rel_cf_cd(s, sd, ns);
    widen(&s[0][0], &sd[0][0], 2 * ns);
    CHECK(so3fft_s2_execute_forward(pd, sd, backd) == SO3FFT_OK);
    e[2] = rel_cf_cd(back, backd, nc);

    /* real */
    make_real(c, b);
    widen(&c[0][0], &cd[0][0], 2 * nc);
    CHECK(so3fftf_s2_execute_inverse_real(pf, c, r) == SO3FFT_OK);
    CHECK(so3fftf_s2_execute_forward_real(pf, r, back) == SO3FFT_OK);
    CHECK(so3fft_s2_execute_inverse_real(pd, cd, rd) == SO3FFT_OK);
    e[3] = rel_cf_cd(back, cd, nc);
    e[4] = rel_f_d(r, rd, ns);
    widen(r, rd, ns);
    CHECK(so3fft_s2_execute_forward_real(pd, rd, backd) == SO3FFT_OK);
    e[5] = rel_cf_cd(back, backd, nc);
    /* the real inverse is the complex inverse's real part */
    CHECK(so3fftf_s2_execute_inverse(pf, c, s) == SO3FFT_OK);
    for (i = 0; i < (int)ns; i++) sd[i][0] = r[i], sd[i][1] = 0.0;
    e[6] = rel_cf_cd(s, sd, ns);
    CHECK_NO_ERR();

    for (i = 0; i < 7; i++) {
        if (!(e[i] < TOL)) {
            fprintf(stderr, "B = %d, check %d: relative error %.3g\n", b, i, e[i]);
            g_failures++;
        }
        if (!(e[i] <= *worst)) *worst = e[i];
    }
    so3fftf_destroy_s2_plan(pf);
    so3fft_destroy_s2_plan(pd);
    free(c), free(back), free(s), free(cd), free(backd), free(sd), free(r), free(rd);
}

/* A limited plan: the coefficients it keeps as from the full plan, the others 0. */
static void limited(int b, int L, int mmax) {
    size_t ns = so3fft_s2_num_samples(b), nc = so3fft_s2_num_coeffs(b);
    so3fftf_s2_plan p = so3fftf_plan_s2(b, SO3FFT_ESTIMATE, 2);
    so3fftf_s2_plan q = so3fftf_plan_s2_limited(b, L, mmax, SO3FFT_ESTIMATE, 1);
    so3fftf_complex *c = alloc_cf(nc), *full = alloc_cf(nc), *part = alloc_cf(nc);
    so3fftf_complex *s = alloc_cf(ns);
    so3fft_complex *cd = alloc_cx(nc);
    double diff = 0.0, big = 0.0;
    int l, m;
    CHECK(p != NULL && q != NULL);
    if (!p || !q) return;
    CHECK(so3fftf_s2_get_bandwidth(q) == b);
    random_coeffs(c, cd, nc, 5);
    CHECK(so3fftf_s2_execute_inverse(p, c, s) == SO3FFT_OK);
    CHECK(so3fftf_s2_execute_forward(p, s, full) == SO3FFT_OK);
    CHECK(so3fftf_s2_execute_forward(q, s, part) == SO3FFT_OK);
    for (l = 0; l < b; l++)
        for (m = -l; m <= l; m++) {
            ptrdiff_t at = so3fft_s2_coef_index(b, l, m);
            if (l < L && m >= -mmax && m <= mmax) {
                diff = fmax(diff, hypot(part[at][0] - full[at][0], part[at][1] - full[at][1]));
                big = fmax(big, hypot(full[at][0], full[at][1]));
            } else {
                CHECK(part[at][0] == 0.0f && part[at][1] == 0.0f);
            }
        }
    CHECK(diff <= TOL * big);
    so3fftf_destroy_s2_plan(p);
    so3fftf_destroy_s2_plan(q);
    free(c), free(full), free(part), free(s), free(cd);
}

/* The _many executes of k fields give the bits of k single calls. */
static void many(int b, int k) {
    size_t ns = so3fft_s2_num_samples(b), nc = so3fft_s2_num_coeffs(b), t;
    so3fftf_s2_plan p = so3fftf_plan_s2(b, SO3FFT_ESTIMATE, 2);
    so3fftf_complex *c = alloc_cf(k * nc), *c1 = alloc_cf(k * nc), *ck = alloc_cf(k * nc);
    so3fftf_complex *s = alloc_cf(k * ns), *s1 = alloc_cf(k * ns), *sk = alloc_cf(k * ns);
    so3fft_complex *cd = alloc_cx(k * nc);
    float *r1 = alloc_f(k * ns), *rk = alloc_f(k * ns);
    unsigned long long seed = 9;
    CHECK(p != NULL);
    if (!p) return;
    random_coeffs(c, cd, k * nc, 77);
    for (t = 0; t < (size_t)k; t++) make_real(c + t * nc, b);

    CHECK(so3fftf_s2_execute_inverse_many(p, k, c, sk) == SO3FFT_OK);
    for (t = 0; t < (size_t)k; t++)
        CHECK(so3fftf_s2_execute_inverse(p, c + t * nc, s1 + t * ns) == SO3FFT_OK);
    CHECK(memcmp(sk, s1, k * ns * sizeof *s1) == 0);

    /* samples of no particular band limit */
    for (t = 0; t < k * ns; t++) {
        s[t][0] = (float)rnd(&seed);
        s[t][1] = (float)rnd(&seed);
    }
    CHECK(so3fftf_s2_execute_forward_many(p, k, s, ck) == SO3FFT_OK);
    for (t = 0; t < (size_t)k; t++)
        CHECK(so3fftf_s2_execute_forward(p, s + t * ns, c1 + t * nc) == SO3FFT_OK);
    CHECK(memcmp(ck, c1, k * nc * sizeof *c1) == 0);

    CHECK(so3fftf_s2_execute_inverse_real_many(p, k, c, rk) == SO3FFT_OK);
    for (t = 0; t < (size_t)k; t++)
        CHECK(so3fftf_s2_execute_inverse_real(p, c + t * nc, r1 + t * ns) == SO3FFT_OK);
    CHECK(memcmp(rk, r1, k * ns * sizeof *r1) == 0);

    CHECK(so3fftf_s2_execute_forward_real_many(p, k, r1, ck) == SO3FFT_OK);
    for (t = 0; t < (size_t)k; t++)
        CHECK(so3fftf_s2_execute_forward_real(p, r1 + t * ns, c1 + t * nc) == SO3FFT_OK);
    CHECK(memcmp(ck, c1, k * nc * sizeof *c1) == 0);
    CHECK_NO_ERR();

    so3fftf_destroy_s2_plan(p);
    free(c), free(c1), free(ck), free(s), free(s1), free(sk), free(cd), free(r1), free(rk);
}

/* ---- errors: the f32 call and its f64 twin fail alike ---------------------------------- */

/* A call's outcome: its return value (or whether a planner returned NULL), the error code and
 * a copy of the message. */
/* Compares an f32 S^2 planner with its f64 twin: both NULL, the same code and message. */
#define SAME_PLAN_FAILURE(code, fcall, dcall)                                               \
    SAME_NULL(code, so3fftf_s2_plan, fcall, so3fftf_destroy_s2_plan, so3fft_s2_plan, dcall, \
              so3fft_destroy_s2_plan, 1)

static void bad_arguments(void) {
    const int b = 8;
    size_t ns = so3fft_s2_num_samples(b), nc = so3fft_s2_num_coeffs(b);
    so3fftf_s2_plan pf = so3fftf_plan_s2(b, SO3FFT_ESTIMATE, 1);
    so3fft_s2_plan pd = so3fft_plan_s2(b, SO3FFT_ESTIMATE, 1);
    /* one block for each precision: samples, then coefficients right behind them */
    so3fftf_complex *sf = alloc_cf(ns + nc + 1), *cf = sf + ns;
    so3fft_complex *sd = alloc_cx(ns + nc + 1), *cd = sd + ns;
    float *rf = alloc_f(ns + 1);
    double *rd = alloc_d(ns + 1);
    /* misaligned for the element type: a float array one byte off, a double array 4 bytes */
    so3fftf_complex *misf = (so3fftf_complex *)(void *)((char *)cf + 1);
    so3fft_complex *misd = (so3fft_complex *)(void *)((char *)cd + 4);
    float *misrf = (float *)(void *)((char *)rf + 2);
    double *misrd = (double *)(void *)((char *)rd + 4);
    CHECK(pf != NULL && pd != NULL);
    if (!pf || !pd) return;
    memset(sf, 0, (ns + nc) * sizeof *sf);
    memset(sd, 0, (ns + nc) * sizeof *sd);
    memset(rf, 0, ns * sizeof *rf);
    memset(rd, 0, ns * sizeof *rd);

    /* planners */
    SAME_PLAN_FAILURE(SO3FFT_EBANDWIDTH, so3fftf_plan_s2(0, SO3FFT_ESTIMATE, 1),
                      so3fft_plan_s2(0, SO3FFT_ESTIMATE, 1));
    SAME_PLAN_FAILURE(SO3FFT_EBANDWIDTH,
                      so3fftf_plan_s2(SO3FFT_S2_MAX_BANDWIDTH + 1, SO3FFT_ESTIMATE, 1),
                      so3fft_plan_s2(SO3FFT_S2_MAX_BANDWIDTH + 1, SO3FFT_ESTIMATE, 1));
    SAME_PLAN_FAILURE(SO3FFT_EINVAL, so3fftf_plan_s2(b, SO3FFT_REAL, 1),
                      so3fft_plan_s2(b, SO3FFT_REAL, 1));
    SAME_PLAN_FAILURE(SO3FFT_EINVAL, so3fftf_plan_s2(b, 1u << 20, 1),
                      so3fft_plan_s2(b, 1u << 20, 1));
    SAME_PLAN_FAILURE(SO3FFT_EINVAL, so3fftf_plan_s2(b, SO3FFT_ESTIMATE, -1),
                      so3fft_plan_s2(b, SO3FFT_ESTIMATE, -1));
    SAME_PLAN_FAILURE(SO3FFT_EINVAL, so3fftf_plan_s2_limited(b, 0, 3, SO3FFT_ESTIMATE, 1),
                      so3fft_plan_s2_limited(b, 0, 3, SO3FFT_ESTIMATE, 1));
    SAME_PLAN_FAILURE(SO3FFT_EINVAL, so3fftf_plan_s2_limited(b, b + 1, 3, SO3FFT_ESTIMATE, 1),
                      so3fft_plan_s2_limited(b, b + 1, 3, SO3FFT_ESTIMATE, 1));
    SAME_PLAN_FAILURE(SO3FFT_EINVAL, so3fftf_plan_s2_limited(b, 4, -1, SO3FFT_ESTIMATE, 1),
                      so3fft_plan_s2_limited(b, 4, -1, SO3FFT_ESTIMATE, 1));
    SAME_PLAN_FAILURE(SO3FFT_EBANDWIDTH, so3fftf_plan_s2_limited(-3, 1, 0, SO3FFT_ESTIMATE, 1),
                      so3fft_plan_s2_limited(-3, 1, 0, SO3FFT_ESTIMATE, 1));

    /* NULL plan */
    SAME_CODE(SO3FFT_ENULL, so3fftf_s2_get_bandwidth(NULL), so3fft_s2_get_bandwidth(NULL));
    SAME_CODE(SO3FFT_ENULL, so3fftf_s2_execute_forward(NULL, sf, cf),
              so3fft_s2_execute_forward(NULL, sd, cd));
    SAME_CODE(SO3FFT_ENULL, so3fftf_s2_execute_inverse(NULL, cf, sf),
              so3fft_s2_execute_inverse(NULL, cd, sd));
    SAME_CODE(SO3FFT_ENULL, so3fftf_s2_execute_forward_real(NULL, rf, cf),
              so3fft_s2_execute_forward_real(NULL, rd, cd));
    SAME_CODE(SO3FFT_ENULL, so3fftf_s2_execute_inverse_real(NULL, cf, rf),
              so3fft_s2_execute_inverse_real(NULL, cd, rd));
    SAME_CODE(SO3FFT_ENULL, so3fftf_s2_execute_forward_many(NULL, 2, sf, cf),
              so3fft_s2_execute_forward_many(NULL, 2, sd, cd));
    SAME_CODE(SO3FFT_ENULL, so3fftf_s2_execute_inverse_real_many(NULL, 1, cf, rf),
              so3fft_s2_execute_inverse_real_many(NULL, 1, cd, rd));
    so3fftf_destroy_s2_plan(NULL); /* no-op, not an error */
    CHECK_NO_ERR();

    /* NULL arrays (the input is named first); nothing written */
    fill_sentinel_f(&cf[0][0], 2 * nc);
    SAME_CODE(SO3FFT_ENULL, so3fftf_s2_execute_forward(pf, NULL, cf),
              so3fft_s2_execute_forward(pd, NULL, cd));
    SAME_CODE(SO3FFT_ENULL, so3fftf_s2_execute_forward(pf, NULL, NULL),
              so3fft_s2_execute_forward(pd, NULL, NULL));
    SAME_CODE(SO3FFT_ENULL, so3fftf_s2_execute_inverse(pf, cf, NULL),
              so3fft_s2_execute_inverse(pd, cd, NULL));
    SAME_CODE(SO3FFT_ENULL, so3fftf_s2_execute_forward_real(pf, NULL, cf),
              so3fft_s2_execute_forward_real(pd, NULL, cd));
    SAME_CODE(SO3FFT_ENULL, so3fftf_s2_execute_inverse_real_many(pf, 2, cf, NULL),
              so3fft_s2_execute_inverse_real_many(pd, 2, cd, NULL));
    CHECK(untouched_f(&cf[0][0], 2 * nc));

    /* howmany not positive */
    SAME_CODE(SO3FFT_EINVAL, so3fftf_s2_execute_forward_many(pf, 0, sf, cf),
              so3fft_s2_execute_forward_many(pd, 0, sd, cd));
    SAME_CODE(SO3FFT_EINVAL, so3fftf_s2_execute_inverse_many(pf, -1, cf, sf),
              so3fft_s2_execute_inverse_many(pd, -1, cd, sd));
    SAME_CODE(SO3FFT_EINVAL, so3fftf_s2_execute_forward_real_many(pf, 0, rf, cf),
              so3fft_s2_execute_forward_real_many(pd, 0, rd, cd));
    SAME_CODE(SO3FFT_EINVAL, so3fftf_s2_execute_inverse_real_many(pf, -5, cf, rf),
              so3fft_s2_execute_inverse_real_many(pd, -5, cd, rd));
    CHECK(untouched_f(&cf[0][0], 2 * nc));

    /* overlapping arrays: the same block, shifted by a few values; two fields of samples
     * reach into the coefficients behind them */
    SAME_CODE(SO3FFT_EINVAL, so3fftf_s2_execute_forward(pf, sf, sf + 3),
              so3fft_s2_execute_forward(pd, sd, sd + 3));
    SAME_CODE(SO3FFT_EINVAL, so3fftf_s2_execute_inverse(pf, cf, cf - 1),
              so3fft_s2_execute_inverse(pd, cd, cd - 1));
    SAME_CODE(SO3FFT_EINVAL, so3fftf_s2_execute_forward_many(pf, 2, sf, cf),
              so3fft_s2_execute_forward_many(pd, 2, sd, cd));
    SAME_CODE(SO3FFT_EINVAL,
              so3fftf_s2_execute_inverse_real(pf, cf, (float *)(void *)(cf + 2)),
              so3fft_s2_execute_inverse_real(pd, cd, (double *)(void *)(cd + 2)));
    CHECK(untouched_f(&cf[0][0], 2 * nc));
    /* adjacent (touching, not overlapping) arrays are fine */
    memset(sf, 0, ns * sizeof *sf);
    memset(sd, 0, ns * sizeof *sd);
    CHECK(so3fftf_s2_execute_forward(pf, sf, cf) == SO3FFT_OK);
    CHECK(so3fft_s2_execute_forward(pd, sd, cd) == SO3FFT_OK);
    CHECK_NO_ERR();

    /* misaligned arrays (for their element type); nothing written */
    fill_sentinel_f(&cf[0][0], 2 * nc);
    SAME_CODE_ONLY(SO3FFT_EINVAL, so3fftf_s2_execute_forward(pf, sf, misf),
                   so3fft_s2_execute_forward(pd, sd, misd), "");
    SAME_CODE_ONLY(SO3FFT_EINVAL, so3fftf_s2_execute_inverse(pf, misf, sf),
                   so3fft_s2_execute_inverse(pd, misd, sd), "");
    SAME_CODE_ONLY(SO3FFT_EINVAL, so3fftf_s2_execute_forward_real(pf, misrf, cf),
                   so3fft_s2_execute_forward_real(pd, misrd, cd), "");
    SAME_CODE_ONLY(SO3FFT_EINVAL, so3fftf_s2_execute_inverse_real_many(pf, 1, cf, misrf),
                   so3fft_s2_execute_inverse_real_many(pd, 1, cd, misrd), "");
    CHECK(untouched_f(&cf[0][0], 2 * nc));
    /* aligned to 4 bytes is enough for floats (not for doubles) */
    memset(sf, 0, ns * sizeof *sf);
    CHECK(so3fftf_s2_execute_forward(pf, sf, (so3fftf_complex *)(void *)((char *)cf + 4)) ==
          SO3FFT_OK);
    CHECK_NO_ERR();

    /* the plans still work after all these errors */
    CHECK(so3fftf_s2_execute_inverse_real(pf, cf, rf) == SO3FFT_OK);
    CHECK_NO_ERR();
    so3fftf_destroy_s2_plan(pf);
    so3fft_destroy_s2_plan(pd);
    free(sf), free(sd), free(rf), free(rd);
}

/* ---- wisdom ------------------------------------------------------------------------------ */

/* Length of the single-precision wisdom text (0 on failure). */
static size_t wisdom_len_f(void) {
    char *t = so3fftf_export_wisdom_to_string();
    size_t n = t ? strlen(t) : 0;
    free(t);
    return n;
}

static size_t wisdom_len_d(void) {
    char *t = so3fft_export_wisdom_to_string();
    size_t n = t ? strlen(t) : 0;
    free(t);
    return n;
}

static void wisdom(void) {
    char file[64], *text, *dtext;
    size_t len, dlen;
    so3fftf_s2_plan p;
    snprintf(file, sizeof file, "/tmp/so3fft_f32_wisdom_%ld", (long)getpid());

    /* errors as in double precision */
    SAME_CODE(SO3FFT_ENULL, so3fftf_import_wisdom_from_string(NULL),
              so3fft_import_wisdom_from_string(NULL));
    SAME_CODE(SO3FFT_EINVAL, so3fftf_import_wisdom_from_string("(not wisdom"),
              so3fft_import_wisdom_from_string("(not wisdom"));
    SAME_CODE(SO3FFT_ENULL, so3fftf_import_wisdom_from_filename(NULL),
              so3fft_import_wisdom_from_filename(NULL));
    SAME_CODE(SO3FFT_EINVAL, so3fftf_import_wisdom_from_filename("/nonexistent/so3fft.wisdom"),
              so3fft_import_wisdom_from_filename("/nonexistent/so3fft.wisdom"));
    SAME_CODE(SO3FFT_ENULL, so3fftf_export_wisdom_to_filename(NULL),
              so3fft_export_wisdom_to_filename(NULL));
    SAME_CODE(SO3FFT_EINVAL, so3fftf_export_wisdom_to_filename("/nonexistent/dir/w"),
              so3fft_export_wisdom_to_filename("/nonexistent/dir/w"));

    /* a measured single-precision plan leaves wisdom of libfftw3f */
    so3fftf_forget_wisdom();
    CHECK_NO_ERR();
    p = so3fftf_plan_s2(12, SO3FFT_MEASURE, 1);
    CHECK(p != NULL);
    so3fftf_destroy_s2_plan(p);
    text = so3fftf_export_wisdom_to_string();
    CHECK(text != NULL);
    if (!text) return;
    CHECK_NO_ERR();
    len = strlen(text);
    CHECK(strncmp(text, "(fftw-3", 7) == 0 && strstr(text, "fftwf_wisdom") != NULL);
    dtext = so3fft_export_wisdom_to_string();
    CHECK(dtext != NULL);
    if (!dtext) return;
    dlen = strlen(dtext);

    /* the precisions' stores are separate: neither imports the other's wisdom, and
     * forgetting one leaves the other */
    SAME_CODE(SO3FFT_EINVAL, so3fftf_import_wisdom_from_string(dtext),
              so3fft_import_wisdom_from_string(text));
    so3fftf_forget_wisdom();
    CHECK(wisdom_len_f() < len);
    CHECK(wisdom_len_d() == dlen);

    /* back from the string, then through a file */
    CHECK(so3fftf_import_wisdom_from_string(text) == SO3FFT_OK);
    CHECK_NO_ERR();
    CHECK(wisdom_len_f() == len);
    CHECK(so3fftf_export_wisdom_to_filename(file) == SO3FFT_OK);
    CHECK_NO_ERR();
    so3fftf_forget_wisdom();
    CHECK(wisdom_len_f() < len);
    CHECK(so3fftf_import_wisdom_from_filename(file) == SO3FFT_OK);
    CHECK_NO_ERR();
    CHECK(wisdom_len_f() == len);
    /* a double-precision wisdom file is refused */
    CHECK(so3fft_export_wisdom_to_filename(file) == SO3FFT_OK);
    CHECK(so3fftf_import_wisdom_from_filename(file) == SO3FFT_EINVAL);
    CHECK_ERR(SO3FFT_EINVAL);

    /* a plan made with the imported wisdom, measured, works */
    p = so3fftf_plan_s2(12, SO3FFT_MEASURE, 1);
    CHECK(p != NULL);
    so3fftf_destroy_s2_plan(p);
    unlink(file);
    free(text);
    free(dtext);
}

int main(void) {
    static const int bandwidths[] = {1, 5, 17, 64};
    double worst = 0.0;
    size_t i;
    for (i = 0; i < sizeof bandwidths / sizeof bandwidths[0]; i++)
        round_trips(bandwidths[i], 1 + (int)(i % 2), &worst);
    printf("test_f32: largest relative error of the S^2 round trips and against f64: %.2g\n",
           worst);
    limited(40, 30, 20);
    many(24, 3);
    bad_arguments();
    wisdom();
    return finish("test_f32");
}
