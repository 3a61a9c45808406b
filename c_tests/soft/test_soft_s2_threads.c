/* SOFT-style client test of the S^2 transforms under client threads: several threads call
 * InvFST/FST at once (same and different bandwidths: the plan cache, the plans and their
 * conversion buffers are shared), results equal to a single-threaded run; then a child made
 * by fork() transforms while the parent's cache holds plans. */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <fftw3.h>

#include "makeweights.h"
#include "s2_primitive.h"
#include "s2_semi_fly.h"
#include "s2_semi_memo.h"

#include "../check.h"
#include "s2_test_util.h"

#define NTHREADS 4
#define ROUNDS 20

struct job {
    int bw, dataformat;
    double *cre, *cim;           /* input coefficients */
    double *want_re, *want_im;   /* single-threaded samples */
    double *want_cre, *want_cim; /* single-threaded coefficients of those samples */
    double err;
};

static double max_diff(const double *a, const double *b, size_t n) {
    double m = 0.0;
    size_t i;
    for (i = 0; i < n; i++) {
        double d = fabs(a[i] - b[i]);
        if (!(d <= m)) m = d;
    }
    return m;
}

/* Inverse then forward of the job's coefficients into the given arrays. */
static void round_trip(const struct job *j, double *re, double *im, double *cre, double *cim) {
    double w[4 * 8];
    makeweights(j->bw, w);
    InvFST_semi_fly(j->cre, j->cim, re, im, j->bw, NULL, j->dataformat, j->bw, NULL, NULL);
    FST_semi_memo(re, im, cre, cim, j->bw, NULL, NULL, j->dataformat, 0, NULL, NULL, w);
}

/* Largest difference of a round trip from the single-threaded one. */
static double deviation(const struct job *j) {
    size_t ns = 4 * (size_t)j->bw * j->bw, nc = (size_t)j->bw * j->bw;
    double *re = guarded_alloc(ns), *im = guarded_alloc(ns);
    double *cre = guarded_alloc(nc), *cim = guarded_alloc(nc), e[4], worst = 0.0;
    int k;
    round_trip(j, re, im, cre, cim);
    e[0] = max_diff(re, j->want_re, ns);
    e[1] = max_diff(im, j->want_im, ns);
    e[2] = max_diff(cre, j->want_cre, nc);
    e[3] = max_diff(cim, j->want_cim, nc);
    for (k = 0; k < 4; k++)
        if (!(e[k] <= worst)) worst = e[k];
    free(re);
    free(im);
    free(cre);
    free(cim);
    return worst;
}

static void *worker(void *arg) {
    struct job *j = (struct job *)arg;
    int r;
    j->err = 0.0;
    for (r = 0; r < ROUNDS; r++) {
        double e = deviation(j);
        if (!(e <= j->err)) j->err = e;
    }
    return NULL;
}

static unsigned char round_trip_in_child(void *job) {
    struct job *j = (struct job *)job;
    return deviation(j) <= 1e-13 && deviation(j) <= 1e-13;
}

int main(void) {
    struct job jobs[NTHREADS];
    pthread_t th[NTHREADS];
    int t;
    unsigned long long seed = 3;
    for (t = 0; t < NTHREADS; t++) {
        int bw = (t % 2) ? 6 : 5, l, m;
        size_t ns = 4 * (size_t)bw * bw, nc = (size_t)bw * bw, i;
        struct job *j = &jobs[t];
        j->bw = bw;
        j->dataformat = t / 2;
        j->cre = guarded_alloc(nc);
        j->cim = guarded_alloc(nc);
        for (i = 0; i < nc; i++) {
            j->cre[i] = rnd(&seed);
            j->cim[i] = rnd(&seed);
        }
        if (j->dataformat == 1)
            for (l = 0; l < bw; l++) {
                j->cim[seanindex(0, l, bw)] = 0.0;
                for (m = 1; m <= l; m++) {
                    double s = (m % 2) ? -1.0 : 1.0;
                    j->cre[seanindex(-m, l, bw)] = s * j->cre[seanindex(m, l, bw)];
                    j->cim[seanindex(-m, l, bw)] = -s * j->cim[seanindex(m, l, bw)];
                }
            }
        j->want_re = guarded_alloc(ns);
        j->want_im = guarded_alloc(ns);
        j->want_cre = guarded_alloc(nc);
        j->want_cim = guarded_alloc(nc);
        round_trip(j, j->want_re, j->want_im, j->want_cre, j->want_cim);
        CHECK(max_diff(j->want_cre, j->cre, nc) <= 1e-13);
        CHECK(max_diff(j->want_cim, j->cim, nc) <= 1e-13);
    }
    for (t = 0; t < NTHREADS; t++) CHECK(pthread_create(&th[t], NULL, worker, &jobs[t]) == 0);
    for (t = 0; t < NTHREADS; t++) CHECK(pthread_join(th[t], NULL) == 0);
    CHECK(in_forked_child(round_trip_in_child, &jobs[1]) == 1);
    for (t = 0; t < NTHREADS; t++) {
        struct job *j = &jobs[t];
        if (!(j->err <= 1e-13)) {
            fprintf(stderr, "thread %d: deviation %.3e from the single-threaded run\n", t, j->err);
            g_failures++;
        }
        free(j->cre);
        free(j->cim);
        free(j->want_re);
        free(j->want_im);
        free(j->want_cre);
        free(j->want_cim);
    }
    fftw_cleanup();
    return finish("test_soft_s2_threads");
}
