/* A program that uses the SOFT API and the native API together (linked with both libraries):
 * a SOFT round trip and a native one on the same coefficients, and SOFT's index map against
 * the native one. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include <fftw3.h>

#include <so3fft.h>

#include "soft_fftw.h"
#include "utils_so3.h"
#include "wrap_fftw.h"

int main(void) {
    const int bw = 4;
    int n = totalCoeffs_so3(bw), i, l, m, mp;
    fftw_complex *c = (fftw_complex *)fftw_malloc(sizeof(fftw_complex) * (size_t)n);
    fftw_complex *s = (fftw_complex *)fftw_malloc(sizeof(fftw_complex) * 8 * 64);
    fftw_complex *back = (fftw_complex *)fftw_malloc(sizeof(fftw_complex) * (size_t)n);
    double err = 0.0;
    so3fft_plan plan;

    if (!c || !s || !back || (size_t)n != so3fft_num_coeffs(bw)) return EXIT_FAILURE;
    for (l = 0; l < bw; l++)
        for (m = -l; m <= l; m++)
            for (mp = -l; mp <= l; mp++)
                if (so3CoefLoc(m, mp, l, bw) != (int)so3fft_coef_index(bw, l, m, mp)) {
                    fprintf(stderr, "index of (%d, %d, %d) differs\n", l, m, mp);
                    return EXIT_FAILURE;
                }
    for (i = 0; i < n; i++) {
        c[i][0] = cos(1.0 + i);
        c[i][1] = sin(2.0 * i);
    }
    /* SOFT's inverse, the native forward: the coefficients come back. */
    Inverse_SO3_Naive_fftw_W(bw, c, s, 0);
    plan = so3fft_plan_forward(bw, s, back, SO3FFT_ESTIMATE);
    if (!plan || so3fft_execute_forward(plan, s, back) != SO3FFT_OK) {
        fprintf(stderr, "so3fft: %s\n", so3fft_last_error());
        return EXIT_FAILURE;
    }
    so3fft_destroy_plan(plan);
    for (i = 0; i < n; i++) err = fmax(err, hypot(back[i][0] - c[i][0], back[i][1] - c[i][1]));
    printf("SOFT inverse, native forward: error %.3e\n", err);
    fftw_free(c);
    fftw_free(s);
    fftw_free(back);
    return err < 1e-12 ? EXIT_SUCCESS : EXIT_FAILURE;
}
