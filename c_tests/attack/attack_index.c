/* Issue 24, case 5: the limits of the SOFT layer's int index functions.
 *
 * The README (SOFT layer, "Errors") promises: invalid input, B outside 1..2048 among it, is
 * rejected, and `int` functions return -1. Asserted here (each call in a forked child with an
 * alarm, so a crash is reported as such):
 *  - howMany_so3(m1, m2, bw) is -1 for bw outside 1..2048 and for orders with
 *    max(|m1|, |m2|) >= bw (no such block; coefLoc_so3 already returns -1 there), e.g.
 *    (0,0,-5), (0,INT_MIN,8), (INT_MIN,0,8), (8,0,8), (0,0,0);
 *  - every index/size function (totalCoeffs_so3, numCoeffs_so3, howMany_so3, sampLoc_so3,
 *    coefLoc_so3, so3CoefLoc, seanindex) returns -1 for bw = 2049, 2^20, INT_MAX, 0, -1, INT_MIN;
 *  - sampLoc_so3 computes 2bw (2bw (m1 mod 2bw) + (m2 mod 2bw)) in wide integers and returns
 *    -1 exactly when that does not fit in an int: its largest value is at orders (-1,-1)
 *    (2bw-1 in FFT order), which fits up to bw = 645 and not from bw = 646; the largest
 *    positive orders (bw-1, bw-1) fit up to bw = 812 (so the README's "from B = 812" is off
 *    twice: -1 comes from bw = 646 for (-1,-1), from 813 for (bw-1, bw-1));
 *  - the valid range still works: sampLoc_so3 and so3CoefLoc at bw = 2048 for small orders. */
#define _POSIX_C_SOURCE 200809L
#include <limits.h>

#include "attack.h"
#include "so3_correlate_fftw.h"
#include "utils_so3.h"


#define EXPECT(expr, want)                                                               \
    do {                                                                                 \
        long long got_ = (long long)(expr), want_ = (long long)(want);                   \
        if (got_ != want_) {                                                             \
            fprintf(stderr, "%s:%d: %s = %lld, expected %lld\n", __FILE__, __LINE__, #expr, \
                    got_, want_);                                                        \
            g_failures++;                                                                \
        }                                                                                \
    } while (0)

/* sampLoc_so3 by its formula in 64 bits, -1 if it does not fit in an int. */
static long long samp_loc(long long m1, long long m2, long long bw) {
    long long n = 2 * bw, v = n * (n * ((m1 % n + n) % n) + (m2 % n + n) % n);
    return v > INT_MAX ? -1 : v;
}

static int all_checks(void *arg) {
    static const int bad_bw[] = {2049, 1 << 20, INT_MAX, 0, -1, INT_MIN};
    unsigned i;
    int bw;
    (void)arg;
    /* howMany_so3: invalid orders and bandwidths */
    EXPECT(howMany_so3(0, 0, -5), -1);
    EXPECT(howMany_so3(0, INT_MIN, 8), -1);
    EXPECT(howMany_so3(INT_MIN, 0, 8), -1);
    EXPECT(howMany_so3(INT_MIN, INT_MIN, INT_MIN), -1);
    EXPECT(howMany_so3(8, 0, 8), -1);
    EXPECT(howMany_so3(0, -9, 8), -1);
    EXPECT(howMany_so3(0, 0, 0), -1);
    EXPECT(howMany_so3(-7, 7, 8), 1); /* valid edge */
    EXPECT(howMany_so3(0, 0, 2048), 2048);
    /* bandwidths outside 1..2048 rejected by every index function */
    for (i = 0; i < sizeof bad_bw / sizeof bad_bw[0]; i++) {
        int b = bad_bw[i];
        EXPECT(totalCoeffs_so3(b), -1);
        EXPECT(numCoeffs_so3(b, 0), -1);
        EXPECT(howMany_so3(0, 0, b), -1);
        EXPECT(howMany_so3(1, -1, b), -1);
        EXPECT(sampLoc_so3(0, 0, b), -1);
        EXPECT(sampLoc_so3(1, 1, b), -1);
        EXPECT(coefLoc_so3(0, 0, b), -1);
        EXPECT(so3CoefLoc(0, 0, 0, b), -1);
        EXPECT(seanindex(0, 0, b), -1);
    }
    /* numCoeffs_so3 takes its arguments in either order: bandwidth 2049 either way */
    EXPECT(numCoeffs_so3(0, 2049), -1);
    EXPECT(numCoeffs_so3(3, 1 << 20), -1);
    /* sampLoc_so3: the -1 threshold, by the formula, for the largest and the positive orders */
    for (bw = 640; bw <= 2048; bw += (bw < 660 || (bw > 800 && bw < 820)) ? 1 : 97) {
        EXPECT(sampLoc_so3(-1, -1, bw), samp_loc(-1, -1, bw));
        EXPECT(sampLoc_so3(bw - 1, bw - 1, bw), samp_loc(bw - 1, bw - 1, bw));
        EXPECT(sampLoc_so3(0, 1, bw), 2 * bw);
    }
    EXPECT(sampLoc_so3(-1, -1, 645), samp_loc(-1, -1, 645));
    CHECK(sampLoc_so3(-1, -1, 645) > 0);
    EXPECT(sampLoc_so3(-1, -1, 646), -1);
    CHECK(sampLoc_so3(811, 811, 812) > 0);
    EXPECT(sampLoc_so3(812, 812, 813), -1);
    EXPECT(so3CoefLoc(0, 0, 2047, 2048), 2047);
    return g_failures ? 1 : 0;
}

int main(void) {
    char buf[64];
    int o = run_forked(all_checks, NULL, 20);
    if (o != 0) {
        fprintf(stderr, "index checks: %s\n", outcome_name(o, buf, sizeof buf));
        g_failures++;
    }
    return finish("attack_index");
}
