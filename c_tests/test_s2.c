/* The S^2 transforms through the C API: closed-form harmonics, round trips (complex and
 * real), the index against SOFT's seanindex formula, and bad arguments. */
#include "test_util.h"

static const double PI_ = 3.14159265358979323846;

/* Y_1^0 and Y_1^1 in closed form (orthonormal, Condon-Shortley phase). */
static void y1(int m, double theta, double phi, double *re, double *im) {
    if (m == 0) {
        *re = sqrt(3.0 / (4.0 * PI_)) * cos(theta);
        *im = 0.0;
    } else {
        double a = -sqrt(3.0 / (8.0 * PI_)) * sin(theta);
        *re = a * cos(phi);
        *im = a * sin(phi);
    }
}

static long seanindex_formula(int m, int l, int b) {
    long L = b - 1, a = m < 0 ? -m : m;
    if (m >= 0) return (long)m * b - (long)m * (m - 1) / 2 + (l - m);
    return L * (L + 3) / 2 + 1 + (L - a) * (L - a + 1) / 2 + (l - a);
}

int main(void) {
    const int b = 16, n = 2 * b;
    size_t ns = so3fft_s2_num_samples(b), nc = so3fft_s2_num_coeffs(b), i;
    so3fft_s2_plan p = so3fft_plan_s2(b, SO3FFT_ESTIMATE, 2);
    so3fft_complex *c = alloc_cx(nc), *c2 = alloc_cx(nc), *s = alloc_cx(ns);
    double *r = (double *)malloc(ns * sizeof(double));
    int m, l, j, k;
    CHECK(p != NULL && r != NULL);
    CHECK(ns == (size_t)(n * n) && nc == (size_t)(b * b));
    CHECK(so3fft_s2_get_bandwidth(p) == b);

    /* single coefficients give the closed-form harmonics */
    for (m = 0; m <= 1; m++) {
        double err = 0.0;
        memset(c, 0, nc * sizeof *c);
        c[so3fft_s2_coef_index(b, 1, m)][0] = 1.0;
        CHECK(so3fft_s2_execute_inverse(p, c, s) == SO3FFT_OK);
        for (j = 0; j < n; j++) {
            for (k = 0; k < n; k++) {
                double re, im, theta = PI_ * (2 * j + 1) / (4.0 * b), phi = PI_ * k / b;
                y1(m, theta, phi, &re, &im);
                err = fmax(err, hypot(s[j * n + k][0] - re, s[j * n + k][1] - im));
            }
        }
        CHECK(err < 1e-14);
    }

    /* round trips */
    fill_random(c, nc, 3);
    CHECK(so3fft_s2_execute_inverse(p, c, s) == SO3FFT_OK);
    CHECK(so3fft_s2_execute_forward(p, s, c2) == SO3FFT_OK);
    CHECK(max_abs_diff(c, c2, nc) < 1e-13);
    /* a real function's coefficients: fhat(l,-m) = (-1)^m conj(fhat(l,m)), fhat(l,0) real */
    for (l = 0; l < b; l++) {
        c[so3fft_s2_coef_index(b, l, 0)][1] = 0.0;
        for (m = 1; m <= l; m++) {
            ptrdiff_t pos = so3fft_s2_coef_index(b, l, m), neg = so3fft_s2_coef_index(b, l, -m);
            double sg = (m % 2) ? -1.0 : 1.0;
            c[neg][0] = sg * c[pos][0];
            c[neg][1] = -sg * c[pos][1];
        }
    }
    CHECK(so3fft_s2_execute_inverse_real(p, c, r) == SO3FFT_OK);
    CHECK(so3fft_s2_execute_inverse(p, c, s) == SO3FFT_OK);
    for (i = 0; i < ns; i++) CHECK(fabs(s[i][0] - r[i]) < 1e-13 && fabs(s[i][1]) < 1e-13);
    CHECK(so3fft_s2_execute_forward_real(p, r, c2) == SO3FFT_OK);
    CHECK(max_abs_diff(c, c2, nc) < 1e-13);

    /* two real fields in one call: bitwise the same as one at a time */
    {
        so3fft_complex *c3 = alloc_cx(2 * nc);
        double *r2 = (double *)malloc(2 * ns * sizeof(double));
        CHECK(r2 != NULL);
        memcpy(r2, r, ns * sizeof(double));
        for (i = 0; i < ns; i++) r2[ns + i] = 0.5 * r[ns - 1 - i];
        CHECK(so3fft_s2_execute_forward_real_many(p, 2, r2, c3) == SO3FFT_OK);
        CHECK(memcmp(c3, c2, nc * sizeof *c2) == 0);
        CHECK(so3fft_s2_execute_forward_real(p, r2 + ns, c2) == SO3FFT_OK);
        CHECK(memcmp(c3 + nc, c2, nc * sizeof *c2) == 0);
        CHECK(so3fft_s2_execute_inverse_real_many(p, 0, c3, r2) == SO3FFT_EINVAL);
        CHECK_ERR(SO3FFT_EINVAL);
        {
            so3fft_complex *s2 = alloc_cx(2 * ns);
            CHECK(so3fft_s2_execute_inverse_many(p, 2, c3, s2) == SO3FFT_OK);
            CHECK(so3fft_s2_execute_inverse(p, c3 + nc, s) == SO3FFT_OK);
            CHECK(memcmp(s2 + ns, s, ns * sizeof *s) == 0);
            free(s2);
        }
        free(c3);
        free(r2);
    }

    /* a limited plan: degrees < 9, orders |m| <= 3; the other coefficients come out 0 and the
     * kept ones as from the full plan */
    {
        so3fft_s2_plan q = so3fft_plan_s2_limited(b, 9, 3, SO3FFT_ESTIMATE, 1);
        so3fft_complex *c3 = alloc_cx(nc);
        CHECK(q != NULL);
        fill_random((so3fft_complex *)s, ns, 17);
        CHECK(so3fft_s2_execute_forward(q, s, c3) == SO3FFT_OK);
        CHECK(so3fft_s2_execute_forward(p, s, c2) == SO3FFT_OK);
        for (l = 0; l < b; l++)
            for (m = -l; m <= l; m++) {
                ptrdiff_t at = so3fft_s2_coef_index(b, l, m);
                if (l < 9 && m >= -3 && m <= 3)
                    CHECK(hypot(c3[at][0] - c2[at][0], c3[at][1] - c2[at][1]) < 1e-13);
                else
                    CHECK(c3[at][0] == 0.0 && c3[at][1] == 0.0);
            }
        CHECK(so3fft_plan_s2_limited(b, 0, 3, SO3FFT_ESTIMATE, 1) == NULL);
        CHECK_ERR(SO3FFT_EINVAL);
        CHECK(so3fft_plan_s2_limited(b, b + 1, 3, SO3FFT_ESTIMATE, 1) == NULL);
        CHECK(so3fft_plan_s2_limited(b, 4, -1, SO3FFT_ESTIMATE, 1) == NULL);
        CHECK_ERR(SO3FFT_EINVAL);
        so3fft_destroy_s2_plan(q);
        free(c3);
    }

    /* the index is seanindex */
    for (m = -(b - 1); m < b; m++)
        for (l = m < 0 ? -m : m; l < b; l++)
            CHECK(so3fft_s2_coef_index(b, l, m) == seanindex_formula(m, l, b));
    CHECK(so3fft_s2_coef_index(b, b, 0) == -1);
    CHECK_ERR(SO3FFT_EINVAL);
    CHECK(so3fft_s2_coef_index(b, 2, 3) == -1);

    /* bad arguments: an error code and a message, nothing written */
    CHECK(so3fft_plan_s2(0, SO3FFT_ESTIMATE, 1) == NULL);
    CHECK_ERR(SO3FFT_EBANDWIDTH);
    CHECK(so3fft_plan_s2(SO3FFT_S2_MAX_BANDWIDTH + 1, SO3FFT_ESTIMATE, 1) == NULL);
    CHECK_ERR(SO3FFT_EBANDWIDTH);
    CHECK(so3fft_plan_s2(8, SO3FFT_REAL, 1) == NULL);
    CHECK_ERR(SO3FFT_EINVAL);
    CHECK(so3fft_plan_s2(8, SO3FFT_ESTIMATE, -1) == NULL);
    CHECK_ERR(SO3FFT_EINVAL);
    CHECK(so3fft_s2_execute_forward(NULL, s, c) == SO3FFT_ENULL);
    CHECK_ERR(SO3FFT_ENULL);
    CHECK(so3fft_s2_execute_forward(p, NULL, c) == SO3FFT_ENULL);
    memcpy(c2, c, nc * sizeof *c);
    CHECK(so3fft_s2_execute_forward(p, s, (so3fft_complex *)s + 3) == SO3FFT_EINVAL);
    CHECK_ERR(SO3FFT_EINVAL);
    CHECK(so3fft_s2_execute_inverse(p, c, (so3fft_complex *)((char *)s + 4)) == SO3FFT_EINVAL);
    CHECK(memcmp(c, c2, nc * sizeof *c) == 0);
    CHECK(so3fft_s2_get_bandwidth(NULL) == SO3FFT_ENULL);
    so3fft_destroy_s2_plan(NULL);

    so3fft_destroy_s2_plan(p);
    free(c);
    free(c2);
    free(s);
    free(r);
    return finish("test_s2");
}
