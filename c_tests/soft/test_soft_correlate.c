/* softFFTWCor2 (wrap_fftw.h) against the reference correlations of tests/data/s2 (signals
 * that are their pattern rotated by a grid rotation, the all-zero signal, an exact tie), and
 * invalid arguments. Usage: test_soft_correlate <dir with the s2/ reference files>. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <fftw3.h>

#include "wrap_fftw.h"

#include "../s2_reference.h"

static int g_failures;

#define CHECK(cond)                                                                      \
    do {                                                                                 \
        if (!(cond)) {                                                                   \
            fprintf(stderr, "%s:%d: check failed: %s\n", __FILE__, __LINE__, #cond);     \
            g_failures++;                                                                \
        }                                                                                \
    } while (0)

int main(int argc, char **argv) {
    static const char *cases[] = {"cor_B8_complex.txt", "cor_B8_real.txt", "cor_B16_complex.txt",
                                  "cor_B16_real.txt", "cor_B8_zero_signal.txt"};
    const char *dir = argc > 1 ? argv[1] : "tests/data";
    size_t i;
    for (i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        cor_case c;
        int n;
        double a = -1, b = -1, g = -1, *sig, *pat, *sig_copy;
        if (read_case(dir, cases[i], &c) != 0) {
            fprintf(stderr, "%s: unreadable\n", cases[i]);
            g_failures++;
            continue;
        }
        n = 4 * c.bw * c.bw;
        sig = c.is_real ? real_parts(c.sig, n) : c.sig;
        pat = c.is_real ? real_parts(c.pat, n) : c.pat;
        CHECK(sig && pat);
        sig_copy = (double *)malloc(sizeof(double) * (size_t)(c.is_real ? n : 2 * n));
        CHECK(sig_copy != NULL);
        memcpy(sig_copy, sig, sizeof(double) * (size_t)(c.is_real ? n : 2 * n));
        softFFTWCor2(c.bw, sig, pat, &a, &b, &g, c.is_real);
        if (a != c.alpha || b != c.beta || g != c.gamma) {
            fprintf(stderr, "%s: got (%.17g, %.17g, %.17g), expected (%.17g, %.17g, %.17g)\n",
                    cases[i], a, b, g, c.alpha, c.beta, c.gamma);
            g_failures++;
        }
        CHECK(memcmp(sig_copy, sig, sizeof(double) * (size_t)(c.is_real ? n : 2 * n)) == 0);
        /* invalid arguments: a message, the angles untouched */
        a = 7.0;
        softFFTWCor2(0, sig, pat, &a, &b, &g, c.is_real);
        softFFTWCor2(c.bw, NULL, pat, &a, &b, &g, c.is_real);
        softFFTWCor2(c.bw, sig, pat, NULL, &b, &g, c.is_real);
        CHECK(a == 7.0);
        if (c.is_real) {
            free(sig);
            free(pat);
        }
        free(sig_copy);
        free(c.sig);
        free(c.pat);
    }
    if (g_failures) {
        fprintf(stderr, "test_soft_correlate: %d check(s) failed\n", g_failures);
        return 1;
    }
    printf("test_soft_correlate: all checks passed\n");
    return 0;
}
