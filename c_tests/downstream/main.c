/* A minimal downstream program: inverse and forward transform of one coefficient, and an SO(3)
 * and an S^2 round trip in single precision (libfftw3f linked). It defines functions named like SOFT's
 * (transpose, csecond), as numerical codes often do: libso3fft must neither clash with them in
 * a static link nor replace them. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include <so3fft.h>

/* Not SOFT's signatures: the program's own functions that happen to share the names. */
int transpose(int x);
double csecond(void);
int transpose(int x) { return 7 * x; }
double csecond(void) { return 42.0; }

/* Single precision: the S^2 round trip of one coefficient; its error, or -1 on failure. */
static double s2_float_round_trip(void) {
    const int B = 8;
    size_t nc = so3fft_s2_num_coeffs(B), ns = so3fft_s2_num_samples(B), i;
    so3fftf_complex *c = calloc(nc, sizeof *c), *s = calloc(ns, sizeof *s);
    so3fftf_s2_plan p = so3fftf_plan_s2(B, SO3FFT_ESTIMATE, 1);
    ptrdiff_t k = so3fft_s2_coef_index(B, 5, -3);
    double err = -1.0;
    if (c && s && p && k >= 0) {
        c[k][0] = 1.0f;
        if (so3fftf_s2_execute_inverse(p, c, s) == SO3FFT_OK &&
            so3fftf_s2_execute_forward(p, s, c) == SO3FFT_OK) {
            for (err = 0.0, i = 0; i < nc; i++)
                err = fmax(err, hypot(c[i][0] - (i == (size_t)k), c[i][1]));
        }
    }
    if (err < 0.0) fprintf(stderr, "so3fft (single precision): %s\n", so3fft_last_error());
    so3fftf_destroy_s2_plan(p);
    free(c);
    free(s);
    return err;
}

/* Single precision: the SO(3) round trip of one coefficient; its error, or -1 on failure. */
static double so3_float_round_trip(void) {
    const int B = 6;
    size_t nc = so3fft_num_coeffs(B), ns = so3fft_num_samples(B), i;
    so3fftf_complex *c = calloc(nc, sizeof *c), *s = calloc(ns, sizeof *s);
    so3fftf_plan p = so3fftf_plan_both(B, SO3FFT_ESTIMATE);
    ptrdiff_t k = so3fft_coef_index(B, 4, 2, -3);
    double err = -1.0;
    if (c && s && p && k >= 0) {
        c[k][0] = 1.0f;
        if (so3fftf_execute_inverse(p, c, s) == SO3FFT_OK &&
            so3fftf_execute_forward(p, s, c) == SO3FFT_OK) {
            for (err = 0.0, i = 0; i < nc; i++)
                err = fmax(err, hypot(c[i][0] - (i == (size_t)k), c[i][1]));
        }
    }
    if (err < 0.0) fprintf(stderr, "so3fft (single precision): %s\n", so3fft_last_error());
    so3fftf_destroy_plan(p);
    free(c);
    free(s);
    return err;
}

int main(void) {
    const int B = 8;
    size_t nc = so3fft_num_coeffs(B), ns = so3fft_num_samples(B), i;
    so3fft_complex *coeffs = malloc(nc * sizeof *coeffs);
    so3fft_complex *samples = malloc(ns * sizeof *samples);
    so3fft_complex *back = malloc(nc * sizeof *back);
    so3fft_plan plan;
    double err = 0.0, err_f, err_so3f;
    ptrdiff_t k = so3fft_coef_index(B, 3, -1, 2);

    if (transpose(3) != 21 || csecond() != 42.0) {
        fprintf(stderr, "the program's own transpose or csecond was replaced\n");
        return EXIT_FAILURE;
    }
    if (!coeffs || !samples || !back || k < 0) return EXIT_FAILURE;
    for (i = 0; i < nc; i++) coeffs[i][0] = coeffs[i][1] = 0.0;
    coeffs[k][0] = 1.0;
    coeffs[k][1] = 0.5;

    plan = so3fft_plan_both(B, SO3FFT_ESTIMATE);
    if (!plan) {
        fprintf(stderr, "so3fft: %s\n", so3fft_last_error());
        return EXIT_FAILURE;
    }
    if (so3fft_execute_inverse(plan, coeffs, samples) != SO3FFT_OK ||
        so3fft_execute_forward(plan, samples, back) != SO3FFT_OK) {
        fprintf(stderr, "so3fft: %s\n", so3fft_last_error());
        so3fft_destroy_plan(plan);
        return EXIT_FAILURE;
    }
    so3fft_destroy_plan(plan);
    for (i = 0; i < nc; i++) err = fmax(err, hypot(back[i][0] - coeffs[i][0], back[i][1] - coeffs[i][1]));
    printf("so3fft %s: B=%d round trip error %.3g\n", so3fft_version(), B, err);
    free(coeffs);
    free(samples);
    free(back);
    err_f = s2_float_round_trip();
    printf("so3fft %s: S^2 single precision round trip error %.3g\n", so3fft_version(), err_f);
    err_so3f = so3_float_round_trip();
    printf("so3fft %s: SO(3) single precision round trip error %.3g\n", so3fft_version(),
           err_so3f);
    return err < 1e-12 && err_f >= 0.0 && err_f < 1e-5 && err_so3f >= 0.0 && err_so3f < 1e-5
               ? EXIT_SUCCESS
               : EXIT_FAILURE;
}
