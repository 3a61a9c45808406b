/* Rotation of functions on the sphere through the SOFT layer (s2RotateFFTW, rotateFctFFTW,
 * rotateFctFFTWS, rotateFctFFTWS_mem, rotateCoefAll) against the reference of tests/data/s2
 * (f(g^-1 x) evaluated directly with mpmath at off-grid angles), at bandwidths where SOFT's
 * own versions overflow their buffers (exact properties there), and with bad arguments.
 * Usage: test_soft_rotate <dir with the s2/ reference files>. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <fftw3.h>

#include "rotate_so3_fftw.h"
#include "rotate_so3_utils.h"
#include "s2_semi_fly.h"
#include "wrap_fftw.h"

static int g_failures;

#define CHECK(cond)                                                                      \
    do {                                                                                 \
        if (!(cond)) {                                                                   \
            fprintf(stderr, "%s:%d: check failed: %s\n", __FILE__, __LINE__, #cond);     \
            g_failures++;                                                                \
        }                                                                                \
    } while (0)

typedef struct {
    int bw, is_real;
    double alpha, beta, gamma;
    double *in, *out; /* interleaved complex, (2bw)^2 values */
} rot_case;

static int read_rot(const char *dir, const char *name, rot_case *c) {
    char path[1024], line[512], key[64];
    FILE *fp;
    double v;
    memset(c, 0, sizeof *c);
    snprintf(path, sizeof path, "%s/s2/%s", dir, name);
    if (!(fp = fopen(path, "r"))) return 1;
    while (fgets(line, sizeof line, fp)) {
        int count, i;
        if (line[0] == '#') continue;
        if (sscanf(line, "section %63s %d", key, &count) == 2) {
            int n = 2 * c->bw;
            double *dst = (double *)calloc((size_t)(2 * n * n), sizeof(double));
            if (!dst) break;
            for (i = 0; i < count && fgets(line, sizeof line, fp); i++) {
                int j, k;
                double re, im;
                if (sscanf(line, "%d %d %lf %lf", &j, &k, &re, &im) == 4) {
                    dst[2 * (j * n + k)] = re;
                    dst[2 * (j * n + k) + 1] = im;
                }
            }
            if (!strcmp(key, "input"))
                c->in = dst;
            else if (!strcmp(key, "output"))
                c->out = dst;
            else
                free(dst);
        } else if (sscanf(line, "%63s %lf", key, &v) == 2) {
            if (!strcmp(key, "B")) c->bw = (int)v;
            if (!strcmp(key, "isReal")) c->is_real = (int)v;
            if (!strcmp(key, "alpha")) c->alpha = v;
            if (!strcmp(key, "beta")) c->beta = v;
            if (!strcmp(key, "gamma")) c->gamma = v;
        }
    }
    fclose(fp);
    return c->in && c->out ? 0 : 1;
}

static double max_abs(const double *a, int n) {
    double m = 0.0;
    int i;
    for (i = 0; i < n; i++) m = fmax(m, fabs(a[i]));
    return m;
}

int main(int argc, char **argv) {
    const char *dir = argc > 1 ? argv[1] : "tests/data";
    static const char *cases[] = {"rot_B8_complex.txt", "rot_B8_real.txt"};
    size_t c_i;
    for (c_i = 0; c_i < 2; c_i++) {
        rot_case c;
        int n, i;
        double *out, *re, *im, *ore, *oim, err = 0.0, scale;
        if (read_rot(dir, cases[c_i], &c) != 0) {
            fprintf(stderr, "%s: unreadable\n", cases[c_i]);
            g_failures++;
            continue;
        }
        n = 4 * c.bw * c.bw;
        scale = max_abs(c.out, 2 * n);
        /* s2RotateFFTW, interleaved (or real) samples */
        out = (double *)calloc((size_t)(2 * n + 8), sizeof(double));
        if (c.is_real) {
            double *rin = (double *)malloc((size_t)n * sizeof(double));
            for (i = 0; i < n; i++) rin[i] = c.in[2 * i];
            out[n] = 12345.0; /* guard after the n outputs */
            s2RotateFFTW(c.bw, rin, out, c.alpha, c.beta, c.gamma, 1);
            for (i = 0; i < n; i++) err = fmax(err, fabs(out[i] - c.out[2 * i]));
            CHECK(out[n] == 12345.0);
            free(rin);
        } else {
            out[2 * n] = 12345.0;
            s2RotateFFTW(c.bw, c.in, out, c.alpha, c.beta, c.gamma, 0);
            for (i = 0; i < 2 * n; i++) err = fmax(err, fabs(out[i] - c.out[i]));
            CHECK(out[2 * n] == 12345.0);
        }
        if (!(err < 1e-13 * scale)) {
            fprintf(stderr, "%s: s2RotateFFTW error %.3e (scale %.3e)\n", cases[c_i], err, scale);
            g_failures++;
        }
        /* rotateFctFFTW and rotateFctFFTWS_mem on split arrays */
        re = (double *)malloc((size_t)n * sizeof(double));
        im = (double *)malloc((size_t)n * sizeof(double));
        ore = (double *)malloc((size_t)n * sizeof(double));
        oim = (double *)malloc((size_t)n * sizeof(double));
        for (i = 0; i < n; i++) {
            re[i] = c.in[2 * i];
            im[i] = c.in[2 * i + 1];
        }
        rotateFctFFTW(c.bw, c.bw, c.bw - 1, re, im, ore, oim, c.alpha, c.beta, c.gamma, NULL, NULL,
                      NULL);
        err = 0.0;
        for (i = 0; i < n; i++)
            err = fmax(err, fmax(fabs(ore[i] - c.out[2 * i]), fabs(oim[i] - c.out[2 * i + 1])));
        CHECK(err < 1e-13 * scale);
        rotateFctFFTWS_mem(c.bw, c.bw - 1, re, im, c.alpha, c.beta, c.gamma);
        for (i = 0; i < n; i++) CHECK(re[i] == ore[i] && im[i] == oim[i]);
        /* bad arguments: nothing written */
        ore[0] = 777.0;
        rotateFctFFTW(c.bw, c.bw, c.bw, re, im, ore, oim, 0, 0, 0, NULL, NULL, NULL);
        rotateFctFFTW(c.bw, c.bw, 0, re, im, ore, NULL, 0, 0, 0, NULL, NULL, NULL);
        rotateFctFFTW(c.bw, c.bw, 0, re, im, re, oim, 0, 0, 0, NULL, NULL, NULL);
        CHECK(ore[0] == 777.0);
        free(out);
        free(re);
        free(im);
        free(ore);
        free(oim);
        free(c.in);
        free(c.out);
    }
    /* B = 32, where SOFT's s2RotateFFTW overflows its heap: the rotation by g and then by
     * g^-1 = Rz(-gamma) Ry(-beta) Rz(-alpha) gives the input back; coefficients rotated by
     * rotateCoefAll keep their norm per degree (D^l is unitary). */
    {
        int bw = 32, n = 4 * bw * bw, i;
        double *in = (double *)malloc((size_t)(2 * n) * sizeof(double));
        double *mid = (double *)malloc((size_t)(2 * n) * sizeof(double));
        double *back = (double *)malloc((size_t)(2 * n) * sizeof(double));
        double *cr = (double *)calloc((size_t)(bw * bw), sizeof(double));
        double *ci = (double *)calloc((size_t)(bw * bw), sizeof(double));
        double *rr = (double *)calloc((size_t)(bw * bw), sizeof(double));
        double *ri = (double *)calloc((size_t)(bw * bw), sizeof(double));
        double err = 0.0, n0 = 0.0, n1 = 0.0;
        unsigned long long s = 99;
        /* a band-limited input: the synthesis of random coefficients */
        for (i = 0; i < bw * bw; i++) {
            s = s * 6364136223846793005ULL + 1442695040888963407ULL;
            cr[i] = (double)(s >> 11) / 9007199254740992.0 - 0.5;
            s = s * 6364136223846793005ULL + 1442695040888963407ULL;
            ci[i] = (double)(s >> 11) / 9007199254740992.0 - 0.5;
        }
        rotateCoefAll(bw, bw, bw - 1, 0.7, 1.9, -0.4, cr, ci, rr, ri, NULL);
        for (i = 0; i < bw * bw; i++) {
            n0 += cr[i] * cr[i] + ci[i] * ci[i];
            n1 += rr[i] * rr[i] + ri[i] * ri[i];
        }
        CHECK(fabs(n0 - n1) < 1e-12 * n0);
        {
            double *sr = (double *)malloc((size_t)n * sizeof(double));
            double *si = (double *)malloc((size_t)n * sizeof(double));
            InvFST_semi_fly(cr, ci, sr, si, bw, NULL, 0, bw, NULL, NULL);
            for (i = 0; i < n; i++) {
                in[2 * i] = sr[i];
                in[2 * i + 1] = si[i];
            }
            free(sr);
            free(si);
        }
        s2RotateFFTW(bw, in, mid, 0.7, 1.9, -0.4, 0);
        s2RotateFFTW(bw, mid, back, 0.4, -1.9, -0.7, 0);
        for (i = 0; i < 2 * n; i++) err = fmax(err, fabs(back[i] - in[i]));
        CHECK(err < 1e-12 * max_abs(in, 2 * n));
        free(in);
        free(mid);
        free(back);
        free(cr);
        free(ci);
        free(rr);
        free(ri);
    }
    if (g_failures) {
        fprintf(stderr, "test_soft_rotate: %d check(s) failed\n", g_failures);
        return 1;
    }
    printf("test_soft_rotate: all checks passed\n");
    return 0;
}
