/* The single-precision C API of the SO(3) plans (so3fftf_plan_*, so3fftf_execute*, the
 * queries, so3fftf_weights) and of the partial plans (so3fftf_partial_*):
 *  - complex and real round trips at several bandwidths (relative L2 error), and agreement
 *    with the double-precision functions on the same data (samples and coefficients);
 *  - with SO3FFT_REAL: the inverse's imaginary parts exactly 0, the forward reading the real
 *    parts only;
 *  - so3fftf_execute on the arrays given at planning, new-array execute on other arrays,
 *    bitwise the same; planner settings shared with the double API;
 *  - so3fftf_plan_memory equal to so3fftf_get_memory of the plan made, below the double figure;
 *  - so3fftf_weights: the double weights rounded;
 *  - partial plans (degree- and order-limited shape, other grid, beta selections by index and by
 *    value, real signals) against the double partial plans; _many bitwise equal to single calls;
 *  - bad arguments (those of test_errors.c and test_partial.c): the same error codes and
 *    messages as the double-precision functions, nothing written;
 *  - nothing written behind the arrays (guard values; valgrind checks the rest). */
#include "test_util.h"
#include "f32_twins.h"

/* Round trip of a single-precision transform, relative L2 (docs/precision.md). */
static const double TOL = 1e-5;
/* Single against double precision on the same data, relative L2. */
static const double AGREE = 5e-6;

/* The guard values behind an array of n complex floats are intact. */
static int guard_cf(so3fftf_complex *a, size_t n) { return untouched_f(&a[n][0], 2 * GUARD); }

/* Random values in float, and the same values in double (d may be NULL). */
static void random_cf(so3fftf_complex *c, so3fft_complex *d, size_t n, unsigned long long seed) {
    size_t i;
    for (i = 0; i < n; i++) {
        c[i][0] = (float)rnd(&seed);
        c[i][1] = (float)rnd(&seed);
    }
    if (d) widen(&c[0][0], &d[0][0], 2 * n);
}

/* The index of fhat(l, m, mp) in the coefficients of the full transform (shape NULL) or of a
 * shape; negative where there is none. */
static ptrdiff_t index_of(int b, const so3fft_shape *s, int l, int m, int mp) {
    if (s) return so3fft_shape_coef_index(s, l, m, mp);
    if (m < -l || m > l || mp < -l || mp > l) return -1;
    return so3fft_coef_index(b, l, m, mp);
}

/* Makes `c` the coefficients of a real signal: fhat(l,-m,-mp) = (-1)^(m-mp) conj(fhat(l,m,mp)),
 * taking the blocks mp > 0, or mp = 0 and m >= 0, as they are. */
static void make_real(so3fftf_complex *c, int b, const so3fft_shape *s) {
    int L = s ? s->L : b, mmax = s ? s->m_max : b - 1, mpmax = s ? s->mp_max : b - 1;
    int l, m, mp;
    for (l = 0; l < L; l++)
        for (mp = 0; mp <= mpmax; mp++)
            for (m = (mp == 0 ? 0 : -mmax); m <= mmax; m++) {
                ptrdiff_t i = index_of(b, s, l, m, mp), j = index_of(b, s, l, -m, -mp);
                float sg = ((m - mp) % 2 == 0) ? 1.0f : -1.0f;
                if (i < 0 || j < 0) continue;
                if (i == j) {
                    c[i][1] = 0.0f;
                } else {
                    c[j][0] = sg * c[i][0];
                    c[j][1] = -sg * c[i][1];
                }
            }
}

/* Records a relative error: a failure above `tol`; the largest seen goes to *worst. */
static void judge(const char *what, int b, double e, double tol, double *worst) {
    if (!(e < tol)) {
        fprintf(stderr, "B = %d, %s: relative error %.3g (limit %.1g)\n", b, what, e, tol);
        g_failures++;
    }
    if (!(e <= *worst)) *worst = e;
}

/* ---- the full transform ------------------------------------------------------------------ */

/* Round trips at bandwidth b on `nthreads` workers, agreement with double precision, plan
 * queries and memory. */
static void round_trips(int b, int nthreads, double *worst) {
    size_t ns = so3fft_num_samples(b), nc = so3fft_num_coeffs(b), i;
    so3fftf_plan pf = so3fftf_plan_general(b, SO3FFT_BOTH, NULL, NULL, SO3FFT_ESTIMATE, nthreads);
    so3fftf_plan pfr = so3fftf_plan_general(b, SO3FFT_BOTH, NULL, NULL, SO3FFT_REAL, nthreads);
    so3fft_plan pd = so3fft_plan_general(b, SO3FFT_BOTH, NULL, NULL, SO3FFT_ESTIMATE, nthreads);
    so3fft_plan pdr = so3fft_plan_general(b, SO3FFT_BOTH, NULL, NULL, SO3FFT_REAL, nthreads);
    so3fftf_complex *c = alloc_cf(nc), *back = alloc_cf(nc), *back2 = alloc_cf(nc);
    so3fftf_complex *s = alloc_cf(ns);
    so3fft_complex *cd = alloc_cx(nc), *backd = alloc_cx(nc), *sd = alloc_cx(ns);
    ptrdiff_t mf, mfr, md;
    int imag_zero = 1;

    CHECK(pf && pfr && pd && pdr);
    if (!(pf && pfr && pd && pdr)) {
        fprintf(stderr, "B = %d: %s\n", b, so3fft_last_error());
        return;
    }
    CHECK(so3fftf_get_bandwidth(pf) == b && so3fftf_get_bandwidth(pfr) == b);
    CHECK(so3fftf_get_nthreads(pf) == nthreads);
    CHECK(so3fftf_get_fft_threading(pf) == SO3FFT_FFT_SLICES_ACROSS_WORKERS);
    CHECK_NO_ERR();

    /* memory: known before planning; below the double plan's from B = 16 on (at the
     * smallest bandwidths the tables and stacks dominate, and single-precision plans hold
     * double rows for their lowest orders on top) */
    mf = so3fftf_get_memory(pf);
    mfr = so3fftf_get_memory(pfr);
    md = so3fft_get_memory(pd);
    CHECK(mf > 0 && mfr > 0);
    CHECK(so3fftf_plan_memory(b, SO3FFT_ESTIMATE, nthreads) == mf);
    CHECK(so3fftf_plan_memory(b, SO3FFT_REAL, nthreads) == mfr);
    CHECK(so3fft_plan_memory(b, SO3FFT_ESTIMATE, nthreads) == md);
    if (b >= 16) {
        CHECK(mf < md);
        CHECK(mfr < so3fft_get_memory(pdr));
    }
    CHECK_NO_ERR();

    /* complex */
    random_cf(c, cd, nc, 1000 + (unsigned long long)b);
    CHECK(so3fftf_execute_inverse(pf, c, s) == SO3FFT_OK);
    CHECK(so3fftf_execute_forward(pf, s, back) == SO3FFT_OK);
    judge("complex round trip", b, rel_cf_cd(back, cd, nc), TOL, worst);
    CHECK(so3fft_execute_inverse(pd, cd, sd) == SO3FFT_OK);
    judge("complex inverse against f64", b, rel_cf_cd(s, sd, ns), AGREE, worst);
    widen(&s[0][0], &sd[0][0], 2 * ns);
    CHECK(so3fft_execute_forward(pd, sd, backd) == SO3FFT_OK);
    judge("complex forward against f64", b, rel_cf_cd(back, backd, nc), AGREE, worst);
    CHECK_NO_ERR();

    /* real signal in complex arrays */
    make_real(c, b, NULL);
    widen(&c[0][0], &cd[0][0], 2 * nc);
    CHECK(so3fftf_execute_inverse(pfr, c, s) == SO3FFT_OK);
    for (i = 0; i < ns; i++) imag_zero &= s[i][1] == 0.0f;
    CHECK(imag_zero);
    CHECK(so3fftf_execute_forward(pfr, s, back) == SO3FFT_OK);
    judge("real round trip", b, rel_cf_cd(back, cd, nc), TOL, worst);
    CHECK(so3fft_execute_inverse(pdr, cd, sd) == SO3FFT_OK);
    judge("real inverse against f64", b, rel_cf_cd(s, sd, ns), AGREE, worst);
    widen(&s[0][0], &sd[0][0], 2 * ns);
    CHECK(so3fft_execute_forward(pdr, sd, backd) == SO3FFT_OK);
    judge("real forward against f64", b, rel_cf_cd(back, backd, nc), AGREE, worst);
    /* the real forward reads the real parts only */
    for (i = 0; i < ns; i++) s[i][1] = 7.0f;
    CHECK(so3fftf_execute_forward(pfr, s, back2) == SO3FFT_OK);
    CHECK(memcmp(back, back2, nc * sizeof *back) == 0);
    /* the complex inverse of real coefficients: its real parts are the real inverse's */
    CHECK(so3fftf_execute_inverse(pf, c, s) == SO3FFT_OK);
    for (i = 0; i < ns; i++) sd[i][1] = 0.0;
    judge("complex against real inverse", b, rel_cf_cd(s, sd, ns), AGREE, worst);
    CHECK_NO_ERR();

    CHECK(guard_cf(c, nc) && guard_cf(back, nc) && guard_cf(back2, nc) && guard_cf(s, ns));
    so3fftf_destroy_plan(pf);
    so3fftf_destroy_plan(pfr);
    so3fft_destroy_plan(pd);
    so3fft_destroy_plan(pdr);
    CHECK_NO_ERR();
    free(c), free(back), free(back2), free(s), free(cd), free(backd), free(sd);
}

/* Plans made with arrays: so3fftf_execute on them, new-array execute on others, a plan for
 * both directions: bitwise the same. Planner settings shared with the double API. */
static void arrays_and_settings(void) {
    const int b = 6;
    size_t ns = so3fft_num_samples(b), nc = so3fft_num_coeffs(b);
    so3fftf_complex *s = alloc_cf(ns), *c = alloc_cf(nc), *s2 = alloc_cf(ns), *c2 = alloc_cf(nc);
    so3fftf_complex *s3 = alloc_cf(ns), *c3 = alloc_cf(nc);
    so3fftf_plan pfw = so3fftf_plan_forward(b, s, c, SO3FFT_ESTIMATE);
    so3fftf_plan piv = so3fftf_plan_inverse(b, c2, s2, SO3FFT_ESTIMATE);
    so3fftf_plan pb = so3fftf_plan_both(b, SO3FFT_ESTIMATE);
    so3fftf_plan p1;
    ptrdiff_t capped, full;
    CHECK(pfw && piv && pb);
    if (!(pfw && piv && pb)) return;
    CHECK_NO_ERR();

    random_cf(c2, NULL, nc, 17);
    CHECK(so3fftf_execute(piv) == SO3FFT_OK);
    CHECK(so3fftf_execute_inverse(pb, c2, s3) == SO3FFT_OK);
    CHECK(memcmp(s2, s3, ns * sizeof *s2) == 0);
    memcpy(s, s2, ns * sizeof *s);
    CHECK(so3fftf_execute(pfw) == SO3FFT_OK);
    CHECK(so3fftf_execute_forward(pb, s, c3) == SO3FFT_OK);
    CHECK(memcmp(c, c3, nc * sizeof *c) == 0);
    /* new-array execute of a plan made with arrays, on other arrays */
    fill_sentinel_f(&c3[0][0], 2 * nc);
    CHECK(so3fftf_execute_forward(pfw, s3, c3) == SO3FFT_OK);
    CHECK(memcmp(c, c3, nc * sizeof *c) == 0);
    /* so3fftf_execute reads the planning arrays anew */
    random_cf(s, NULL, ns, 23);
    CHECK(so3fftf_execute(pfw) == SO3FFT_OK);
    CHECK(so3fftf_execute_forward(pb, s, c3) == SO3FFT_OK);
    CHECK(memcmp(c, c3, nc * sizeof *c) == 0);
    CHECK_NO_ERR();

    /* the thread and workspace settings of the library apply to both precisions */
    CHECK(so3fft_plan_with_nthreads(1) == SO3FFT_OK);
    p1 = so3fftf_plan_both(b, SO3FFT_ESTIMATE);
    CHECK(p1 != NULL && so3fftf_get_nthreads(p1) == 1);
    so3fftf_destroy_plan(p1);
    CHECK(so3fft_plan_with_nthreads(0) == SO3FFT_OK);
    full = so3fftf_plan_memory(32, SO3FFT_ESTIMATE, 1);
    CHECK(so3fft_plan_with_max_workspace(1) == SO3FFT_OK);
    capped = so3fftf_plan_memory(32, SO3FFT_ESTIMATE, 1);
    p1 = so3fftf_plan_general(32, SO3FFT_BOTH, NULL, NULL, SO3FFT_ESTIMATE, 1);
    CHECK(p1 != NULL && so3fftf_get_memory(p1) == capped);
    CHECK(capped > 0 && capped < full);
    so3fftf_destroy_plan(p1);
    CHECK(so3fft_plan_with_max_workspace(0) == SO3FFT_OK);
    CHECK(so3fftf_plan_memory(32, SO3FFT_ESTIMATE, 1) == full);
    CHECK_NO_ERR();

    CHECK(guard_cf(s, ns) && guard_cf(c, nc) && guard_cf(s2, ns) && guard_cf(c2, nc) &&
          guard_cf(s3, ns) && guard_cf(c3, nc));
    so3fftf_destroy_plan(pfw);
    so3fftf_destroy_plan(piv);
    so3fftf_destroy_plan(pb);
    free(s), free(c), free(s2), free(c2), free(s3), free(c3);
}

/* so3fftf_weights: the double weights rounded to float. */
static void weights(void) {
    static const int bs[] = {1, 5, 16};
    size_t k, i;
    for (k = 0; k < sizeof bs / sizeof bs[0]; k++) {
        int b = bs[k];
        float *wf = alloc_f(2 * (size_t)b);
        double *wd = alloc_d(2 * (size_t)b);
        int same = 1;
        CHECK(so3fftf_weights(b, wf) == SO3FFT_OK);
        CHECK_NO_ERR();
        CHECK(so3fft_weights(b, wd) == SO3FFT_OK);
        for (i = 0; i < 2 * (size_t)b; i++) same &= wf[i] == (float)wd[i];
        CHECK(same);
        CHECK(untouched_f(wf + 2 * b, GUARD));
        free(wf), free(wd);
    }
}

/* ---- partial plans ----------------------------------------------------------------------- */

/* A degree- and order-limited shape on another alpha/gamma grid: single against double
 * precision, complex and real; _many bitwise equal to single calls. */
static void partial_shape(double *worst) {
    so3fft_shape s = so3fft_shape_default(16);
    so3fft_partial_options o;
    so3fftf_partial pf;
    so3fft_partial pd;
    ptrdiff_t nc, ns, idist, odist;
    so3fftf_complex *c, *back, *x, *cm, *xm, *one, *onec;
    so3fft_complex *cd, *backd, *xd;
    float *r, *rm, *oner;
    double *rd;
    int t;
    const int count = 3;
    s.L = 12;
    s.L0 = 1;
    s.m_max = 6;
    s.mp_max = 5;
    s.n_alpha = 13;
    s.n_gamma = 15;
    CHECK(so3fft_shape_check(&s, SO3FFT_BOTH) == SO3FFT_OK);
    memset(&o, 0, sizeof o);
    o.nthreads = 2;
    pf = so3fftf_plan_partial(&s, &o, SO3FFT_ESTIMATE | SO3FFT_REAL);
    pd = so3fft_plan_partial(&s, &o, SO3FFT_ESTIMATE | SO3FFT_REAL);
    CHECK(pf && pd);
    if (!(pf && pd)) {
        fprintf(stderr, "partial: %s\n", so3fft_last_error());
        return;
    }
    nc = so3fftf_partial_num_coeffs(pf);
    ns = so3fftf_partial_num_samples(pf);
    CHECK(nc == so3fft_partial_num_coeffs(pd) && nc == so3fft_shape_num_coeffs(&s));
    CHECK(ns == so3fft_partial_num_samples(pd) && ns == 32 * 13 * 15);
    CHECK_NO_ERR();
    c = alloc_cf((size_t)nc), back = alloc_cf((size_t)nc), x = alloc_cf((size_t)ns);
    cd = alloc_cx((size_t)nc), backd = alloc_cx((size_t)nc), xd = alloc_cx((size_t)ns);
    r = alloc_f((size_t)ns), rd = alloc_d((size_t)ns);

    /* complex */
    random_cf(c, cd, (size_t)nc, 31);
    CHECK(so3fftf_partial_inverse(pf, c, x) == SO3FFT_OK);
    CHECK(so3fft_partial_inverse(pd, cd, xd) == SO3FFT_OK);
    judge("partial inverse against f64", 16, rel_cf_cd(x, xd, (size_t)ns), AGREE, worst);
    CHECK(so3fftf_partial_forward(pf, x, back) == SO3FFT_OK);
    judge("partial round trip", 16, rel_cf_cd(back, cd, (size_t)nc), TOL, worst);
    widen(&x[0][0], &xd[0][0], 2 * (size_t)ns);
    CHECK(so3fft_partial_forward(pd, xd, backd) == SO3FFT_OK);
    judge("partial forward against f64", 16, rel_cf_cd(back, backd, (size_t)nc), AGREE, worst);

    /* real */
    make_real(c, 16, &s);
    widen(&c[0][0], &cd[0][0], 2 * (size_t)nc);
    CHECK(so3fftf_partial_inverse_real(pf, c, r) == SO3FFT_OK);
    CHECK(so3fft_partial_inverse_real(pd, cd, rd) == SO3FFT_OK);
    judge("partial real inverse against f64", 16, rel_f_d(r, rd, (size_t)ns), AGREE, worst);
    CHECK(so3fftf_partial_forward_real(pf, r, back) == SO3FFT_OK);
    judge("partial real round trip", 16, rel_cf_cd(back, cd, (size_t)nc), TOL, worst);
    widen(r, rd, (size_t)ns);
    CHECK(so3fft_partial_forward_real(pd, rd, backd) == SO3FFT_OK);
    judge("partial real forward against f64", 16, rel_cf_cd(back, backd, (size_t)nc), AGREE,
          worst);
    CHECK_NO_ERR();

    /* _many: `count` transforms with gaps between them, bitwise the single calls */
    idist = nc + 3;
    odist = ns + 1;
    cm = alloc_cf((size_t)(count * idist)), xm = alloc_cf((size_t)(count * odist));
    rm = alloc_f((size_t)(count * odist));
    one = alloc_cf((size_t)ns), onec = alloc_cf((size_t)nc), oner = alloc_f((size_t)ns);
    random_cf(cm, NULL, (size_t)(count * idist), 37);
    for (t = 0; t < count; t++) make_real(cm + t * idist, 16, &s);
    CHECK(so3fftf_partial_inverse_many(pf, count, cm, idist, xm, odist) == SO3FFT_OK);
    CHECK(so3fftf_partial_inverse_real_many(pf, count, cm, idist, rm, odist) == SO3FFT_OK);
    for (t = 0; t < count; t++) {
        CHECK(so3fftf_partial_inverse(pf, cm + t * idist, one) == SO3FFT_OK);
        CHECK(memcmp(one, xm + t * odist, (size_t)ns * sizeof *one) == 0);
        CHECK(so3fftf_partial_inverse_real(pf, cm + t * idist, oner) == SO3FFT_OK);
        CHECK(memcmp(oner, rm + t * odist, (size_t)ns * sizeof *oner) == 0);
    }
    CHECK(so3fftf_partial_forward_many(pf, count, xm, odist, cm, idist) == SO3FFT_OK);
    for (t = 0; t < count; t++) {
        CHECK(so3fftf_partial_forward(pf, xm + t * odist, onec) == SO3FFT_OK);
        CHECK(memcmp(onec, cm + t * idist, (size_t)nc * sizeof *onec) == 0);
    }
    CHECK(so3fftf_partial_forward_real_many(pf, count, rm, odist, cm, idist) == SO3FFT_OK);
    for (t = 0; t < count; t++) {
        CHECK(so3fftf_partial_forward_real(pf, rm + t * odist, onec) == SO3FFT_OK);
        CHECK(memcmp(onec, cm + t * idist, (size_t)nc * sizeof *onec) == 0);
    }
    CHECK_NO_ERR();

    CHECK(guard_cf(c, (size_t)nc) && guard_cf(back, (size_t)nc) && guard_cf(x, (size_t)ns));
    CHECK(untouched_f(r + ns, GUARD) && untouched_f(rm + count * odist, GUARD));
    CHECK(guard_cf(cm, (size_t)(count * idist)) && guard_cf(xm, (size_t)(count * odist)));
    so3fftf_destroy_partial(pf);
    so3fft_destroy_partial(pd);
    CHECK_NO_ERR();
    free(c), free(back), free(x), free(cd), free(backd), free(xd), free(r), free(rd);
    free(cm), free(xm), free(rm), free(one), free(onec), free(oner);
}

/* Beta selections (grid indices; beta values in double) against the double plans and the
 * full single-precision inverse. */
static void partial_betas(double *worst) {
    static const double PI_ = 3.14159265358979323846;
    so3fft_shape s = so3fft_shape_default(12);
    so3fft_partial_options o;
    so3fftf_partial all, sel;
    so3fft_partial seld;
    int ks[4] = {23, 0, 7, 9};
    double vals[2];
    ptrdiff_t nc, ns, sl = 9 * 7;
    so3fftf_complex *c, *x, *y;
    so3fft_complex *cd, *yd;
    int i;
    s.m_max = 4;
    s.mp_max = 3;
    s.n_alpha = 9;
    s.n_gamma = 7;
    all = so3fftf_plan_partial(&s, NULL, SO3FFT_ESTIMATE);
    memset(&o, 0, sizeof o);
    o.nbetas = 4;
    o.beta_indices = ks;
    sel = so3fftf_plan_partial(&s, &o, SO3FFT_ESTIMATE);
    seld = so3fft_plan_partial(&s, &o, SO3FFT_ESTIMATE);
    CHECK(all && sel && seld);
    if (!(all && sel && seld)) return;
    nc = so3fftf_partial_num_coeffs(all);
    ns = so3fftf_partial_num_samples(all);
    CHECK(ns == 24 * sl);
    CHECK(so3fftf_partial_num_samples(sel) == 4 * sl);
    c = alloc_cf((size_t)nc), x = alloc_cf((size_t)ns), y = alloc_cf((size_t)(4 * sl));
    cd = alloc_cx((size_t)nc), yd = alloc_cx((size_t)(4 * sl));
    random_cf(c, cd, (size_t)nc, 41);
    CHECK(so3fftf_partial_inverse(all, c, x) == SO3FFT_OK);
    CHECK(so3fftf_partial_inverse(sel, c, y) == SO3FFT_OK);
    CHECK(so3fft_partial_inverse(seld, cd, yd) == SO3FFT_OK);
    judge("beta indices against f64", 12, rel_cf_cd(y, yd, (size_t)(4 * sl)), AGREE, worst);
    for (i = 0; i < 4; i++) {
        widen(&x[ks[i] * sl][0], &yd[0][0], 2 * (size_t)sl);
        judge("beta indices against all betas", 12, rel_cf_cd(y + i * sl, yd, (size_t)sl),
              AGREE, worst);
    }
    /* a selection plan runs the inverse only, in both precisions */
    CHECK(so3fftf_partial_forward(sel, y, c) == SO3FFT_EDIRECTION);
    CHECK_ERR(SO3FFT_EDIRECTION);
    so3fftf_destroy_partial(sel);
    so3fft_destroy_partial(seld);

    vals[0] = PI_ * (2 * 3 + 1) / (4.0 * 12);
    vals[1] = 1.0;
    o.nbetas = 2;
    o.beta_indices = NULL;
    o.beta_values = vals;
    sel = so3fftf_plan_partial(&s, &o, SO3FFT_ESTIMATE);
    seld = so3fft_plan_partial(&s, &o, SO3FFT_ESTIMATE);
    CHECK(sel && seld);
    if (sel && seld) {
        CHECK(so3fftf_partial_inverse(sel, c, y) == SO3FFT_OK);
        CHECK(so3fft_partial_inverse(seld, cd, yd) == SO3FFT_OK);
        judge("beta values against f64", 12, rel_cf_cd(y, yd, (size_t)(2 * sl)), AGREE, worst);
        widen(&x[3 * sl][0], &yd[0][0], 2 * (size_t)sl);
        judge("beta value on the grid", 12, rel_cf_cd(y, yd, (size_t)sl), AGREE, worst);
    }
    CHECK_NO_ERR();
    CHECK(guard_cf(c, (size_t)nc) && guard_cf(x, (size_t)ns) && guard_cf(y, (size_t)(4 * sl)));
    so3fftf_destroy_partial(sel);
    so3fft_destroy_partial(seld);
    so3fftf_destroy_partial(all);
    free(c), free(x), free(y), free(cd), free(yd);
}

/* ---- errors: the f32 call and its f64 twin fail alike ---------------------------------- */

/* A call's outcome: its return value (or whether a planner returned NULL), the error code and
 * a copy of the message. */
#define SAME_PLAN_FAILURE(code, fcall, dcall)                                               \
    SAME_NULL(code, so3fftf_plan, fcall, so3fftf_destroy_plan, so3fft_plan, dcall,          \
              so3fft_destroy_plan, 1)

#define SAME_PARTIAL_FAILURE(code, fcall, dcall)                                            \
    SAME_NULL(code, so3fftf_partial, fcall, so3fftf_destroy_partial, so3fft_partial, dcall, \
              so3fft_destroy_partial, 1)

/* Bandwidths, flags, thread counts, directions (test_errors.c in both precisions). */
static void bad_plan_arguments(void) {
    static const int bad_b[] = {0, -1, -1000, SO3FFT_MAX_BANDWIDTH + 1, 1 << 30};
    static const unsigned bad_flags[] = {1u << 3, 1u << 6, 1u << 31, 0xffffffffu};
    float wf[16];
    double wd[16];
    size_t i;
    for (i = 0; i < sizeof bad_b / sizeof bad_b[0]; i++) {
        int b = bad_b[i];
        SAME_PLAN_FAILURE(SO3FFT_EBANDWIDTH, so3fftf_plan_forward(b, NULL, NULL, 0),
                          so3fft_plan_forward(b, NULL, NULL, 0));
        SAME_PLAN_FAILURE(SO3FFT_EBANDWIDTH, so3fftf_plan_inverse(b, NULL, NULL, 0),
                          so3fft_plan_inverse(b, NULL, NULL, 0));
        SAME_PLAN_FAILURE(SO3FFT_EBANDWIDTH, so3fftf_plan_both(b, 0), so3fft_plan_both(b, 0));
        SAME_PLAN_FAILURE(SO3FFT_EBANDWIDTH,
                          so3fftf_plan_general(b, SO3FFT_BOTH, NULL, NULL, 0, 1),
                          so3fft_plan_general(b, SO3FFT_BOTH, NULL, NULL, 0, 1));
        SAME_CODE(SO3FFT_EBANDWIDTH, so3fftf_plan_memory(b, 0, 1), so3fft_plan_memory(b, 0, 1));
        wf[0] = SENTINEL_F;
        SAME_CODE(SO3FFT_EBANDWIDTH, so3fftf_weights(b, wf), so3fft_weights(b, wd));
        CHECK(wf[0] == SENTINEL_F);
    }
    /* the message names the bandwidth */
    CHECK(so3fftf_plan_both(-7, 0) == NULL);
    CHECK(strstr(so3fft_last_error(), "-7") != NULL);
    SAME_CODE(SO3FFT_ENULL, so3fftf_weights(4, NULL), so3fft_weights(4, NULL));
    SAME_CODE_ONLY(SO3FFT_EINVAL, so3fftf_weights(4, (float *)(void *)((char *)wf + 2)),
                   so3fft_weights(4, (double *)(void *)((char *)wd + 4)), "4 bytes");

    for (i = 0; i < sizeof bad_flags / sizeof bad_flags[0]; i++) {
        unsigned f = bad_flags[i];
        SAME_PLAN_FAILURE(SO3FFT_EINVAL, so3fftf_plan_forward(4, NULL, NULL, f),
                          so3fft_plan_forward(4, NULL, NULL, f));
        SAME_PLAN_FAILURE(SO3FFT_EINVAL, so3fftf_plan_both(4, SO3FFT_MEASURE | f),
                          so3fft_plan_both(4, SO3FFT_MEASURE | f));
        SAME_CODE(SO3FFT_EINVAL, so3fftf_plan_memory(8, f, 1), so3fft_plan_memory(8, f, 1));
    }
    SAME_PLAN_FAILURE(SO3FFT_EINVAL, so3fftf_plan_general(4, SO3FFT_BOTH, NULL, NULL, 0, -2),
                      so3fft_plan_general(4, SO3FFT_BOTH, NULL, NULL, 0, -2));
    SAME_PLAN_FAILURE(SO3FFT_EINVAL,
                      so3fftf_plan_general(4, SO3FFT_BOTH, NULL, NULL, 0, 1 << 20),
                      so3fft_plan_general(4, SO3FFT_BOTH, NULL, NULL, 0, 1 << 20));
    SAME_CODE(SO3FFT_EINVAL, so3fftf_plan_memory(8, 0, -1), so3fft_plan_memory(8, 0, -1));
    SAME_PLAN_FAILURE(SO3FFT_EINVAL, so3fftf_plan_general(4, 0, NULL, NULL, 0, 1),
                      so3fft_plan_general(4, 0, NULL, NULL, 0, 1));
    SAME_PLAN_FAILURE(SO3FFT_EINVAL, so3fftf_plan_general(4, 7, NULL, NULL, 0, 1),
                      so3fft_plan_general(4, 7, NULL, NULL, 0, 1));
    so3fftf_destroy_plan(NULL); /* no-op, not an error */
    CHECK_NO_ERR();
}

/* Arrays at planning and at execution, NULL plans, directions (test_errors.c). */
static void bad_arrays(void) {
    const int b = 4;
    size_t nc = so3fft_num_coeffs(b), ns = so3fft_num_samples(b);
    so3fftf_complex *s = alloc_cf(ns), *c = alloc_cf(nc + 1), *big = alloc_cf(ns + nc + 1);
    so3fft_complex *sd = alloc_cx(ns), *cd = alloc_cx(nc), *bigd = alloc_cx(ns + nc + 1);
    char *raw = (char *)malloc((nc + 1) * sizeof(so3fft_complex));
    so3fftf_complex *mis = (so3fftf_complex *)(void *)(raw + 1);
    so3fft_complex *misd = (so3fft_complex *)(void *)(raw + 4);
    so3fftf_plan pf, pi, pb, pf0;
    so3fft_plan qf, qi, qb, qf0;
    random_cf(s, NULL, ns, 1);
    random_cf(c, NULL, nc, 2);
    fill_random(sd, ns, 1);
    fill_random(cd, nc, 2);

    /* at planning: exactly one array NULL, arrays with SO3FFT_BOTH, overlap, misalignment */
    SAME_PLAN_FAILURE(SO3FFT_ENULL, so3fftf_plan_forward(b, s, NULL, 0),
                      so3fft_plan_forward(b, sd, NULL, 0));
    SAME_PLAN_FAILURE(SO3FFT_ENULL, so3fftf_plan_inverse(b, NULL, s, 0),
                      so3fft_plan_inverse(b, NULL, sd, 0));
    SAME_PLAN_FAILURE(SO3FFT_EINVAL, so3fftf_plan_general(b, SO3FFT_BOTH, s, c, 0, 1),
                      so3fft_plan_general(b, SO3FFT_BOTH, sd, cd, 0, 1));
    SAME_PLAN_FAILURE(SO3FFT_EINVAL, so3fftf_plan_forward(b, big, big + ns - 1, 0),
                      so3fft_plan_forward(b, bigd, bigd + ns - 1, 0));
    SAME_NULL(SO3FFT_EINVAL, so3fftf_plan, so3fftf_plan_inverse(b, mis, s, 0),
              so3fftf_destroy_plan, so3fft_plan, so3fft_plan_inverse(b, misd, sd, 0),
              so3fft_destroy_plan, 0);
    CHECK(so3fftf_plan_inverse(b, mis, s, 0) == NULL);
    CHECK(strstr(so3fft_last_error(), "4 bytes") != NULL);

    pf = so3fftf_plan_forward(b, s, c, 0), qf = so3fft_plan_forward(b, sd, cd, 0);
    pi = so3fftf_plan_inverse(b, c, s, 0), qi = so3fft_plan_inverse(b, cd, sd, 0);
    pb = so3fftf_plan_both(b, 0), qb = so3fft_plan_both(b, 0);
    pf0 = so3fftf_plan_forward(b, NULL, NULL, 0), qf0 = so3fft_plan_forward(b, NULL, NULL, 0);
    CHECK(pf && pi && pb && pf0 && qf && qi && qb && qf0);
    if (!(pf && pi && pb && pf0 && qf && qi && qb && qf0)) return;

    /* NULL plan */
    SAME_CODE(SO3FFT_ENULL, so3fftf_execute(NULL), so3fft_execute(NULL));
    SAME_CODE(SO3FFT_ENULL, so3fftf_execute_forward(NULL, s, c),
              so3fft_execute_forward(NULL, sd, cd));
    SAME_CODE(SO3FFT_ENULL, so3fftf_execute_inverse(NULL, c, s),
              so3fft_execute_inverse(NULL, cd, sd));
    SAME_CODE(SO3FFT_ENULL, so3fftf_get_bandwidth(NULL), so3fft_get_bandwidth(NULL));
    SAME_CODE(SO3FFT_ENULL, so3fftf_get_nthreads(NULL), so3fft_get_nthreads(NULL));
    SAME_CODE(SO3FFT_ENULL, so3fftf_get_fft_threading(NULL), so3fft_get_fft_threading(NULL));
    SAME_CODE(SO3FFT_ENULL, so3fftf_get_memory(NULL), so3fft_get_memory(NULL));

    /* so3fftf_execute on plans made without arrays: the message names the f32 functions */
    SAME_CODE_ONLY(SO3FFT_ENULL, so3fftf_execute(pb), so3fft_execute(qb),
                   "so3fftf_execute_forward");
    SAME_CODE_ONLY(SO3FFT_ENULL, so3fftf_execute(pf0), so3fft_execute(qf0),
                   "so3fftf_execute_inverse");

    /* NULL arrays in new-array execute; nothing written */
    fill_sentinel_f(&c[0][0], 2 * nc);
    SAME_CODE(SO3FFT_ENULL, so3fftf_execute_forward(pb, NULL, c),
              so3fft_execute_forward(qb, NULL, cd));
    SAME_CODE(SO3FFT_ENULL, so3fftf_execute_forward(pf0, s, NULL),
              so3fft_execute_forward(qf0, sd, NULL));
    SAME_CODE(SO3FFT_ENULL, so3fftf_execute_inverse(pb, NULL, s),
              so3fft_execute_inverse(qb, NULL, sd));
    CHECK(untouched_f(&c[0][0], 2 * nc));

    /* wrong direction; nothing written */
    fill_sentinel_f(&s[0][0], 2 * ns);
    SAME_CODE(SO3FFT_EDIRECTION, so3fftf_execute_inverse(pf, c, s),
              so3fft_execute_inverse(qf, cd, sd));
    CHECK(untouched_f(&s[0][0], 2 * ns));
    SAME_CODE(SO3FFT_EDIRECTION, so3fftf_execute_forward(pi, s, c),
              so3fft_execute_forward(qi, sd, cd));
    CHECK(untouched_f(&c[0][0], 2 * nc));
    SAME_CODE(SO3FFT_EDIRECTION, so3fftf_execute_inverse(pf0, c, s),
              so3fft_execute_inverse(qf0, cd, sd));

    /* overlapping and misaligned arrays in new-array execute; nothing written */
    SAME_CODE(SO3FFT_EINVAL, so3fftf_execute_forward(pb, big, big + 1),
              so3fft_execute_forward(qb, bigd, bigd + 1));
    SAME_CODE(SO3FFT_EINVAL, so3fftf_execute_inverse(pb, big + ns, big + 1),
              so3fft_execute_inverse(qb, bigd + ns, bigd + 1));
    SAME_CODE_ONLY(SO3FFT_EINVAL, so3fftf_execute_forward(pb, s, mis),
                   so3fft_execute_forward(qb, sd, misd), "4 bytes");
    SAME_CODE_ONLY(SO3FFT_EINVAL, so3fftf_execute_inverse(pb, mis, s),
                   so3fft_execute_inverse(qb, misd, sd), "4 bytes");
    CHECK(untouched_f(&s[0][0], 2 * ns));
    CHECK(untouched_f(&c[0][0], 2 * nc));

    /* adjacent (touching, not overlapping) arrays are fine, and 4-byte alignment suffices */
    random_cf(big, NULL, ns, 3);
    CHECK(so3fftf_execute_forward(pb, big, big + ns) == SO3FFT_OK);
    CHECK_NO_ERR();
    CHECK(so3fftf_execute_forward(pb, big, (so3fftf_complex *)(void *)((char *)c + 4)) ==
          SO3FFT_OK);
    CHECK_NO_ERR();
    /* and the plans still work after all these errors */
    random_cf(s, NULL, ns, 4);
    CHECK(so3fftf_execute(pf) == SO3FFT_OK);
    CHECK(so3fftf_execute(pi) == SO3FFT_OK);
    CHECK_NO_ERR();
    CHECK(guard_cf(s, ns) && guard_cf(c, nc + 1) && guard_cf(big, ns + nc + 1));

    so3fftf_destroy_plan(pf), so3fftf_destroy_plan(pi);
    so3fftf_destroy_plan(pb), so3fftf_destroy_plan(pf0);
    so3fft_destroy_plan(qf), so3fft_destroy_plan(qi);
    so3fft_destroy_plan(qb), so3fft_destroy_plan(qf0);
    free(s), free(c), free(big), free(sd), free(cd), free(bigd), free(raw);
}

/* Partial plans: shapes, options, batches, arrays (test_partial.c in both precisions). */
static void bad_partial(void) {
    so3fft_shape s = so3fft_shape_default(8), t;
    so3fft_partial_options o;
    so3fftf_partial pf, pfc;
    so3fft_partial pd, pdc;
    ptrdiff_t nc, ns;
    so3fftf_complex *c, *x;
    so3fft_complex *cd, *xd;
    float *r;
    double *rd;
    char *raw;
    int k = 99;

    SAME_PARTIAL_FAILURE(SO3FFT_ENULL, so3fftf_plan_partial(NULL, NULL, 0),
                         so3fft_plan_partial(NULL, NULL, 0));
    t = s;
    t.L0 = 8;
    SAME_PARTIAL_FAILURE(SO3FFT_EINVAL, so3fftf_plan_partial(&t, NULL, 0),
                         so3fft_plan_partial(&t, NULL, 0));
    t = s;
    t.m_max = 3;
    t.n_alpha = 6;
    SAME_PARTIAL_FAILURE(SO3FFT_EINVAL, so3fftf_plan_partial(&t, NULL, 0),
                         so3fft_plan_partial(&t, NULL, 0));
    t = s;
    t.B_grid = 6;
    SAME_PARTIAL_FAILURE(SO3FFT_EINVAL, so3fftf_plan_partial(&t, NULL, 0),
                         so3fft_plan_partial(&t, NULL, 0));
    t = so3fft_shape_default(0);
    SAME_PARTIAL_FAILURE(SO3FFT_EINVAL, so3fftf_plan_partial(&t, NULL, 0),
                         so3fft_plan_partial(&t, NULL, 0));
    memset(&o, 0, sizeof o);
    o.nbetas = 1;
    SAME_PARTIAL_FAILURE(SO3FFT_EINVAL, so3fftf_plan_partial(&s, &o, 0),
                         so3fft_plan_partial(&s, &o, 0));
    o.beta_indices = &k;
    SAME_PARTIAL_FAILURE(SO3FFT_EINVAL, so3fftf_plan_partial(&s, &o, 0),
                         so3fft_plan_partial(&s, &o, 0));
    k = 3;
    o.direction = SO3FFT_FORWARD;
    SAME_PARTIAL_FAILURE(SO3FFT_EINVAL, so3fftf_plan_partial(&s, &o, 0),
                         so3fft_plan_partial(&s, &o, 0));
    memset(&o, 0, sizeof o);
    o.nthreads = -2;
    SAME_PARTIAL_FAILURE(SO3FFT_EINVAL, so3fftf_plan_partial(&s, &o, 0),
                         so3fft_plan_partial(&s, &o, 0));
    o.nthreads = 0;
    o.direction = 9;
    SAME_PARTIAL_FAILURE(SO3FFT_EINVAL, so3fftf_plan_partial(&s, &o, 0),
                         so3fft_plan_partial(&s, &o, 0));
    o.direction = 0;
    SAME_PARTIAL_FAILURE(SO3FFT_EINVAL, so3fftf_plan_partial(&s, &o, SO3FFT_DESTROY_INPUT),
                         so3fft_plan_partial(&s, &o, SO3FFT_DESTROY_INPUT));
    SAME_PARTIAL_FAILURE(SO3FFT_EINVAL, so3fftf_plan_partial(&s, &o, 1u << 20),
                         so3fft_plan_partial(&s, &o, 1u << 20));

    /* NULL plan */
    SAME_CODE(SO3FFT_ENULL, so3fftf_partial_num_coeffs(NULL), so3fft_partial_num_coeffs(NULL));
    SAME_CODE(SO3FFT_ENULL, so3fftf_partial_num_samples(NULL),
              so3fft_partial_num_samples(NULL));
    SAME_CODE(SO3FFT_ENULL, so3fftf_partial_inverse(NULL, NULL, NULL),
              so3fft_partial_inverse(NULL, NULL, NULL));
    SAME_CODE(SO3FFT_ENULL, so3fftf_partial_forward_real_many(NULL, 1, NULL, 0, NULL, 0),
              so3fft_partial_forward_real_many(NULL, 1, NULL, 0, NULL, 0));
    so3fftf_destroy_partial(NULL);
    CHECK_NO_ERR();

    /* executes: a real plan and a complex one of each precision */
    s.m_max = 5;
    s.n_alpha = 11;
    pf = so3fftf_plan_partial(&s, NULL, SO3FFT_REAL);
    pd = so3fft_plan_partial(&s, NULL, SO3FFT_REAL);
    pfc = so3fftf_plan_partial(&s, NULL, 0);
    pdc = so3fft_plan_partial(&s, NULL, 0);
    CHECK(pf && pd && pfc && pdc);
    if (!(pf && pd && pfc && pdc)) return;
    nc = so3fftf_partial_num_coeffs(pf);
    ns = so3fftf_partial_num_samples(pf);
    c = alloc_cf(2 * (size_t)nc), x = alloc_cf(2 * (size_t)ns);
    cd = alloc_cx(2 * (size_t)nc), xd = alloc_cx(2 * (size_t)ns);
    r = alloc_f((size_t)ns), rd = alloc_d((size_t)ns);
    raw = (char *)malloc(((size_t)ns + 1) * sizeof(so3fft_complex));
    random_cf(c, cd, 2 * (size_t)nc, 7);
    fill_sentinel_f(&x[0][0], 4 * (size_t)ns);
    fill_sentinel_f(r, (size_t)ns);

    /* batches: howmany, distances, overlapping outputs */
    SAME_CODE(SO3FFT_EINVAL, so3fftf_partial_inverse_many(pf, 0, c, nc, x, ns),
              so3fft_partial_inverse_many(pd, 0, cd, nc, xd, ns));
    SAME_CODE(SO3FFT_EINVAL, so3fftf_partial_inverse_many(pf, 2, c, nc, x, ns - 1),
              so3fft_partial_inverse_many(pd, 2, cd, nc, xd, ns - 1));
    SAME_CODE(SO3FFT_EINVAL, so3fftf_partial_inverse_many(pf, 2, c, -1, x, ns),
              so3fft_partial_inverse_many(pd, 2, cd, -1, xd, ns));
    SAME_CODE(SO3FFT_EINVAL, so3fftf_partial_forward_many(pf, 2, x, ns, c, -3),
              so3fft_partial_forward_many(pd, 2, xd, ns, cd, -3));
    SAME_CODE(SO3FFT_EINVAL, so3fftf_partial_inverse_real_many(pf, -1, c, nc, r, ns),
              so3fft_partial_inverse_real_many(pd, -1, cd, nc, rd, ns));
    /* NULL, overlapping and misaligned arrays */
    SAME_CODE(SO3FFT_ENULL, so3fftf_partial_inverse(pf, NULL, x),
              so3fft_partial_inverse(pd, NULL, xd));
    SAME_CODE(SO3FFT_ENULL, so3fftf_partial_forward(pf, x, NULL),
              so3fft_partial_forward(pd, xd, NULL));
    SAME_CODE(SO3FFT_ENULL, so3fftf_partial_forward_real(pf, NULL, c),
              so3fft_partial_forward_real(pd, NULL, cd));
    SAME_CODE(SO3FFT_EINVAL, so3fftf_partial_forward(pf, x, x + 1),
              so3fft_partial_forward(pd, xd, xd + 1));
    SAME_CODE(SO3FFT_EINVAL,
              so3fftf_partial_inverse_real(pf, c, (float *)(void *)(c + 1)),
              so3fft_partial_inverse_real(pd, cd, (double *)(void *)(cd + 1)));
    SAME_CODE_ONLY(SO3FFT_EINVAL,
                   so3fftf_partial_inverse(pf, c, (so3fftf_complex *)(void *)(raw + 1)),
                   so3fft_partial_inverse(pd, cd, (so3fft_complex *)(void *)(raw + 4)),
                   "4 bytes");
    SAME_CODE_ONLY(SO3FFT_EINVAL,
                   so3fftf_partial_forward_real(pf, (float *)(void *)(raw + 2), c),
                   so3fft_partial_forward_real(pd, (double *)(void *)(raw + 4), cd), "4 bytes");
    /* real executes need a plan made with SO3FFT_REAL */
    SAME_CODE(SO3FFT_EINVAL, so3fftf_partial_inverse_real(pfc, c, r),
              so3fft_partial_inverse_real(pdc, cd, rd));
    SAME_CODE(SO3FFT_EINVAL, so3fftf_partial_forward_real_many(pfc, 1, r, 0, c, 0),
              so3fft_partial_forward_real_many(pdc, 1, rd, 0, cd, 0));
    CHECK(untouched_f(&x[0][0], 4 * (size_t)ns) && untouched_f(r, (size_t)ns));
    /* 4-byte alignment suffices for floats */
    CHECK(so3fftf_partial_inverse(pf, c, (so3fftf_complex *)(void *)((char *)x + 4)) ==
          SO3FFT_OK);
    CHECK(so3fftf_partial_inverse_real(pf, c, r) == SO3FFT_OK);
    CHECK_NO_ERR();
    CHECK(guard_cf(c, 2 * (size_t)nc) && guard_cf(x, 2 * (size_t)ns));
    CHECK(untouched_f(r + ns, GUARD));

    so3fftf_destroy_partial(pf), so3fftf_destroy_partial(pfc);
    so3fft_destroy_partial(pd), so3fft_destroy_partial(pdc);
    free(c), free(x), free(cd), free(xd), free(r), free(rd), free(raw);
}

int main(void) {
    static const int bandwidths[] = {1, 7, 16, 32};
    double worst = 0.0;
    size_t i;
    for (i = 0; i < sizeof bandwidths / sizeof bandwidths[0]; i++)
        round_trips(bandwidths[i], 1 + (int)(i % 2), &worst);
    arrays_and_settings();
    weights();
    partial_shape(&worst);
    partial_betas(&worst);
    printf("test_f32_so3: largest relative error (round trips, against f64): %.2g\n", worst);
    bad_plan_arguments();
    bad_arrays();
    bad_partial();
    return finish("test_f32_so3");
}
