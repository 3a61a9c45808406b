/*
 * Stage 0c of notes/single-precision-plan.md: the FFT stage of one beta slice in double
 * (fftw_*) against single precision (fftwf_*), FFTW_MEASURE plans, alternated runs, medians.
 *
 * The transform set is src/engine/fft_stage.rs's for a full transform at bandwidth B (slices
 * of 2B x 2B, orders |M'| <= N = B - 1), on work buffers whose rows are padded by one cache
 * line (64 bytes: 4 complex doubles, 8 complex floats):
 *   complex inverse  columns 0..N and -N..-1 over alpha in place (plan_many_dft, stride of a
 *                    padded row), rows over gamma in place, rows streamed to the slice;
 *   complex forward  slice rows copied into the work buffer, rows in place, the 2N + 1
 *                    columns;
 *   real inverse     columns 0..N of the half spectrum (rows of B + 1 + pad), c2r rows into
 *                    the slice's reals;
 *   real forward     r2c rows from the slice's reals, columns 0..N.
 * Around them, the copies of src/engine/copies.rs: the inverse's scatter of a slice's lane
 * row (its (2N + 1)^2 values in cluster order) into the work buffer through a table of
 * (lane offset, work index) pairs, and the forward's weighted gather back; timed apart.
 *
 * Each worker transforms K distinct slices (inverse then forward, K such that the double
 * slices span 64 MiB), so that slices come from memory as in a transform. Two threads are
 * two workers with the same single-threaded plans on their own slices (the engine's
 * slices-across-workers threading).
 *
 * Not part of the build or of CI. To run (Debian: libfftw3-dev):
 *   cc -O2 -march=native notes/reference/fft_f32/fft_stage_f32.c -o /tmp/fft_stage_f32 \
 *      -lfftw3f -lfftw3 -lfftw3f_threads -lfftw3_threads -lpthread -lm
 *   /tmp/fft_stage_f32 [reps] [B ...]          (default: 9 reps, B = 64 128 256)
 */
#define _POSIX_C_SOURCE 200809L
#include <emmintrin.h>
#include <fftw3.h>
#include <math.h>
#include <pthread.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

static double now(void) {
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

/* A slice's slots: lane row offsets and work buffer indices (complex layout: row stride rs;
 * real layout: the half spectrum, row stride hs, CONJ where the value is read at (-M, -M')). */
#define CONJ 0x80000000u
typedef struct {
    long n;
    unsigned *at, *work, *real;
} slots;

/* The slots of bandwidth B in cluster order: for 0 <= m' <= m <= N, the distinct points
 * among (+-m, +-m') and (+-m', +-m), at consecutive lane offsets. */
static slots slots_new(int b, int rs, int hs) {
    int n = b - 1, na = 2 * b;
    long total = (long)(2 * n + 1) * (2 * n + 1);
    slots t = {0, malloc(sizeof(unsigned) * total), malloc(sizeof(unsigned) * total),
               malloc(sizeof(unsigned) * total)};
    for (int m = 0; m <= n; m++)
        for (int m2 = 0; m2 <= m; m2++) {
            int pts[8][2] = {{m, m2},  {m2, m},  {-m, -m2}, {-m2, -m},
                             {m, -m2}, {-m2, m}, {-m, m2},  {m2, -m}};
            for (int p = 0; p < 8; p++) {
                int dup = 0;
                for (int q = 0; q < p; q++)
                    dup |= pts[q][0] == pts[p][0] && pts[q][1] == pts[p][1];
                if (dup) continue;
                int mm = pts[p][0], mp = pts[p][1];
                t.at[t.n] = (unsigned)t.n;
                t.work[t.n] = (unsigned)(((mm + na) % na) * rs + (mp + na) % na);
                t.real[t.n] = mp >= 0 ? (unsigned)(((mm + na) % na) * hs + mp)
                                      : (unsigned)(((-mm + na) % na) * hs - mp) | CONJ;
                t.n++;
            }
        }
    if (t.n != total) {
        fprintf(stderr, "slots: %ld, expected %ld\n", t.n, total);
        exit(1);
    }
    return t;
}

static void slots_free(slots *t) {
    free(t->at);
    free(t->work);
    free(t->real);
}

/* The parts of the complex stage timed on their own (one thread). */
#define NPARTS 6
static const char *PART_NAMES[NPARTS] = {"inv cols", "inv rows", "inv stream", "fwd copy",
                                         "fwd rows", "fwd cols"};

#define R double
#define X(name) fftw_##name
#define P(name) name##_f64
#include "fft_stage_body.h"
#undef R
#undef X
#undef P

#define R float
#define X(name) fftwf_##name
#define P(name) name##_f32
#include "fft_stage_body.h"
#undef R
#undef X
#undef P

/* Complex values of one 64-byte line: the rows' padding (the f32 padding can be set with
 * the environment variable PAD32, in complex floats). */
#define PAD64 4
static int PAD32 = 8;

/* One worker's run of one precision. */
typedef struct {
    int f32, real;
    const stage_f64 *s64;
    const stage_f32 *s32;
    work_f64 *w64;
    work_f32 *w32;
    const slots *t;
    pthread_barrier_t *start;
    double elapsed, copies;
} job;

static void *run_job(void *arg) {
    job *j = arg;
    if (j->start) pthread_barrier_wait(j->start);
    double t0 = now(), tc = 0;
    if (j->f32)
        run_f32(j->s32, j->w32, j->t, j->real, &tc);
    else
        run_f64(j->s64, j->w64, j->t, j->real, &tc);
    j->elapsed = now() - t0;
    j->copies = tc;
    return NULL;
}

static int cmp(const void *a, const void *b) {
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

static double median(double *v, int n) {
    qsort(v, (size_t)n, sizeof(double), cmp);
    return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

/* Seconds per slice and worker of one run: all, and without the scatters and gathers. */
static void run_once(job *jobs, int threads, int k, double *all, double *fft) {
    pthread_barrier_t start;
    pthread_t other;
    if (threads == 2) {
        pthread_barrier_init(&start, NULL, 2);
        jobs[0].start = jobs[1].start = &start;
        pthread_create(&other, NULL, run_job, &jobs[1]);
    } else {
        jobs[0].start = NULL;
    }
    run_job(&jobs[0]);
    if (threads == 2) {
        pthread_join(other, NULL);
        pthread_barrier_destroy(&start);
    }
    *all = *fft = 0;
    for (int i = 0; i < threads; i++) {
        *all += jobs[i].elapsed / k / threads;
        *fft += (jobs[i].elapsed - jobs[i].copies) / k / threads;
    }
}

int main(int argc, char **argv) {
    int reps = argc > 1 ? atoi(argv[1]) : 9;
    if (getenv("PAD32")) PAD32 = atoi(getenv("PAD32"));
    int bs[8] = {64, 128, 256}, nb = 3;
    if (argc > 2) {
        nb = 0;
        for (int i = 2; i < argc && nb < 8; i++) bs[nb++] = atoi(argv[i]);
    }
    /* As the library does (its planner lock's counterpart). */
    fftw_make_planner_thread_safe();
    fftwf_make_planner_thread_safe();
    printf("# f32 rows padded by %d complex values\n", PAD32);
    printf("# ms per slice (inverse + forward) and worker, median of %d alternated runs;\n"
           "# fft: without the scatters/gathers (transforms and row copies only);\n"
           "# rt: relative error of a complex round trip of the slots (the model's check)\n",
           reps);
    printf("%4s %3s %-7s | %9s %9s %6s | %9s %9s %6s | %8s %8s\n", "B", "thr", "kind", "f64 all",
           "f32 all", "ratio", "f64 fft", "f32 fft", "ratio", "rt64", "rt32");
    for (int bi = 0; bi < nb; bi++) {
        int b = bs[bi];
        double tp = now();
        stage_f64 s64;
        stage_f32 s32;
        stage_new_f64(&s64, b, PAD64, 1, FFTW_MEASURE);
        stage_new_f32(&s32, b, PAD32, 1, FFTW_MEASURE);
        fprintf(stderr, "B = %d: planned in %.1f s\n", b, now() - tp);
        slots t64 = slots_new(b, s64.rs, s64.hs), t32 = slots_new(b, s32.rs, s32.hs);
        size_t slice = (size_t)4 * b * b * 16;
        int k = (int)((64u << 20) / slice);
        k = k < 2 ? 2 : k;
        for (int threads = 1; threads <= 2; threads++)
            for (int real = 0; real <= 1; real++) {
                work_f64 w64[2];
                work_f32 w32[2];
                job j64[2], j32[2];
                for (int i = 0; i < threads; i++) {
                    work_new_f64(&w64[i], &s64, k, real);
                    work_new_f32(&w32[i], &s32, k, real);
                    j64[i] = (job){0, real, &s64, NULL, &w64[i], NULL, &t64, NULL, 0, 0};
                    j32[i] = (job){1, real, NULL, &s32, NULL, &w32[i], &t32, NULL, 0, 0};
                }
                double rt64 = 0, rt32 = 0;
                if (!real) {
                    rt64 = round_trip_error_f64(&s64, &w64[0], &t64);
                    rt32 = round_trip_error_f32(&s32, &w32[0], &t32);
                }
                double a64[64], a32[64], f64v[64], f32v[64], x, y;
                run_once(j64, threads, k, &x, &y); /* warm-up */
                run_once(j32, threads, k, &x, &y);
                memset(w64[0].part, 0, sizeof w64[0].part);
                memset(w32[0].part, 0, sizeof w32[0].part);
                int n = reps < 64 ? reps : 64;
                for (int r = 0; r < n; r++) {
                    if (r % 2 == 0) {
                        run_once(j64, threads, k, &a64[r], &f64v[r]);
                        run_once(j32, threads, k, &a32[r], &f32v[r]);
                    } else {
                        run_once(j32, threads, k, &a32[r], &f32v[r]);
                        run_once(j64, threads, k, &a64[r], &f64v[r]);
                    }
                }
                double ma64 = median(a64, n), ma32 = median(a32, n);
                double mf64 = median(f64v, n), mf32 = median(f32v, n);
                printf("%4d %3d %-7s | %9.3f %9.3f %6.3f | %9.3f %9.3f %6.3f |", b, threads,
                       real ? "real" : "complex", 1e3 * ma64, 1e3 * ma32, ma32 / ma64, 1e3 * mf64,
                       1e3 * mf32, mf32 / mf64);
                if (real)
                    printf(" %8s %8s\n", "-", "-");
                else
                    printf(" %8.1e %8.1e\n", rt64, rt32);
                fflush(stdout);
                if (threads == 1 && !real)
                    for (int p = 0; p < NPARTS; p++)
                        printf("#   %-10s f64 %7.3f f32 %7.3f ms  ratio %.3f\n", PART_NAMES[p],
                               1e3 * w64[0].part[p] / (n * k), 1e3 * w32[0].part[p] / (n * k),
                               w32[0].part[p] / w64[0].part[p]);
                for (int i = 0; i < threads; i++) {
                    work_free_f64(&w64[i]);
                    work_free_f32(&w32[i]);
                }
            }
        slots_free(&t64);
        slots_free(&t32);
        stage_free_f64(&s64);
        stage_free_f32(&s32);
    }
    return 0;
}
