/* SOFT-style client test: several client threads call the transforms at once (same and
 * different bandwidths; the plan cache and the plans must be safe), results equal to a
 * single-threaded run. */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <fftw3.h>

#include "soft_fftw.h"
#include "utils_so3.h"
#include "wrap_fftw.h"

#include "soft_test_util.h"

#define NTHREADS 4
#define ROUNDS 3

struct job {
    int bw, flag;
    fftw_complex *coeffs, *want_samples, *want_coeffs;
    double err;
};

static void *worker(void *arg) {
    struct job *j = (struct job *)arg;
    int bw = j->bw, r;
    size_t n3 = (size_t)8 * bw * bw * bw, nc = (size_t)totalCoeffs_so3(bw);
    fftw_complex *s = alloc_cx(n3), *c = alloc_cx(nc);
    j->err = 0.0;
    for (r = 0; r < ROUNDS; r++) {
        double e1, e2;
        Inverse_SO3_Naive_fftw_W(bw, j->coeffs, s, j->flag);
        Forward_SO3_Naive_fftw_W(bw, s, c, j->flag);
        e1 = max_abs_diff(s, j->want_samples, n3);
        e2 = max_abs_diff(c, j->want_coeffs, nc);
        if (!(e1 <= j->err)) j->err = e1;
        if (!(e2 <= j->err)) j->err = e2;
    }
    fftw_free(c);
    fftw_free(s);
    return NULL;
}

/* The round trip of `job` (a struct job *) gives back its coefficients and matches its
 * single-threaded results: 1, else 0. */
static unsigned char round_trip_in_child(void *job) {
    struct job *j = (struct job *)job;
    int bw = j->bw;
    size_t n3 = (size_t)8 * bw * bw * bw, nc = (size_t)totalCoeffs_so3(bw);
    fftw_complex *s = alloc_cx(n3), *c = alloc_cx(nc);
    Inverse_SO3_Naive_fftw_W(bw, j->coeffs, s, j->flag);
    Forward_SO3_Naive_fftw_W(bw, s, c, j->flag);
    return max_abs_diff(c, j->coeffs, nc) <= 1e-12 &&
           max_abs_diff(s, j->want_samples, n3) <= 1e-13 &&
           max_abs_diff(c, j->want_coeffs, nc) <= 1e-13;
}

int main(void) {
    struct job jobs[NTHREADS];
    pthread_t th[NTHREADS];
    int t;
    for (t = 0; t < NTHREADS; t++) {
        int bw = (t % 2) ? 6 : 5;
        size_t n3 = (size_t)8 * bw * bw * bw, nc = (size_t)totalCoeffs_so3(bw);
        jobs[t].bw = bw;
        jobs[t].flag = t / 2;
        jobs[t].coeffs = alloc_cx(nc);
        jobs[t].want_samples = alloc_cx(n3);
        jobs[t].want_coeffs = alloc_cx(nc);
        random_coeffs(bw, jobs[t].coeffs, jobs[t].flag, 77u + (unsigned)t);
    }
    /* single-threaded results first (this also exercises plan creation under threads below,
     * for the bandwidth 7 job started concurrently with the others) */
    for (t = 0; t < NTHREADS; t++) {
        Inverse_SO3_Naive_fftw_W(jobs[t].bw, jobs[t].coeffs, jobs[t].want_samples, jobs[t].flag);
        Forward_SO3_Naive_fftw_W(jobs[t].bw, jobs[t].want_samples, jobs[t].want_coeffs,
                                 jobs[t].flag);
        CHECK_CLOSE(max_abs_diff(jobs[t].want_coeffs, jobs[t].coeffs,
                                 (size_t)totalCoeffs_so3(jobs[t].bw)),
                    1e-12, "round trip");
    }
    for (t = 0; t < NTHREADS; t++) CHECK(pthread_create(&th[t], NULL, worker, &jobs[t]) == 0);
    /* a new bandwidth planned while the others run */
    {
        fftw_complex *c = alloc_cx((size_t)totalCoeffs_so3(7)), *s = alloc_cx(8 * 343);
        fftw_complex *c2 = alloc_cx((size_t)totalCoeffs_so3(7));
        random_coeffs(7, c, 0, 5);
        Inverse_SO3_Naive_fftw_W(7, c, s, 0);
        Forward_SO3_Naive_fftw_W(7, s, c2, 0);
        CHECK_CLOSE(max_abs_diff(c, c2, (size_t)totalCoeffs_so3(7)), 1e-12, "B=7 concurrently");
        fftw_free(c2);
        fftw_free(s);
        fftw_free(c);
    }
    for (t = 0; t < NTHREADS; t++) {
        CHECK(pthread_join(th[t], NULL) == 0);
    }
    /* A child made by fork() while the cache holds plans (whose worker threads are the
     * parent's) plans afresh instead of waiting for them forever, as SOFT itself works in
     * a child. */
    CHECK(in_forked_child(round_trip_in_child, &jobs[0]) == 1);
    for (t = 0; t < NTHREADS; t++) {
        CHECK_CLOSE(jobs[t].err, 1e-13, "concurrent result vs single-threaded");
        fftw_free(jobs[t].want_coeffs);
        fftw_free(jobs[t].want_samples);
        fftw_free(jobs[t].coeffs);
    }
    fftw_cleanup();
    return finish("test_soft_threads");
}
