/*
 * What fraction of this machine's measured FMA peak does a production dense kernel reach?
 * A reference point for the DWT's "fraction of peak" (issue 5, target 1): OpenBLAS's
 * AVX-512 DGEMM against the same kind of register-only FMA loop the benchmark uses
 * (16 independent chains), measured alternately in one process, one thread.
 *
 * Not part of the build or of CI. To run (Debian):
 *   apt-get install -y libopenblas-dev
 *   gcc -O2 -march=native notes/reference/dgemm_peak.c -o /tmp/dgemm_peak -lopenblas
 *   OPENBLAS_NUM_THREADS=1 /tmp/dgemm_peak 2048 3
 *   OPENBLAS_NUM_THREADS=1 /tmp/dgemm_peak 512 3
 */
#include <cblas.h>
#include <immintrin.h>
#include <stdio.h>
#include <stdlib.h>
#include <time.h>

static double now(void) {
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return t.tv_sec + 1e-9 * t.tv_nsec;
}

/* GFLOP/s of 16 independent chains of AVX-512 FMAs on register operands. */
__attribute__((noinline)) static double fma_peak(long iters) {
    __m512d a[16];
    const __m512d m = _mm512_set1_pd(0.9999999), c = _mm512_set1_pd(1e-7);
    for (int i = 0; i < 16; i++) a[i] = _mm512_set1_pd(i);
    double t0 = now();
    for (long k = 0; k < iters; k++) {
#pragma GCC unroll 16
        for (int i = 0; i < 16; i++) a[i] = _mm512_fmadd_pd(a[i], m, c);
    }
    double t = now() - t0, s = 0;
    for (int i = 0; i < 16; i++) s += _mm512_reduce_add_pd(a[i]);
    if (s == 42.0) puts(""); /* keep the chains alive */
    return 16.0 * 16 * iters / t / 1e9;
}

int main(int argc, char **argv) {
    int n = argc > 1 ? atoi(argv[1]) : 2048, rounds = argc > 2 ? atoi(argv[2]) : 3;
    double *A = aligned_alloc(64, 8L * n * n), *B = aligned_alloc(64, 8L * n * n),
           *C = aligned_alloc(64, 8L * n * n);
    for (long i = 0; i < (long)n * n; i++) A[i] = drand48(), B[i] = drand48(), C[i] = 0;
    for (int r = 0; r < rounds; r++) {
        double peak = 0, best = 1e30;
        for (int k = 0; k < 5; k++) {
            double x = fma_peak(20000000);
            if (x > peak) peak = x;
        }
        for (int k = 0; k < 3; k++) {
            double t0 = now();
            cblas_dgemm(CblasRowMajor, CblasNoTrans, CblasNoTrans, n, n, n, 1.0, A, n, B, n,
                        0.0, C, n);
            double t = now() - t0;
            if (t < best) best = t;
        }
        double g = 2.0 * n * n * (double)n / best / 1e9;
        printf("n=%d FMA peak %.1f GFLOP/s, DGEMM %.1f GFLOP/s = %.0f%% of it\n", n, peak, g,
               100 * g / peak);
    }
    free(A), free(B), free(C);
    return 0;
}
