/* Every documented error path returns its error code and a non-empty message, writes
 * nothing, and leaves the library usable; successful calls clear the error state. */
#include <stdint.h>

#include "test_util.h"

#define SENTINEL 4242.0

static void fill_sentinel(so3fft_complex *a, size_t n) {
    size_t i;
    for (i = 0; i < n; i++) a[i][0] = a[i][1] = SENTINEL;
}

static int untouched(so3fft_complex *a, size_t n) {
    size_t i;
    for (i = 0; i < n; i++)
        if (a[i][0] != SENTINEL || a[i][1] != SENTINEL) return 0;
    return 1;
}

static void bad_bandwidth(void) {
    int bad[] = {0, -1, -1000, SO3FFT_MAX_BANDWIDTH + 1, 1 << 30};
    size_t i;
    double w[4];
    for (i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        int B = bad[i];
        CHECK(so3fft_plan_forward(B, NULL, NULL, 0) == NULL);
        CHECK_ERR(SO3FFT_EBANDWIDTH);
        CHECK(so3fft_plan_inverse(B, NULL, NULL, 0) == NULL);
        CHECK_ERR(SO3FFT_EBANDWIDTH);
        CHECK(so3fft_plan_both(B, 0) == NULL);
        CHECK_ERR(SO3FFT_EBANDWIDTH);
        CHECK(so3fft_plan_general(B, SO3FFT_BOTH, NULL, NULL, 0, 1) == NULL);
        CHECK_ERR(SO3FFT_EBANDWIDTH);
        CHECK(so3fft_num_samples(B) == 0);
        CHECK_ERR(SO3FFT_EBANDWIDTH);
        CHECK(so3fft_num_coeffs(B) == 0);
        CHECK_ERR(SO3FFT_EBANDWIDTH);
        CHECK(so3fft_coef_index(B, 0, 0, 0) == -1);
        CHECK_ERR(SO3FFT_EBANDWIDTH);
        CHECK(so3fft_sample_index(B, 0, 0, 0) == -1);
        CHECK_ERR(SO3FFT_EBANDWIDTH);
        CHECK(isnan(so3fft_alpha(B, 0)));
        CHECK_ERR(SO3FFT_EBANDWIDTH);
        CHECK(isnan(so3fft_beta(B, 0)));
        CHECK_ERR(SO3FFT_EBANDWIDTH);
        CHECK(isnan(so3fft_gamma(B, 0)));
        CHECK_ERR(SO3FFT_EBANDWIDTH);
        w[0] = SENTINEL;
        CHECK(so3fft_weights(B, w) == SO3FFT_EBANDWIDTH);
        CHECK_ERR(SO3FFT_EBANDWIDTH);
        CHECK(w[0] == SENTINEL);
    }
    /* the error message names the bandwidth */
    CHECK(so3fft_plan_both(-7, 0) == NULL);
    CHECK(strstr(so3fft_last_error(), "-7") != NULL);
}

static void bad_indices(void) {
    CHECK(so3fft_coef_index(4, 4, 0, 0) == -1);
    CHECK_ERR(SO3FFT_EINVAL);
    CHECK(so3fft_coef_index(4, -1, 0, 0) == -1);
    CHECK_ERR(SO3FFT_EINVAL);
    CHECK(so3fft_coef_index(4, 2, 3, 0) == -1);
    CHECK_ERR(SO3FFT_EINVAL);
    CHECK(so3fft_coef_index(4, 2, 0, -3) == -1);
    CHECK_ERR(SO3FFT_EINVAL);
    CHECK(so3fft_sample_index(4, 8, 0, 0) == -1);
    CHECK_ERR(SO3FFT_EINVAL);
    CHECK(so3fft_sample_index(4, 0, -1, 0) == -1);
    CHECK_ERR(SO3FFT_EINVAL);
    CHECK(so3fft_sample_index(4, 0, 0, 8) == -1);
    CHECK_ERR(SO3FFT_EINVAL);
    CHECK(isnan(so3fft_alpha(4, 8)));
    CHECK_ERR(SO3FFT_EINVAL);
    CHECK(isnan(so3fft_beta(4, -1)));
    CHECK_ERR(SO3FFT_EINVAL);
    CHECK(isnan(so3fft_gamma(4, 8)));
    CHECK_ERR(SO3FFT_EINVAL);
    CHECK(so3fft_weights(4, NULL) == SO3FFT_ENULL);
    CHECK_ERR(SO3FFT_ENULL);
    /* a successful call clears the error state */
    CHECK(so3fft_coef_index(4, 3, -2, 1) >= 0);
    CHECK_NO_ERR();
}

static void bad_flags_threads_direction(void) {
    so3fft_plan p;
    unsigned bad[] = {1u << 3, 1u << 6, 1u << 31, 0xffffffffu};
    size_t i;
    for (i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        CHECK(so3fft_plan_forward(4, NULL, NULL, bad[i]) == NULL);
        CHECK_ERR(SO3FFT_EINVAL);
        CHECK(so3fft_plan_both(4, SO3FFT_MEASURE | bad[i]) == NULL);
        CHECK_ERR(SO3FFT_EINVAL);
    }
    CHECK(so3fft_plan_with_nthreads(-1) == SO3FFT_EINVAL);
    CHECK_ERR(SO3FFT_EINVAL);
    CHECK(so3fft_planner_nthreads() == 0); /* unchanged */
    CHECK(so3fft_plan_general(4, SO3FFT_BOTH, NULL, NULL, 0, -2) == NULL);
    CHECK_ERR(SO3FFT_EINVAL);
    CHECK(so3fft_plan_general(4, SO3FFT_BOTH, NULL, NULL, 0, 1 << 20) == NULL);
    CHECK_ERR(SO3FFT_EINVAL);
    CHECK(so3fft_plan_general(4, 0, NULL, NULL, 0, 1) == NULL);
    CHECK_ERR(SO3FFT_EINVAL);
    CHECK(so3fft_plan_general(4, 7, NULL, NULL, 0, 1) == NULL);
    CHECK_ERR(SO3FFT_EINVAL);
    /* the library is still usable */
    p = so3fft_plan_both(4, SO3FFT_MEASURE | SO3FFT_REAL | SO3FFT_DESTROY_INPUT);
    CHECK(p != NULL);
    CHECK_NO_ERR();
    so3fft_destroy_plan(p);
}

static void bad_arrays(void) {
    const int B = 4;
    size_t nc = so3fft_num_coeffs(B), ns = so3fft_num_samples(B);
    so3fft_complex *s = alloc_cx(ns), *c = alloc_cx(nc), *big = alloc_cx(ns + nc + 1);
    so3fft_complex *mis;
    char *raw = (char *)malloc((nc + 1) * sizeof(so3fft_complex));
    so3fft_plan pf, pi, pb, pf0;
    fill_random(s, ns, 1);
    fill_random(c, nc, 2);

    /* exactly one array NULL at planning */
    CHECK(so3fft_plan_forward(B, s, NULL, 0) == NULL);
    CHECK_ERR(SO3FFT_ENULL);
    CHECK(so3fft_plan_inverse(B, NULL, s, 0) == NULL);
    CHECK_ERR(SO3FFT_ENULL);
    /* arrays with SO3FFT_BOTH */
    CHECK(so3fft_plan_general(B, SO3FFT_BOTH, s, c, 0, 1) == NULL);
    CHECK_ERR(SO3FFT_EINVAL);
    /* overlapping arrays at planning */
    CHECK(so3fft_plan_forward(B, big, big + ns - 1, 0) == NULL);
    CHECK_ERR(SO3FFT_EINVAL);
    /* misaligned array (not aligned like double) */
    mis = (so3fft_complex *)(void *)(raw + 1);
    CHECK(so3fft_plan_inverse(B, mis, s, 0) == NULL);
    CHECK_ERR(SO3FFT_EINVAL);

    pf = so3fft_plan_forward(B, s, c, 0);
    pi = so3fft_plan_inverse(B, c, s, 0);
    pb = so3fft_plan_both(B, 0);
    pf0 = so3fft_plan_forward(B, NULL, NULL, 0);
    CHECK(pf && pi && pb && pf0);
    if (!(pf && pi && pb && pf0)) return;

    /* NULL plan */
    CHECK(so3fft_execute(NULL) == SO3FFT_ENULL);
    CHECK_ERR(SO3FFT_ENULL);
    CHECK(so3fft_execute_forward(NULL, s, c) == SO3FFT_ENULL);
    CHECK_ERR(SO3FFT_ENULL);
    CHECK(so3fft_execute_inverse(NULL, c, s) == SO3FFT_ENULL);
    CHECK_ERR(SO3FFT_ENULL);
    CHECK(so3fft_get_bandwidth(NULL) == SO3FFT_ENULL);
    CHECK_ERR(SO3FFT_ENULL);
    CHECK(so3fft_get_nthreads(NULL) == SO3FFT_ENULL);
    CHECK_ERR(SO3FFT_ENULL);
    CHECK(so3fft_get_fft_threading(NULL) == SO3FFT_ENULL);
    CHECK_ERR(SO3FFT_ENULL);
    CHECK(so3fft_get_memory(NULL) == SO3FFT_ENULL);
    CHECK_ERR(SO3FFT_ENULL);
    /* memory estimate: invalid bandwidth, flags, thread count */
    CHECK(so3fft_plan_memory(0, 0, 1) == SO3FFT_EBANDWIDTH);
    CHECK_ERR(SO3FFT_EBANDWIDTH);
    CHECK(so3fft_plan_memory(SO3FFT_MAX_BANDWIDTH + 1, 0, 1) == SO3FFT_EBANDWIDTH);
    CHECK_ERR(SO3FFT_EBANDWIDTH);
    CHECK(so3fft_plan_memory(8, 1u << 30, 1) == SO3FFT_EINVAL);
    CHECK_ERR(SO3FFT_EINVAL);
    CHECK(so3fft_plan_memory(8, 0, -1) == SO3FFT_EINVAL);
    CHECK_ERR(SO3FFT_EINVAL);
    so3fft_destroy_plan(NULL); /* no-op, not an error */
    CHECK_NO_ERR();

    /* so3fft_execute on plans made without arrays */
    CHECK(so3fft_execute(pb) == SO3FFT_ENULL);
    CHECK_ERR(SO3FFT_ENULL);
    CHECK(so3fft_execute(pf0) == SO3FFT_ENULL);
    CHECK_ERR(SO3FFT_ENULL);

    /* NULL arrays in new-array execute; nothing written */
    fill_sentinel(c, nc);
    CHECK(so3fft_execute_forward(pb, NULL, c) == SO3FFT_ENULL);
    CHECK_ERR(SO3FFT_ENULL);
    CHECK(so3fft_execute_forward(pf0, s, NULL) == SO3FFT_ENULL);
    CHECK_ERR(SO3FFT_ENULL);
    CHECK(so3fft_execute_inverse(pb, NULL, s) == SO3FFT_ENULL);
    CHECK_ERR(SO3FFT_ENULL);
    CHECK(untouched(c, nc));

    /* wrong direction; nothing written */
    fill_sentinel(s, ns);
    fill_sentinel(c, nc);
    CHECK(so3fft_execute_inverse(pf, c, s) == SO3FFT_EDIRECTION);
    CHECK_ERR(SO3FFT_EDIRECTION);
    CHECK(untouched(s, ns));
    CHECK(so3fft_execute_forward(pi, s, c) == SO3FFT_EDIRECTION);
    CHECK_ERR(SO3FFT_EDIRECTION);
    CHECK(untouched(c, nc));
    CHECK(so3fft_execute_inverse(pf0, c, s) == SO3FFT_EDIRECTION);
    CHECK_ERR(SO3FFT_EDIRECTION);

    /* overlapping and misaligned arrays in new-array execute */
    CHECK(so3fft_execute_forward(pb, big, big + 1) == SO3FFT_EINVAL);
    CHECK_ERR(SO3FFT_EINVAL);
    CHECK(so3fft_execute_inverse(pb, big + ns, big + 1) == SO3FFT_EINVAL);
    CHECK_ERR(SO3FFT_EINVAL);
    CHECK(so3fft_execute_forward(pb, s, mis) == SO3FFT_EINVAL);
    CHECK_ERR(SO3FFT_EINVAL);
    CHECK(untouched(s, ns));

    /* adjacent (touching, not overlapping) arrays are fine */
    fill_random(big, ns, 3);
    CHECK(so3fft_execute_forward(pb, big, big + ns) == SO3FFT_OK);
    CHECK_NO_ERR();
    /* and the plans still work after all these errors */
    fill_random(s, ns, 4);
    CHECK(so3fft_execute(pf) == SO3FFT_OK);
    CHECK(so3fft_execute(pi) == SO3FFT_OK);
    CHECK_NO_ERR();

    so3fft_destroy_plan(pf);
    so3fft_destroy_plan(pi);
    so3fft_destroy_plan(pb);
    so3fft_destroy_plan(pf0);
    free(s);
    free(c);
    free(big);
    free(raw);
}

int main(void) {
    CHECK(so3fft_last_error_code() == SO3FFT_OK);
    CHECK(so3fft_last_error() != NULL && so3fft_last_error()[0] == '\0');
    bad_bandwidth();
    bad_indices();
    bad_flags_threads_direction();
    bad_arrays();
    return finish("test_errors");
}
