/* Guard zones shared by the C tests of the S^2 entry points of the SOFT layer. */
#ifndef SO3FFT_SOFT_S2_TEST_UTIL_H
#define SO3FFT_SOFT_S2_TEST_UTIL_H

#include <stdio.h>
#include <stdlib.h>

/* Values after every buffer, and the value they hold. */
#define GUARD 64
#define CANARY 1234.5678

/* n doubles followed by GUARD more, all CANARY (malloc, as SOFT's clients allocate). */
static inline double *guarded_alloc(size_t n) {
    double *p = (double *)malloc((n + GUARD) * sizeof(double));
    size_t i;
    if (!p) {
        fprintf(stderr, "malloc failed\n");
        exit(EXIT_FAILURE);
    }
    for (i = 0; i < n + GUARD; i++) p[i] = CANARY;
    return p;
}

/* Do p[from..to) all still hold CANARY? */
static inline int canaries_intact(const double *p, size_t from, size_t to) {
    size_t i;
    for (i = from; i < to; i++)
        if (p[i] != CANARY) return 0;
    return 1;
}

#endif /* SO3FFT_SOFT_S2_TEST_UTIL_H */
