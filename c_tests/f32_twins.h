/* Helpers of the single-precision C tests: float arrays against double ones, and the
 * comparison of an so3fftf_ call with its so3fft_ twin (both fail with the same code and
 * message, nothing written). Include after test_util.h. */
#ifndef SO3FFT_C_TESTS_F32_TWINS_H
#define SO3FFT_C_TESTS_F32_TWINS_H

#include <math.h>
#include <stdlib.h>
#include <stdio.h>
#include <string.h>

#define SENTINEL_F 1234.5f
/* Guard values behind each array the allocators below return. */
#define GUARD 8

/* n complex floats and GUARD guard values behind them (exit on failure). */
static inline so3fftf_complex *alloc_cf(size_t n) {
    so3fftf_complex *p = (so3fftf_complex *)malloc((n + GUARD) * sizeof(so3fftf_complex));
    size_t i;
    if (!p) exit(EXIT_FAILURE);
    for (i = n; i < n + GUARD; i++) p[i][0] = p[i][1] = SENTINEL_F;
    return p;
}

/* n floats and GUARD guard values behind them. */
static inline float *alloc_f(size_t n) {
    float *p = (float *)malloc((n + GUARD) * sizeof(float));
    size_t i;
    if (!p) exit(EXIT_FAILURE);
    for (i = n; i < n + GUARD; i++) p[i] = SENTINEL_F;
    return p;
}

/* n doubles. */
static inline double *alloc_d(size_t n) {
    double *p = (double *)malloc(n * sizeof(double));
    if (!p) exit(EXIT_FAILURE);
    return p;
}

/* ||a - b|| / ||b|| over n values of a float array and a double array (NaN propagates). */
static inline double rel_f_d(const float *a, const double *b, size_t n) {
    double num = 0.0, den = 0.0;
    size_t i;
    for (i = 0; i < n; i++) {
        double d = (double)a[i] - b[i];
        num += d * d;
        den += b[i] * b[i];
    }
    return sqrt(num / den);
}

/* The same for complex arrays. */
static inline double rel_cf_cd(so3fftf_complex *a, so3fft_complex *b, size_t n) {
    return rel_f_d(&a[0][0], &b[0][0], 2 * n);
}

/* A float array widened to double. */
static inline void widen(const float *a, double *b, size_t n) {
    size_t i;
    for (i = 0; i < n; i++) b[i] = a[i];
}

static inline int untouched_f(const float *a, size_t n) {
    size_t i;
    for (i = 0; i < n; i++)
        if (a[i] != SENTINEL_F) return 0;
    return 1;
}

static inline void fill_sentinel_f(float *a, size_t n) {
    size_t i;
    for (i = 0; i < n; i++) a[i] = SENTINEL_F;
}

struct outcome {
    long ret;
    int code;
    char msg[512];
};

static inline struct outcome outcome_of(long ret) {
    struct outcome o;
    o.ret = ret;
    o.code = so3fft_last_error_code();
    strncpy(o.msg, so3fft_last_error(), sizeof o.msg - 1);
    o.msg[sizeof o.msg - 1] = '\0';
    return o;
}

/* Both calls failed with `code` (returned, where the function returns one, and in the error
 * state), with a message, the same message when `same_msg`. */
static inline void same_failure(const char *file, int line, int code, struct outcome f, struct outcome d,
                         int same_msg) {
    if (f.code != code || d.code != code || f.ret != d.ret || f.msg[0] == '\0' ||
        (same_msg && strcmp(f.msg, d.msg) != 0)) {
        fprintf(stderr,
                "%s:%d: expected error %d from both; f32: %ld, %d \"%s\"; "
                "f64: %ld, %d \"%s\"\n",
                file, line, code, f.ret, f.code, f.msg, d.ret, d.code, d.msg);
        g_failures++;
    }
}

/* Compares an f32 call returning an error code (or a count) with its f64 twin. */
#define SAME_CODE(code, fcall, dcall)                                                       \
    do {                                                                                    \
        struct outcome f_ = outcome_of((long)(fcall));                                      \
        struct outcome d_ = outcome_of((long)(dcall));                                      \
        CHECK(f_.ret == (code));                                                            \
        same_failure(__FILE__, __LINE__, (code), f_, d_, 1);                                          \
    } while (0)

/* Compares an f32 call returning `fail` on failure (-1 for those returning an index or a
 * count) with its f64 twin: `fail` from both, error `code`, the same message. */
#define SAME_FAILURE(fail, code, fcall, dcall)                                              \
    do {                                                                                    \
        struct outcome f_ = outcome_of((long)(fcall));                                      \
        struct outcome d_ = outcome_of((long)(dcall));                                      \
        CHECK(f_.ret == (fail));                                                            \
        same_failure(__FILE__, __LINE__, (code), f_, d_, 1);                                \
    } while (0)

/* The same where the messages differ: an alignment (4 bytes against 8) and an address, or
 * a function name; `fmsg` must be part of the f32 message. */
#define SAME_CODE_ONLY(code, fcall, dcall, fmsg)                                            \
    do {                                                                                    \
        struct outcome f_ = outcome_of((long)(fcall));                                      \
        struct outcome d_ = outcome_of((long)(dcall));                                      \
        CHECK(f_.ret == (code));                                                            \
        same_failure(__FILE__, __LINE__, (code), f_, d_, 0);                                          \
        CHECK(strstr(f_.msg, (fmsg)) != NULL);                                              \
    } while (0)

/* Compares an f32 planner with its f64 twin: both NULL, the same code and message; `ftype`
 * and `dtype` are the plan types, `fdestroy` and `ddestroy` their destroy functions. */
#define SAME_NULL(code, ftype, fcall, fdestroy, dtype, dcall, ddestroy, same_msg)           \
    do {                                                                                    \
        ftype fp_ = (fcall);                                                                \
        struct outcome f_ = outcome_of(fp_ != NULL);                                        \
        dtype dp_ = (dcall);                                                                \
        struct outcome d_ = outcome_of(dp_ != NULL);                                        \
        CHECK(fp_ == NULL && dp_ == NULL);                                                  \
        same_failure(__FILE__, __LINE__, (code), f_, d_, (same_msg));                                 \
        fdestroy(fp_);                                                                      \
        ddestroy(dp_);                                                                      \
    } while (0)

#endif
