/* Thread safety: one plan executed concurrently from two pthreads on different arrays,
 * planners running concurrently (also with the host program's own FFTW planner calls),
 * the thread-local error state, and plans across fork(). */
#define _POSIX_C_SOURCE 200809L
#include <fftw3.h>
#include <pthread.h>

#include "test_util.h"

enum { B = 8, REPS = 6, NWORKERS = 2 };

static so3fft_plan g_plan;
static so3fft_complex *g_coef, *g_samples; /* shared inputs, read-only */
static so3fft_complex *g_ref_s, *g_ref_c;   /* serial results */
static size_t g_nc, g_ns;

typedef struct {
    int id;
    int failures;
    so3fft_complex *s, *c; /* this worker's outputs */
} worker;

static void *execute_worker(void *arg) {
    worker *w = (worker *)arg;
    int r;
    for (r = 0; r < REPS; r++) {
        if (so3fft_execute_inverse(g_plan, g_coef, w->s) != SO3FFT_OK) w->failures++;
        if (max_abs_diff(w->s, g_ref_s, g_ns) > 1e-14) w->failures++;
        if (so3fft_execute_forward(g_plan, g_samples, w->c) != SO3FFT_OK) w->failures++;
        if (max_abs_diff(w->c, g_ref_c, g_nc) > 1e-14) w->failures++;
    }
    return NULL;
}

static void concurrent_execute(void) {
    pthread_t t[NWORKERS];
    worker w[NWORKERS];
    int i;
    g_nc = so3fft_num_coeffs(B);
    g_ns = so3fft_num_samples(B);
    g_coef = alloc_cx(g_nc);
    g_samples = alloc_cx(g_ns);
    g_ref_s = alloc_cx(g_ns);
    g_ref_c = alloc_cx(g_nc);
    fill_random(g_coef, g_nc, 11);
    fill_random(g_samples, g_ns, 12);
    g_plan = so3fft_plan_general(B, SO3FFT_BOTH, NULL, NULL, SO3FFT_ESTIMATE, 2);
    CHECK(g_plan != NULL);
    if (!g_plan) return;
    CHECK(so3fft_execute_inverse(g_plan, g_coef, g_ref_s) == SO3FFT_OK);
    CHECK(so3fft_execute_forward(g_plan, g_samples, g_ref_c) == SO3FFT_OK);
    for (i = 0; i < NWORKERS; i++) {
        w[i].id = i;
        w[i].failures = 0;
        w[i].s = alloc_cx(g_ns);
        w[i].c = alloc_cx(g_nc);
        CHECK(pthread_create(&t[i], NULL, execute_worker, &w[i]) == 0);
    }
    for (i = 0; i < NWORKERS; i++) {
        CHECK(pthread_join(t[i], NULL) == 0);
        CHECK(w[i].failures == 0);
        free(w[i].s);
        free(w[i].c);
    }
    so3fft_destroy_plan(g_plan);
    free(g_coef);
    free(g_samples);
    free(g_ref_s);
    free(g_ref_c);
}

static void *planner_worker(void *arg) {
    worker *w = (worker *)arg;
    int r;
    for (r = 0; r < 4; r++) {
        so3fft_plan p = so3fft_plan_general(3 + (r + w->id) % 4, SO3FFT_BOTH, NULL, NULL,
                                            r % 2 ? SO3FFT_MEASURE : 0, 1);
        if (!p) w->failures++;
        so3fft_destroy_plan(p);
    }
    return NULL;
}

/* The host program plans with FFTW itself while so3fft plans. */
static void *host_fftw_worker(void *arg) {
    worker *w = (worker *)arg;
    int r;
    fftw_complex *a = fftw_alloc_complex(64), *b = fftw_alloc_complex(64);
    for (r = 0; r < 50; r++) {
        fftw_plan p = fftw_plan_dft_1d(16 + r % 48, a, b, FFTW_FORWARD, FFTW_ESTIMATE);
        if (!p) w->failures++;
        fftw_destroy_plan(p);
    }
    fftw_free(a);
    fftw_free(b);
    return NULL;
}

static void concurrent_planning(void) {
    pthread_t t[3];
    worker w[3];
    int i;
    /* The first so3fft plan makes FFTW's planner thread-safe (documented). */
    so3fft_plan first = so3fft_plan_both(2, 0);
    CHECK(first != NULL);
    for (i = 0; i < 3; i++) {
        w[i].id = i;
        w[i].failures = 0;
        CHECK(pthread_create(&t[i], NULL, i == 2 ? host_fftw_worker : planner_worker, &w[i]) == 0);
    }
    for (i = 0; i < 3; i++) {
        CHECK(pthread_join(t[i], NULL) == 0);
        CHECK(w[i].failures == 0);
    }
    so3fft_destroy_plan(first);
}

static void *error_worker(void *arg) {
    int *ok = (int *)arg;
    /* a fresh thread starts with no error, whatever the main thread did */
    *ok = so3fft_last_error_code() == SO3FFT_OK && so3fft_last_error()[0] == '\0';
    /* an error here does not affect the main thread */
    *ok = *ok && so3fft_plan_both(-5, 0) == NULL && so3fft_last_error_code() == SO3FFT_EBANDWIDTH;
    return NULL;
}

static void thread_local_errors(void) {
    pthread_t t;
    int ok = 0;
    CHECK(so3fft_execute(NULL) == SO3FFT_ENULL);
    CHECK(pthread_create(&t, NULL, error_worker, &ok) == 0);
    CHECK(pthread_join(t, NULL) == 0);
    CHECK(ok);
    CHECK_ERR(SO3FFT_ENULL);
}

/* What the child of plan_across_fork() checks; returns failure bits. */
struct fork_case {
    so3fft_plan p;
    so3fft_complex *c, *s, *c2;
    size_t nc;
};

static unsigned char fork_child(void *arg) {
    struct fork_case *f = (struct fork_case *)arg;
    unsigned char code = 0;
    so3fft_plan q;
    int rc = so3fft_execute_inverse(f->p, f->c, f->s);
    if (rc != SO3FFT_EINVAL) {
        fprintf(stderr, "fork child: execute returned %d (%s)\n", rc, so3fft_last_error());
        code |= 1;
    }
    if (strstr(so3fft_last_error(), "fork") == NULL) code |= 2;
    so3fft_destroy_plan(f->p);
    q = so3fft_plan_general(B, SO3FFT_BOTH, NULL, NULL, SO3FFT_ESTIMATE, 2);
    if (!q) return code | 4;
    if (so3fft_execute_inverse(q, f->c, f->s) != SO3FFT_OK) code |= 8;
    if (so3fft_execute_forward(q, f->s, f->c2) != SO3FFT_OK) code |= 8;
    if (!(max_abs_diff(f->c, f->c2, f->nc) < 1e-12)) code |= 16;
    so3fft_destroy_plan(q);
    return code;
}

/* A plan whose worker threads ran in the parent, used in a child made by fork(): executing
 * it fails with an error instead of waiting forever for the parent's threads, destroying it
 * returns, and a plan made in the child works. */
static void plan_across_fork(void) {
    struct fork_case f;
    size_t ns = so3fft_num_samples(B);
    int code;
    f.nc = so3fft_num_coeffs(B);
    f.p = so3fft_plan_general(B, SO3FFT_BOTH, NULL, NULL, SO3FFT_ESTIMATE, 2);
    CHECK(f.p != NULL);
    if (!f.p) return;
    f.c = alloc_cx(f.nc);
    f.s = alloc_cx(ns);
    f.c2 = alloc_cx(f.nc);
    fill_random(f.c, f.nc, 21);
    CHECK(so3fft_execute_inverse(f.p, f.c, f.s) == SO3FFT_OK);
    code = in_forked_child(fork_child, &f);
    if (code != 0) fprintf(stderr, "fork child: failure bits %d\n", code);
    CHECK(code == 0);
    /* The parent's plan is unaffected. */
    CHECK(so3fft_execute_forward(f.p, f.s, f.c2) == SO3FFT_OK);
    CHECK(max_abs_diff(f.c, f.c2, f.nc) < 1e-12);
    so3fft_destroy_plan(f.p);
    free(f.c2);
    free(f.s);
    free(f.c);
}

int main(void) {
    concurrent_execute();
    concurrent_planning();
    thread_local_errors();
    plan_across_fork();
    return finish("test_threads");
}
