/* Partial plans through the C API: limited shapes against the full plan with the absent
 * coefficients zeroed, round trips on odd and oversampled grids, batches against single
 * executes, beta selections against the full inverse's slices, real against complex, and
 * bad arguments. */
#include "test_util.h"

static const double PI_ = 3.14159265358979323846;

static int iabs_(int x) { return x < 0 ? -x : x; }

/* Limited shape on SOFT's grid == full plan with the absent coefficients zeroed. */
static void against_full_plan(void) {
    const int b = 10;
    so3fft_shape s = so3fft_shape_default(b);
    so3fft_plan full = so3fft_plan_both(b, SO3FFT_ESTIMATE);
    so3fft_partial p;
    ptrdiff_t nc, ns = (ptrdiff_t)so3fft_num_samples(b);
    so3fft_complex *c, *pad, *x, *y, *back;
    int l, m, mp;
    s.L0 = 2;
    s.m_max = 4;
    s.mp_max = 6;
    p = so3fft_plan_partial(&s, NULL, SO3FFT_ESTIMATE);
    CHECK(p != NULL && full != NULL);
    nc = so3fft_partial_num_coeffs(p);
    CHECK(nc == so3fft_shape_num_coeffs(&s) && nc > 0);
    CHECK(so3fft_partial_num_samples(p) == ns);
    c = alloc_cx((size_t)nc);
    back = alloc_cx((size_t)nc);
    pad = alloc_cx(so3fft_num_coeffs(b));
    x = alloc_cx((size_t)ns);
    y = alloc_cx((size_t)ns);
    fill_random(c, (size_t)nc, 5);
    memset(pad, 0, so3fft_num_coeffs(b) * sizeof *pad);
    for (l = s.L0; l < b; l++)
        for (m = -s.m_max; m <= s.m_max; m++)
            for (mp = -s.mp_max; mp <= s.mp_max; mp++) {
                ptrdiff_t i = so3fft_shape_coef_index(&s, l, m, mp);
                if (iabs_(m) > l || iabs_(mp) > l) {
                    CHECK(i < 0);
                    continue;
                }
                CHECK(i >= 0 && i < nc);
                if (i >= 0) {
                    pad[so3fft_coef_index(b, l, m, mp)][0] = c[i][0];
                    pad[so3fft_coef_index(b, l, m, mp)][1] = c[i][1];
                }
            }
    CHECK(so3fft_shape_coef_index(&s, 1, 0, 0) == SO3FFT_EINVAL);
    CHECK_ERR(SO3FFT_EINVAL);
    CHECK(so3fft_shape_coef_index(&s, 6, 5, 0) == SO3FFT_EINVAL);
    CHECK(so3fft_partial_inverse(p, c, x) == SO3FFT_OK);
    CHECK_NO_ERR();
    CHECK(so3fft_execute_inverse(full, pad, y) == SO3FFT_OK);
    CHECK(max_abs_diff(x, y, (size_t)ns) < 1e-12);
    CHECK(so3fft_partial_forward(p, x, back) == SO3FFT_OK);
    CHECK(max_abs_diff(back, c, (size_t)nc) < 1e-12);
    so3fft_destroy_partial(p);
    so3fft_destroy_plan(full);
    free(c);
    free(back);
    free(pad);
    free(x);
    free(y);
}

/* Odd and oversampled grids: round trips; batches bitwise equal to single executes; real
 * against complex. */
static void grids_batches_real(void) {
    so3fft_shape s = so3fft_shape_default(7);
    so3fft_partial_options o;
    so3fft_partial p;
    ptrdiff_t nc, ns, idist, odist;
    so3fft_complex *c, *x, *one, *back, *cb;
    double *re;
    int t, l, m, mp;
    const int count = 3;
    s.m_max = 4;
    s.mp_max = 3;
    s.B_grid = 9;
    s.n_alpha = 11;
    s.n_gamma = 7;
    CHECK(so3fft_shape_check(&s, SO3FFT_BOTH) == SO3FFT_OK);
    memset(&o, 0, sizeof o);
    o.nthreads = 2;
    p = so3fft_plan_partial(&s, &o, SO3FFT_ESTIMATE | SO3FFT_REAL);
    CHECK(p != NULL);
    nc = so3fft_partial_num_coeffs(p);
    ns = so3fft_partial_num_samples(p);
    CHECK(ns == 18 * 11 * 7 && ns == so3fft_shape_num_samples(&s));
    idist = nc + 3;
    odist = ns + 1;
    c = alloc_cx((size_t)(idist * count));
    cb = alloc_cx((size_t)(idist * count));
    x = alloc_cx((size_t)(odist * count));
    one = alloc_cx((size_t)ns);
    back = alloc_cx((size_t)nc);
    re = (double *)malloc((size_t)ns * sizeof(double));
    fill_random(c, (size_t)(idist * count), 9);
    CHECK(so3fft_partial_inverse_many(p, count, c, idist, x, odist) == SO3FFT_OK);
    CHECK(so3fft_partial_forward_many(p, count, x, odist, cb, idist) == SO3FFT_OK);
    for (t = 0; t < count; t++) {
        CHECK(so3fft_partial_inverse(p, c + t * idist, one) == SO3FFT_OK);
        CHECK(memcmp(one, x + t * odist, (size_t)ns * sizeof *one) == 0);
        CHECK(so3fft_partial_forward(p, one, back) == SO3FFT_OK);
        CHECK(memcmp(back, cb + t * idist, (size_t)nc * sizeof *back) == 0);
        CHECK(max_abs_diff(back, c + t * idist, (size_t)nc) < 1e-12);
    }
    /* A real signal's coefficients: fhat(l,-m,-mp) = (-1)^(m-mp) conj(fhat(l,m,mp)). */
    for (l = 0; l < s.L; l++)
        for (m = -s.m_max; m <= s.m_max; m++)
            for (mp = -s.mp_max; mp <= s.mp_max; mp++) {
                ptrdiff_t i = so3fft_shape_coef_index(&s, l, m, mp);
                ptrdiff_t j = so3fft_shape_coef_index(&s, l, -m, -mp);
                if (i < 0 || i > j) continue;
                if (i == j) {
                    c[i][1] = 0.0;
                } else {
                    double sg = ((m - mp) % 2 == 0) ? 1.0 : -1.0;
                    c[j][0] = sg * c[i][0];
                    c[j][1] = -sg * c[i][1];
                }
            }
    CHECK(so3fft_partial_inverse(p, c, one) == SO3FFT_OK);
    CHECK(so3fft_partial_inverse_real(p, c, re) == SO3FFT_OK);
    {
        double e = 0.0;
        ptrdiff_t i;
        for (i = 0; i < ns; i++) e = fmax(e, fmax(fabs(re[i] - one[i][0]), fabs(one[i][1])));
        CHECK(e < 1e-13);
    }
    CHECK(so3fft_partial_forward_real(p, re, back) == SO3FFT_OK);
    CHECK(max_abs_diff(back, c, (size_t)nc) < 1e-12);
    /* bad batches */
    CHECK(so3fft_partial_inverse_many(p, 0, c, idist, x, odist) == SO3FFT_EINVAL);
    CHECK(so3fft_partial_inverse_many(p, 2, c, idist, x, ns - 1) == SO3FFT_EINVAL);
    CHECK_ERR(SO3FFT_EINVAL);
    CHECK(so3fft_partial_inverse_many(p, 2, c, -1, x, odist) == SO3FFT_EINVAL);
    CHECK(so3fft_partial_forward(p, x, (so3fft_complex *)x) == SO3FFT_EINVAL);
    CHECK(so3fft_partial_inverse(p, NULL, x) == SO3FFT_ENULL);
    so3fft_destroy_partial(p);
    free(c);
    free(cb);
    free(x);
    free(one);
    free(back);
    free(re);
}

/* Inverse at selected betas == the full inverse's slices. */
static void selected_betas(void) {
    so3fft_shape s = so3fft_shape_default(8);
    so3fft_partial_options o;
    so3fft_partial all, sel;
    int ks[4] = {15, 0, 7, 9};
    int ks_single[3] = {2, 12, 5};
    double vals[2];
    ptrdiff_t nc, ns, sl;
    so3fft_complex *c, *x, *y;
    int i;
    s.m_max = 5;
    s.mp_max = 2;
    s.n_alpha = 12;
    s.n_gamma = 5;
    sl = 12 * 5;
    all = so3fft_plan_partial(&s, NULL, SO3FFT_ESTIMATE);
    memset(&o, 0, sizeof o);
    o.nbetas = 4;
    o.beta_indices = ks;
    sel = so3fft_plan_partial(&s, &o, SO3FFT_ESTIMATE);
    CHECK(all != NULL && sel != NULL);
    nc = so3fft_partial_num_coeffs(all);
    ns = so3fft_partial_num_samples(all);
    CHECK(so3fft_partial_num_samples(sel) == 4 * sl);
    c = alloc_cx((size_t)nc);
    x = alloc_cx((size_t)ns);
    y = alloc_cx((size_t)(4 * sl));
    fill_random(c, (size_t)nc, 4);
    CHECK(so3fft_partial_inverse(all, c, x) == SO3FFT_OK);
    CHECK(so3fft_partial_inverse(sel, c, y) == SO3FFT_OK);
    for (i = 0; i < 4; i++) CHECK(max_abs_diff(y + i * sl, x + ks[i] * sl, (size_t)sl) < 1e-13);
    /* a selection plan runs the inverse only */
    CHECK(so3fft_partial_forward(sel, y, c) == SO3FFT_EDIRECTION);
    so3fft_destroy_partial(sel);
    /* no beta with its mirror (the kernels then run each member at its own point only) */
    o.nbetas = 3;
    o.beta_indices = ks_single;
    sel = so3fft_plan_partial(&s, &o, SO3FFT_ESTIMATE);
    CHECK(sel != NULL);
    CHECK(so3fft_partial_num_samples(sel) == 3 * sl);
    CHECK(so3fft_partial_inverse(sel, c, y) == SO3FFT_OK);
    for (i = 0; i < 3; i++)
        CHECK(max_abs_diff(y + i * sl, x + ks_single[i] * sl, (size_t)sl) < 1e-13);
    so3fft_destroy_partial(sel);
    /* beta values: the grid's own values give the same slices */
    vals[0] = PI_ * (2 * 3 + 1) / (4.0 * 8);
    vals[1] = PI_ * (2 * 12 + 1) / (4.0 * 8);
    o.nbetas = 2;
    o.beta_indices = NULL;
    o.beta_values = vals;
    sel = so3fft_plan_partial(&s, &o, SO3FFT_ESTIMATE);
    CHECK(sel != NULL);
    CHECK(so3fft_partial_inverse(sel, c, y) == SO3FFT_OK);
    CHECK(max_abs_diff(y, x + 3 * sl, (size_t)sl) < 1e-12);
    CHECK(max_abs_diff(y + sl, x + 12 * sl, (size_t)sl) < 1e-12);
    so3fft_destroy_partial(sel);
    so3fft_destroy_partial(all);
    free(c);
    free(x);
    free(y);
}

static void bad_shapes(void) {
    so3fft_shape s = so3fft_shape_default(8), t;
    so3fft_partial_options o;
    int k = 99;
    CHECK(so3fft_plan_partial(NULL, NULL, 0) == NULL);
    CHECK_ERR(SO3FFT_ENULL);
    t = s;
    t.L0 = 8;
    CHECK(so3fft_plan_partial(&t, NULL, 0) == NULL);
    CHECK_ERR(SO3FFT_EINVAL);
    CHECK(strstr(so3fft_last_error(), "L0") != NULL);
    t = s;
    t.m_max = 3;
    t.n_alpha = 6;
    CHECK(so3fft_shape_check(&t, SO3FFT_INVERSE) == SO3FFT_EINVAL);
    CHECK(strstr(so3fft_last_error(), "n_alpha") != NULL);
    t = s;
    t.B_grid = 6;
    CHECK(so3fft_shape_check(&t, SO3FFT_INVERSE) == SO3FFT_OK);
    CHECK(so3fft_shape_check(&t, SO3FFT_FORWARD) == SO3FFT_EINVAL);
    CHECK(strstr(so3fft_last_error(), "B_grid >= L") != NULL);
    t = s;
    t.n_gamma = -1;
    CHECK(so3fft_shape_num_coeffs(&t) == SO3FFT_EINVAL);
    CHECK(so3fft_shape_check(&s, 7) == SO3FFT_EINVAL);
    t = so3fft_shape_default(0);
    CHECK(t.L == 0);
    CHECK(so3fft_plan_partial(&t, NULL, 0) == NULL);
    memset(&o, 0, sizeof o);
    o.nbetas = 1;
    CHECK(so3fft_plan_partial(&s, &o, 0) == NULL);
    CHECK_ERR(SO3FFT_EINVAL);
    o.beta_indices = &k;
    CHECK(so3fft_plan_partial(&s, &o, 0) == NULL);
    CHECK(strstr(so3fft_last_error(), "outside the grid") != NULL);
    o.nbetas = 0;
    o.nthreads = -2;
    CHECK(so3fft_plan_partial(&s, &o, 0) == NULL);
    o.nthreads = 0;
    CHECK(so3fft_plan_partial(&s, &o, SO3FFT_DESTROY_INPUT) == NULL);
    CHECK(so3fft_plan_partial(&s, &o, 1u << 20) == NULL);
    CHECK(so3fft_partial_num_coeffs(NULL) == SO3FFT_ENULL);
    CHECK(so3fft_partial_inverse(NULL, NULL, NULL) == SO3FFT_ENULL);
    so3fft_destroy_partial(NULL);
}

int main(void) {
    against_full_plan();
    grids_batches_real();
    selected_betas();
    bad_shapes();
    return finish("test_partial");
}
