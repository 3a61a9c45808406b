/* Rotational matching through the C API against the reference correlations of
 * tests/data/s2 (signals that are their pattern rotated by a grid rotation): grid peaks with
 * their exact angles, refinement that stays on an exact peak, bad arguments.
 * Usage: test_matching <dir with the s2/ reference files>. */
#include "test_util.h"

#include "s2_reference.h"

int main(int argc, char **argv) {
    static const char *cases[] = {"cor_B8_complex.txt", "cor_B8_real.txt", "cor_B16_complex.txt",
                                  "cor_B16_real.txt"};
    const char *dir = argc > 1 ? argv[1] : "tests/data";
    size_t i;
    for (i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        cor_case c;
        so3fft_correlation p;
        double angles[3], value = 0.0, *sig, *pat;
        ptrdiff_t n, at;
        if (read_case(dir, cases[i], &c) != 0) {
            fprintf(stderr, "%s: unreadable\n", cases[i]);
            g_failures++;
            continue;
        }
        p = so3fft_plan_correlation(c.bw, 0, -1, c.is_real ? SO3FFT_REAL : 0, 2);
        CHECK(p != NULL);
        n = so3fft_correlation_grid_size(p);
        CHECK(n == 8 * c.bw * c.bw * c.bw);
        sig = c.is_real ? real_parts(c.sig, 4 * c.bw * c.bw) : c.sig;
        pat = c.is_real ? real_parts(c.pat, 4 * c.bw * c.bw) : c.pat;
        if (c.is_real) {
            double *grid = (double *)malloc((size_t)n * sizeof(double));
            double *fused = (double *)malloc((size_t)n * sizeof(double));
            double fused_angles[3];
            CHECK(grid && so3fft_correlate_real(p, sig, pat, grid) == SO3FFT_OK);
            at = so3fft_grid_argmax_real(c.bw, grid, angles);
            /* the argmax found while the grid is computed: the same point and grid */
            CHECK(fused && so3fft_correlate_real_argmax(p, sig, pat, fused, fused_angles) == at);
            CHECK(fused && memcmp(fused, grid, (size_t)n * sizeof(double)) == 0);
            CHECK(memcmp(fused_angles, angles, sizeof angles) == 0);
            CHECK(so3fft_correlate_real_argmax(p, sig, pat, fused, NULL) == at);
            CHECK(so3fft_correlate_real_argmax(NULL, sig, pat, fused, NULL) == -1);
            CHECK_ERR(SO3FFT_ENULL);
            free(fused);
            free(grid);
        } else {
            so3fft_complex *grid = alloc_cx((size_t)n), *fused = alloc_cx((size_t)n);
            double fused_angles[3];
            CHECK(so3fft_correlate(p, (so3fft_complex *)sig, (so3fft_complex *)pat, grid) ==
                  SO3FFT_OK);
            at = so3fft_grid_argmax(c.bw, grid, angles);
            CHECK(so3fft_correlate_argmax(p, (so3fft_complex *)sig, (so3fft_complex *)pat, fused,
                                          fused_angles) == at);
            CHECK(memcmp(fused, grid, (size_t)n * sizeof(so3fft_complex)) == 0);
            CHECK(memcmp(fused_angles, angles, sizeof angles) == 0);
            /* a complex plan refuses real inputs */
            CHECK(so3fft_correlate_real_argmax(p, sig, pat, (double *)fused, NULL) == -1);
            CHECK_ERR(SO3FFT_EINVAL);
            free(fused);
            free(grid);
        }
        CHECK(at == (ptrdiff_t)(c.ii * 4 * c.bw * c.bw + c.jj * 2 * c.bw + c.kk));
        CHECK(angles[0] == c.alpha && angles[1] == c.beta && angles[2] == c.gamma);
        /* the rotation is exactly on the grid: refinement stays there */
        CHECK(so3fft_correlation_refine(p, sig, pat, angles, &value) == SO3FFT_OK);
        CHECK(fabs(angles[0] - c.alpha) < 1e-9 && fabs(angles[1] - c.beta) < 1e-9 &&
              fabs(angles[2] - c.gamma) < 1e-9);
        CHECK(value > 0.0);
        /* several peaks at once: the grid peak and a start beside it both reach it */
        {
            double many[6] = {c.alpha, c.beta, c.gamma, c.alpha + 0.02, c.beta - 0.01, c.gamma + 0.015};
            double values[2] = {0.0, 0.0};
            CHECK(so3fft_correlation_refine_many(p, sig, pat, 2, many, values) == SO3FFT_OK);
            for (int k = 0; k < 2; k++) {
                CHECK(fabs(many[3 * k] - c.alpha) < 1e-9 && fabs(many[3 * k + 1] - c.beta) < 1e-9 &&
                      fabs(many[3 * k + 2] - c.gamma) < 1e-9);
                CHECK(fabs(values[k] - value) <= 1e-12 * value);
            }
            CHECK(so3fft_correlation_refine_many(p, sig, pat, 0, many, NULL) == SO3FFT_OK);
            CHECK(so3fft_correlation_refine_many(p, sig, pat, (size_t)-1, many, NULL) == SO3FFT_EINVAL);
            CHECK_ERR(SO3FFT_EINVAL);
            many[1] = NAN;
            CHECK(so3fft_correlation_refine_many(p, sig, pat, 2, many, values) == SO3FFT_EINVAL);
            CHECK_ERR(SO3FFT_EINVAL);
        }
        /* bad arguments */
        CHECK(so3fft_correlation_refine(p, sig, pat, NULL, &value) == SO3FFT_ENULL);
        CHECK_ERR(SO3FFT_ENULL);
        CHECK(so3fft_correlate_real(NULL, sig, pat, sig) == SO3FFT_ENULL);
        CHECK(so3fft_grid_argmax(0, NULL, angles) == -1);
        CHECK_ERR(SO3FFT_EBANDWIDTH);
        if (c.is_real) {
            free(sig);
            free(pat);
        }
        so3fft_destroy_correlation(p);
        free(c.sig);
        free(c.pat);
    }
    /* top peaks: two planted maxima on a flat grid, a larger value beside the first
       (so that point is no maximum), complex and real */
    {
        const int B = 4, n = 2 * B;
        const size_t total = (size_t)n * n * n;
        so3fft_complex *cg = alloc_cx(total);
        double *rg = (double *)malloc(total * sizeof(double));
        CHECK(rg != NULL);
        for (size_t i = 0; i < total; i++) {
            cg[i][0] = 0.1;
            cg[i][1] = 0.0;
            rg[i] = -0.1;
        }
        const size_t first = (size_t)(1 * n + 2) * n + 3, second = (size_t)(6 * n + 5) * n + 1;
        const size_t beside = (size_t)(1 * n + 3) * n + 3;
        cg[first][0] = 0.0;
        cg[first][1] = 5.0;
        rg[first] = -5.0;
        cg[second][0] = 4.0;
        rg[second] = 4.0;
        cg[beside][0] = 3.0;
        rg[beside] = 3.0;
        for (int real = 0; real < 2; real++) {
            double angles[6], values[2];
            ptrdiff_t idx[2];
            ptrdiff_t got = real ? so3fft_grid_top_peaks_real(B, rg, 2, 0.1, angles, values, idx)
                                 : so3fft_grid_top_peaks(B, cg, 2, 0.1, angles, values, idx);
            CHECK(got == 2);
            CHECK(idx[0] == (ptrdiff_t)first && idx[1] == (ptrdiff_t)second);
            CHECK(values[0] == 25.0 && values[1] == 16.0);
            const double pi = 3.14159265358979323846;
            CHECK(fabs(angles[0] - 2 * pi / B) < 1e-15 && fabs(angles[1] - pi * 3 / (4 * B)) < 1e-15 &&
                  fabs(angles[2] - 3 * pi / B) < 1e-15);
            /* NULL for the optional outputs, k = 0, bad arguments */
            CHECK(so3fft_grid_top_peaks(B, cg, 1, 0.0, angles, NULL, NULL) == 1);
            CHECK(so3fft_grid_top_peaks(B, cg, 0, 0.0, angles, NULL, NULL) == 0);
        }
        double a[3];
        CHECK(so3fft_grid_top_peaks(B, NULL, 1, 0.0, a, NULL, NULL) == -1);
        CHECK_ERR(SO3FFT_ENULL);
        CHECK(so3fft_grid_top_peaks(B, cg, 1, 0.0, NULL, NULL, NULL) == -1);
        CHECK_ERR(SO3FFT_ENULL);
        CHECK(so3fft_grid_top_peaks(B, cg, 1, NAN, a, NULL, NULL) == -1);
        CHECK_ERR(SO3FFT_EINVAL);
        CHECK(so3fft_grid_top_peaks_real(0, rg, 1, 0.0, a, NULL, NULL) == -1);
        CHECK_ERR(SO3FFT_EBANDWIDTH);
        CHECK(so3fft_grid_top_peaks_real(B, rg, (size_t)-1, 0.0, a, NULL, NULL) == -1);
        CHECK_ERR(SO3FFT_EINVAL);
        free(cg);
        free(rg);
    }
    /* rotation matrix and quaternion of Euler angles: orthonormal, R e_z is
       (cos a sin b, sin a sin b, cos b), and the quaternion gives the same matrix */
    {
        const double ang[3] = {0.3, 1.1, -2.0};
        double r[9], q[4];
        CHECK(so3fft_rotation_matrix(ang, r) == SO3FFT_OK);
        CHECK(so3fft_rotation_quaternion(ang, q) == SO3FFT_OK);
        for (int i = 0; i < 3; i++) {
            for (int j = 0; j < 3; j++) {
                double dot = 0.0;
                for (int k = 0; k < 3; k++) {
                    dot += r[3 * i + k] * r[3 * j + k];
                }
                CHECK(fabs(dot - (i == j ? 1.0 : 0.0)) < 1e-15);
            }
        }
        CHECK(fabs(r[2] - cos(0.3) * sin(1.1)) < 1e-15 && fabs(r[5] - sin(0.3) * sin(1.1)) < 1e-15 &&
              fabs(r[8] - cos(1.1)) < 1e-15);
        const double w = q[0], x = q[1], y = q[2], z = q[3];
        CHECK(w >= 0.0 && fabs(w * w + x * x + y * y + z * z - 1.0) < 1e-15);
        CHECK(fabs(r[1] - 2 * (x * y - w * z)) < 1e-15 && fabs(r[6] - 2 * (x * z - w * y)) < 1e-15);
        const double bad[3] = {0.0, NAN, 0.0};
        CHECK(so3fft_rotation_matrix(bad, r) == SO3FFT_EINVAL);
        CHECK_ERR(SO3FFT_EINVAL);
        CHECK(so3fft_rotation_quaternion(ang, NULL) == SO3FFT_ENULL);
        CHECK_ERR(SO3FFT_ENULL);
        CHECK(so3fft_rotation_matrix(NULL, r) == SO3FFT_ENULL);
    }
    CHECK(so3fft_plan_correlation(8, 4, 7, 0, 1) == NULL);
    CHECK_ERR(SO3FFT_EINVAL);
    CHECK(so3fft_plan_correlation(8, 0, -2, 0, 1) == NULL);
    CHECK_ERR(SO3FFT_EINVAL);
    CHECK(so3fft_plan_correlation(0, 0, -1, 0, 1) == NULL);
    CHECK_ERR(SO3FFT_EBANDWIDTH);
    so3fft_destroy_correlation(NULL);
    return finish("test_matching");
}
