/* Round trips, new-array execute, several plans alive at once, helpers, flags, alignment,
 * C99 double _Complex interoperability -- all through the C API. */
#include <complex.h>
#include <stdint.h>

#include "test_util.h"

#define TEST_PI 3.14159265358979323846

/* inverse then forward must give the coefficients back */
static void roundtrip(int B, unsigned flags, int nthreads) {
    size_t nc = so3fft_num_coeffs(B), ns = so3fft_num_samples(B);
    so3fft_complex *c = alloc_cx(nc), *c0 = alloc_cx(nc), *s = alloc_cx(ns), *back = alloc_cx(nc);
    so3fft_plan p = so3fft_plan_general(B, SO3FFT_BOTH, NULL, NULL, flags, nthreads);
    double e;
    fill_random(c, nc, 1000u + (unsigned)B);
    memcpy(c0, c, nc * sizeof *c);
    CHECK(p != NULL);
    if (p) {
        CHECK(so3fft_get_bandwidth(p) == B);
        if (nthreads > 0) CHECK(so3fft_get_nthreads(p) == nthreads);
        CHECK(so3fft_get_nthreads(p) >= 1);
        /* One thread or no measuring: slices across workers; else either variant. */
        if (nthreads == 1 || !(flags & (SO3FFT_MEASURE | SO3FFT_PATIENT | SO3FFT_EXHAUSTIVE)))
            CHECK(so3fft_get_fft_threading(p) == SO3FFT_FFT_SLICES_ACROSS_WORKERS);
        else
            CHECK(so3fft_get_fft_threading(p) == SO3FFT_FFT_SLICES_ACROSS_WORKERS ||
                  so3fft_get_fft_threading(p) == SO3FFT_FFT_FFTW_THREADS);
        CHECK(so3fft_execute_inverse(p, c, s) == SO3FFT_OK);
        CHECK(memcmp(c, c0, nc * sizeof *c) == 0); /* input untouched */
        CHECK(so3fft_execute_forward(p, s, back) == SO3FFT_OK);
        e = max_abs_diff(back, c, nc);
        printf("roundtrip B=%d flags=0x%x threads=%d: max error %.3g\n", B, flags, nthreads, e);
        CHECK(e <= 1e-12);
    }
    so3fft_destroy_plan(p);
    free(c);
    free(c0);
    free(s);
    free(back);
}

static void helpers(void) {
    double w[2 * 64], sum = 0.0;
    int k;
    CHECK(so3fft_num_samples(1) == 8);
    CHECK(so3fft_num_coeffs(1) == 1);
    CHECK(so3fft_num_samples(256) == (size_t)512 * 512 * 512);
    CHECK(so3fft_num_coeffs(256) == 22369536u);
    CHECK(so3fft_num_coeffs(SO3FFT_MAX_BANDWIDTH) > 0);
    CHECK_NO_ERR();
    /* spot values of docs/conventions.md, coefficient layout (B = 256) */
    CHECK(so3fft_coef_index(256, 0, 0, 0) == 0);
    CHECK(so3fft_coef_index(256, 255, 0, 0) == 255);
    CHECK(so3fft_coef_index(256, 1, 0, 1) == 256);
    CHECK(so3fft_coef_index(256, 1, 0, -1) == 65281);
    CHECK(so3fft_coef_index(256, 1, 1, 0) == 65536);
    CHECK(so3fft_coef_index(256, 1, -1, 0) == 22304001);
    CHECK(so3fft_coef_index(256, 255, -1, -1) == 22369535);
    CHECK(so3fft_sample_index(4, 1, 2, 3) == 2 * 64 + 1 * 8 + 3);
    CHECK(so3fft_sample_index(4, 7, 7, 7) == 511);
    CHECK(fabs(so3fft_alpha(4, 3) - 3.0 * TEST_PI / 4.0) < 1e-15);
    CHECK(fabs(so3fft_beta(4, 3) - 7.0 * TEST_PI / 16.0) < 1e-15);
    CHECK(fabs(so3fft_gamma(4, 5) - 5.0 * TEST_PI / 4.0) < 1e-15);
    CHECK_NO_ERR();
    /* the weights integrate sin(beta) dbeta exactly: sum = 2 */
    w[2 * 64 - 1] = -12345.0;
    CHECK(so3fft_weights(63, w) == SO3FFT_OK);
    CHECK(w[2 * 64 - 1] == -12345.0); /* nothing written beyond 2B */
    for (k = 0; k < 2 * 63; k++) sum += w[k];
    CHECK(fabs(sum - 2.0) < 1e-13);
    CHECK(strcmp(so3fft_version(), SO3FFT_VERSION) == 0);
    CHECK(so3fft_max_bandwidth() == SO3FFT_MAX_BANDWIDTH);
    CHECK(strcmp(so3fft_strerror(SO3FFT_OK), "success") == 0);
    CHECK(strlen(so3fft_strerror(SO3FFT_ENOMEM)) > 0);
    CHECK(strlen(so3fft_strerror(12345)) > 0);
}

/* Arrays with the alignment of double only (not 16 bytes), and C99 double complex. */
static void alignment_and_c99_complex(void) {
    const int B = 5;
    size_t nc = so3fft_num_coeffs(B), ns = so3fft_num_samples(B), i;
    double *cbuf = (double *)malloc((2 * nc + 1) * sizeof(double));
    double *sbuf = (double *)malloc((2 * ns + 1) * sizeof(double));
    double complex *cz = (double complex *)malloc(nc * sizeof(double complex));
    double complex *sz = (double complex *)malloc(ns * sizeof(double complex));
    so3fft_complex *c8 = (so3fft_complex *)(cbuf + 1), *s8 = (so3fft_complex *)(sbuf + 1);
    so3fft_complex *ref = alloc_cx(ns);
    so3fft_plan p = so3fft_plan_both(B, SO3FFT_ESTIMATE);
    CHECK(cbuf && sbuf && cz && sz && p);
    if (!(cbuf && sbuf && cz && sz && p)) return;
    CHECK(((uintptr_t)c8 % 16) == 8 || ((uintptr_t)c8 % 16) == 0);
    fill_random(c8, nc, 77);
    for (i = 0; i < nc; i++) cz[i] = c8[i][0] + I * c8[i][1];
    /* reference from 16-byte aligned malloc memory */
    {
        so3fft_complex *ca = alloc_cx(nc);
        memcpy(ca, c8, nc * sizeof *ca);
        CHECK(so3fft_execute_inverse(p, ca, ref) == SO3FFT_OK);
        free(ca);
    }
    CHECK(so3fft_execute_inverse(p, c8, s8) == SO3FFT_OK);
    CHECK(max_abs_diff(s8, ref, ns) <= 1e-14);
    CHECK(so3fft_execute_inverse(p, (so3fft_complex *)cz, (so3fft_complex *)sz) == SO3FFT_OK);
    CHECK(max_abs_diff((so3fft_complex *)sz, ref, ns) <= 1e-14);
    CHECK(so3fft_execute_forward(p, (so3fft_complex *)sz, (so3fft_complex *)cz) == SO3FFT_OK);
    {
        double e = 0.0;
        for (i = 0; i < nc; i++) {
            double d = cabs(cz[i] - (c8[i][0] + I * c8[i][1]));
            if (!(d <= e)) e = d;
        }
        printf("double complex round trip B=%d: max error %.3g\n", B, e);
        CHECK(e <= 1e-12);
    }
    so3fft_destroy_plan(p);
    free(cbuf);
    free(sbuf);
    free(cz);
    free(sz);
    free(ref);
}

/* Several plans alive at once, executed in interleaved order, with and without arrays. */
static void several_plans(void) {
    enum { NP = 4 };
    int Bs[NP] = {3, 4, 6, 4}, i, rep;
    so3fft_plan inv[NP], fwd[NP];
    so3fft_complex *c[NP], *s[NP], *back[NP];
    for (i = 0; i < NP; i++) {
        size_t nc = so3fft_num_coeffs(Bs[i]), ns = so3fft_num_samples(Bs[i]);
        c[i] = alloc_cx(nc);
        s[i] = alloc_cx(ns);
        back[i] = alloc_cx(nc);
        fill_random(c[i], nc, 500u + (unsigned)i);
        inv[i] = so3fft_plan_inverse(Bs[i], c[i], s[i], i % 2 ? SO3FFT_MEASURE : 0);
        fwd[i] = i % 2 ? so3fft_plan_forward(Bs[i], NULL, NULL, SO3FFT_DESTROY_INPUT)
                       : so3fft_plan_forward(Bs[i], s[i], back[i], SO3FFT_ESTIMATE);
        CHECK(inv[i] && fwd[i]);
    }
    for (rep = 0; rep < 2; rep++) {
        for (i = NP - 1; i >= 0; i--) {
            CHECK(so3fft_execute(inv[i]) == SO3FFT_OK);
        }
        for (i = 0; i < NP; i++) {
            memset(back[i], 0, so3fft_num_coeffs(Bs[i]) * sizeof(so3fft_complex));
            if (i % 2) {
                CHECK(so3fft_execute_forward(fwd[i], s[i], back[i]) == SO3FFT_OK);
            } else {
                CHECK(so3fft_execute(fwd[i]) == SO3FFT_OK);
            }
            CHECK(max_abs_diff(back[i], c[i], so3fft_num_coeffs(Bs[i])) <= 1e-12);
        }
    }
    for (i = 0; i < NP; i++) {
        so3fft_destroy_plan(inv[i]);
        so3fft_destroy_plan(fwd[i]);
        free(c[i]);
        free(s[i]);
        free(back[i]);
    }
}

/* Random coefficients of a real signal: f^l_{-m,-m'} = (-1)^(m-m') conj(f^l_{m,m'}). */
static void fill_real_coeffs(so3fft_complex *c, int B, unsigned long long seed) {
    int l, m, mp;
    memset(c, 0, so3fft_num_coeffs(B) * sizeof *c);
    for (l = 0; l < B; l++)
        for (m = -l; m <= l; m++)
            for (mp = -l; mp <= l; mp++) {
                ptrdiff_t k = so3fft_coef_index(B, l, m, mp), kk = so3fft_coef_index(B, l, -m, -mp);
                double sign = ((m - mp) % 2) ? -1.0 : 1.0;
                if (k > kk) continue;
                c[k][0] = rnd(&seed);
                c[k][1] = k == kk ? 0.0 : rnd(&seed);
                c[kk][0] = sign * c[k][0];
                c[kk][1] = -sign * c[k][1];
            }
}

/* Real-valued signal: the inverse of coefficients with the real symmetry is real. */
static void real_signal(void) {
    const int B = 6;
    size_t nc = so3fft_num_coeffs(B), ns = so3fft_num_samples(B), i;
    so3fft_complex *c = alloc_cx(nc), *s = alloc_cx(ns), *back = alloc_cx(nc);
    int l, m, mp;
    double im = 0.0;
    so3fft_plan p = so3fft_plan_both(B, SO3FFT_REAL);
    fill_real_coeffs(c, B, 99);
    CHECK(p != NULL);
    if (p) {
        so3fft_complex *poisoned = alloc_cx(nc), *s2 = alloc_cx(ns);
        CHECK(so3fft_execute_inverse(p, c, s) == SO3FFT_OK);
        for (i = 0; i < ns; i++) im = fmax(im, fabs(s[i][1]));
        printf("real signal B=%d: max |imag| %.3g\n", B, im);
        CHECK(im == 0.0); /* the real path writes exact zeros */
        CHECK(so3fft_execute_forward(p, s, back) == SO3FFT_OK);
        CHECK(max_abs_diff(back, c, nc) <= 1e-12);
        /* The inverse reads only blocks with m' > 0, or m' = 0 and m >= 0: NaN elsewhere
         * must not reach the samples. */
        memcpy(poisoned, c, nc * sizeof *c);
        for (l = 0; l < B; l++)
            for (m = -l; m <= l; m++)
                for (mp = -l; mp <= l; mp++)
                    if (!(mp > 0 || (mp == 0 && m >= 0))) {
                        ptrdiff_t k = so3fft_coef_index(B, l, m, mp);
                        poisoned[k][0] = poisoned[k][1] = NAN;
                    }
        CHECK(so3fft_execute_inverse(p, poisoned, s2) == SO3FFT_OK);
        CHECK(memcmp(s, s2, ns * sizeof *s) == 0);
        free(poisoned);
        free(s2);
    }
    so3fft_destroy_plan(p);
    free(c);
    free(s);
    free(back);
}

/* The planning-time memory estimate is what the plan then holds, and covers at least one
   chunk of the transformed beta slices; B = 2048 is only estimated (about a gigabyte). */
static void memory_estimate(void) {
    const int Bs[] = {1, 5, 16, 33};
    size_t i;
    for (i = 0; i < sizeof Bs / sizeof Bs[0]; i++) {
        int B = Bs[i];
        unsigned flags;
        for (flags = 0; flags <= SO3FFT_REAL; flags += SO3FFT_REAL) {
            ptrdiff_t est = so3fft_plan_memory(B, flags, 2);
            so3fft_plan p = so3fft_plan_general(B, SO3FFT_BOTH, NULL, NULL, flags, 2);
            CHECK(p != NULL);
            CHECK(est > 0);
            CHECK(so3fft_get_memory(p) == est);
            /* at least one beta pair of in-band values (16 bytes each) */
            CHECK((size_t)est >= 2 * (size_t)(2 * B - 1) * (size_t)(2 * B - 1) * 16 / 2);
            so3fft_destroy_plan(p);
        }
    }
    CHECK(so3fft_plan_memory(2048, 0, 2) > 0);
    CHECK_NO_ERR();
}

/* A workspace cap of 1 byte gives the smallest chunks (8 beta pairs, 5 chunks at B = 36):
 * the transforms then run chunk groups that keep their buffers in the caller's arrays
 * (inverse: in output slices not yet written; forward with SO3FFT_DESTROY_INPUT: in input
 * slices already read, complex and real alike chained in one group; the Rust unit tests
 * chunk_groups_keep_clear_of_written_slices and real_parts_forward_chains_and_matches
 * check that this B and cap form such groups). The round trip must still give the
 * coefficients back, complex and real, and the forward without the flag must leave its
 * input alone. */
static void capped_workspace(void) {
    const int B = 36;
    size_t nc = so3fft_num_coeffs(B), ns = so3fft_num_samples(B);
    so3fft_complex *c = alloc_cx(nc), *s = alloc_cx(ns), *s0 = alloc_cx(ns), *back = alloc_cx(nc);
    unsigned k;
    ptrdiff_t est_default = so3fft_plan_memory(B, 0, 1), est_capped;
    CHECK(so3fft_planner_max_workspace() == 0);
    CHECK(so3fft_plan_with_max_workspace(1) == SO3FFT_OK);
    CHECK(so3fft_planner_max_workspace() == 1);
    est_capped = so3fft_plan_memory(B, 0, 1);
    printf("capped workspace B=%d: plan memory %ld bytes (default %ld)\n", B, (long)est_capped,
           (long)est_default);
    CHECK(est_capped > 0 && est_capped < est_default);
    for (k = 0; k < 4; k++) {
        unsigned flags = (k & 1 ? SO3FFT_DESTROY_INPUT : 0u) | (k & 2 ? SO3FFT_REAL : 0u);
        so3fft_plan p = so3fft_plan_general(B, SO3FFT_BOTH, NULL, NULL, flags, k == 3 ? 2 : 1);
        double e;
        CHECK(p != NULL);
        if (!p) continue;
        CHECK(so3fft_get_memory(p) == so3fft_plan_memory(B, flags, k == 3 ? 2 : 1));
        if (flags & SO3FFT_REAL)
            fill_real_coeffs(c, B, 500u + k);
        else
            fill_random(c, nc, 500u + k);
        CHECK(so3fft_execute_inverse(p, c, s) == SO3FFT_OK);
        memcpy(s0, s, ns * sizeof *s);
        CHECK(so3fft_execute_forward(p, s, back) == SO3FFT_OK);
        e = max_abs_diff(back, c, nc);
        printf("capped workspace B=%d flags=0x%x: round-trip error %.3g\n", B, flags, e);
        CHECK(e <= 1e-12);
        if (!(flags & SO3FFT_DESTROY_INPUT)) CHECK(memcmp(s, s0, ns * sizeof *s) == 0);
        so3fft_destroy_plan(p);
    }
    CHECK(so3fft_plan_with_max_workspace(0) == SO3FFT_OK);
    CHECK(so3fft_planner_max_workspace() == 0);
    CHECK(so3fft_plan_memory(B, 0, 1) == est_default);
    CHECK_NO_ERR();
    free(c);
    free(s);
    free(s0);
    free(back);
}

static void threads_setting(void) {
    so3fft_plan p;
    CHECK(so3fft_planner_nthreads() == 0);
    CHECK(so3fft_plan_with_nthreads(1) == SO3FFT_OK);
    CHECK(so3fft_planner_nthreads() == 1);
    p = so3fft_plan_both(3, 0);
    CHECK(p && so3fft_get_nthreads(p) == 1);
    so3fft_destroy_plan(p);
    CHECK(so3fft_plan_with_nthreads(0) == SO3FFT_OK);
    p = so3fft_plan_both(3, 0);
    CHECK(p && so3fft_get_nthreads(p) >= 1);
    so3fft_destroy_plan(p);
}

int main(void) {
    int B;
    helpers();
    for (B = 1; B <= 8; B++) roundtrip(B, SO3FFT_ESTIMATE, 0);
    roundtrip(16, SO3FFT_MEASURE, 2);
    roundtrip(12, SO3FFT_PATIENT | SO3FFT_DESTROY_INPUT, 1);
    roundtrip(2, SO3FFT_EXHAUSTIVE, 2); /* SO3FFT_REAL needs real data: see real_signal() */
    alignment_and_c99_complex();
    several_plans();
    real_signal();
    memory_estimate();
    capped_workspace();
    threads_setting();
    return finish("test_roundtrip");
}
