/* Small helpers shared by the C tests of the so3fft C API. */
#ifndef SO3FFT_TEST_UTIL_H
#define SO3FFT_TEST_UTIL_H

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "so3fft.h"

#include "check.h"

/* A call must have failed with `code` and left a non-empty message. */
#define CHECK_ERR(code)                                                                \
    do {                                                                               \
        int got_ = so3fft_last_error_code();                                           \
        const char *msg_ = so3fft_last_error();                                        \
        if (got_ != (code) || msg_ == NULL || msg_[0] == '\0') {                       \
            fprintf(stderr, "%s:%d: expected error %d (%s), got %d with message \"%s\"\n", \
                    __FILE__, __LINE__, (code), #code, got_, msg_ ? msg_ : "(NULL)");  \
            g_failures++;                                                              \
        }                                                                              \
    } while (0)

/* The last call succeeded: code 0 and empty message. */
#define CHECK_NO_ERR()                                                                 \
    do {                                                                               \
        int got_ = so3fft_last_error_code();                                           \
        const char *msg_ = so3fft_last_error();                                        \
        if (got_ != SO3FFT_OK || msg_ == NULL || msg_[0] != '\0') {                    \
            fprintf(stderr, "%s:%d: expected no error, got %d \"%s\"\n", __FILE__,     \
                    __LINE__, got_, msg_ ? msg_ : "(NULL)");                           \
            g_failures++;                                                              \
        }                                                                              \
    } while (0)

static inline so3fft_complex *alloc_cx(size_t n) {
    so3fft_complex *p = (so3fft_complex *)malloc(n * sizeof(so3fft_complex));
    if (!p) {
        fprintf(stderr, "malloc of %lu complex values failed\n", (unsigned long)n);
        exit(EXIT_FAILURE);
    }
    return p;
}

static inline void fill_random(so3fft_complex *a, size_t n, unsigned long long seed) {
    size_t i;
    for (i = 0; i < n; i++) {
        a[i][0] = rnd(&seed);
        a[i][1] = rnd(&seed);
    }
}

static inline double max_abs_diff(so3fft_complex *a, so3fft_complex *b, size_t n) {
    double m = 0.0;
    size_t i;
    for (i = 0; i < n; i++) {
        double d = hypot(a[i][0] - b[i][0], a[i][1] - b[i][1]);
        if (!(d <= m)) {
            m = d; /* also propagates NaN */
        }
    }
    return m;
}

#endif /* SO3FFT_TEST_UTIL_H */
