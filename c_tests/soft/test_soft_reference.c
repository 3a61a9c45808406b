/* SOFT-style client test: every transform entry point (plain, _pc, _nt, _W; flag 0 and 1)
 * against the reference data of tests/data, with buffers sized exactly to SOFT's
 * documented minimum, inputs checked unchanged, and the real inverse fed NaN in the blocks it
 * must not read. Usage: test_soft_reference <testdata dir> */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <fftw3.h>

#include "csecond.h"
#include "makeWigner.h"
#include "makeweights.h"
#include "soft_fftw.h"
#include "soft_fftw_nt.h"
#include "soft_fftw_pc.h"
#include "utils_so3.h"
#include "wrap_fftw.h"

#include "soft_test_util.h"

#define TOL 1e-12

enum variant { PLAIN, PC, NT, WRAP, NVARIANTS };
static const char *variant_name[NVARIANTS] = {"plain", "_pc", "_nt", "_W"};

/* Read coefficients and samples of a reference file (layouts of docs/conventions.md). */
static int read_reference(const char *path, int *bw, fftw_complex **coeffs,
                          fftw_complex **samples) {
    char line[512];
    int b = 0, nc = 0, ns = 0, i;
    FILE *fp = fopen(path, "r");
    if (!fp) {
        perror(path);
        return 0;
    }
    while (fgets(line, sizeof line, fp))
        if (sscanf(line, "B %d", &b) == 1) break;
    if (!fgets(line, sizeof line, fp) || sscanf(line, "coef %d", &nc) != 1 || b < 1 ||
        nc != totalCoeffs_so3(b)) {
        fclose(fp);
        return 0;
    }
    *coeffs = alloc_cx((size_t)nc);
    for (i = 0; i < nc; i++) {
        int l, m, mp;
        double re, im;
        if (!fgets(line, sizeof line, fp) ||
            sscanf(line, "%d %d %d %lf %lf", &l, &m, &mp, &re, &im) != 5) {
            fclose(fp);
            return 0;
        }
        (*coeffs)[so3CoefLoc(m, mp, l, b)][0] = re;
        (*coeffs)[so3CoefLoc(m, mp, l, b)][1] = im;
    }
    if (!fgets(line, sizeof line, fp) || sscanf(line, "sample %d", &ns) != 1 ||
        ns != 8 * b * b * b) {
        fclose(fp);
        return 0;
    }
    *samples = alloc_cx((size_t)ns);
    for (i = 0; i < ns; i++) {
        int k, j1, j2;
        double re, im;
        if (!fgets(line, sizeof line, fp) ||
            sscanf(line, "%d %d %d %lf %lf", &k, &j1, &j2, &re, &im) != 5) {
            fclose(fp);
            return 0;
        }
        (*samples)[(k * 2 * b + j1) * 2 * b + j2][0] = re;
        (*samples)[(k * 2 * b + j1) * 2 * b + j2][1] = im;
    }
    fclose(fp);
    *bw = b;
    return 1;
}

static void run_forward(enum variant v, int bw, fftw_complex *data, fftw_complex *coeffs,
                        int flag) {
    int n = 2 * bw;
    size_t n3 = (size_t)n * n * n;
    fftw_complex *ws_cx = alloc_cx(n3);
    fftw_complex *ws_cx2 = alloc_cx(n3);
    double *ws_re = alloc_re((size_t)(24 * bw + 2 * bw * bw));
    double *weights = alloc_re((size_t)(2 * bw));
    double *wigners = alloc_re((size_t)(bw * bw * (bw * bw + 3 * bw + 2)) / 3);
    fftw_plan p1 = client_plan(bw, ws_cx2, ws_cx, FFTW_BACKWARD);
    makeweights2(bw, weights);
    switch (v) {
    case PLAIN:
        Forward_SO3_Naive_fftw(bw, data, coeffs, ws_cx, ws_cx2, ws_re, weights, &p1, flag);
        break;
    case PC:
        genWigAll(bw, wigners, ws_re);
        Forward_SO3_Naive_fftw_pc(bw, data, coeffs, ws_cx, ws_cx2, ws_re, weights, &p1,
                                  wigners, flag);
        break;
    case NT:
        Forward_SO3_Naive_fftw_nt(bw, data, coeffs, ws_cx, ws_re, weights, &p1, flag);
        break;
    default:
        Forward_SO3_Naive_fftw_W(bw, data, coeffs, flag);
        break;
    }
    fftw_destroy_plan(p1);
    fftw_free(wigners);
    fftw_free(weights);
    fftw_free(ws_re);
    fftw_free(ws_cx2);
    fftw_free(ws_cx);
}

static void run_inverse(enum variant v, int bw, fftw_complex *coeffs, fftw_complex *data,
                        int flag) {
    int n = 2 * bw;
    size_t n3 = (size_t)n * n * n;
    fftw_complex *ws_cx = alloc_cx(n3);
    fftw_complex *ws_cx2 = alloc_cx((size_t)n); /* SOFT's minimum for the inverse: 2B */
    double *ws_re = alloc_re((size_t)(24 * bw + 2 * bw * bw));
    double *wigners = alloc_re((size_t)(bw * bw * (bw * bw + 3 * bw + 2)) / 3);
    fftw_plan p1 = client_plan(bw, ws_cx, data, FFTW_FORWARD);
    switch (v) {
    case PLAIN:
        Inverse_SO3_Naive_fftw(bw, coeffs, data, ws_cx, ws_cx2, ws_re, &p1, flag);
        break;
    case PC:
        genWigAllTrans(bw, wigners, ws_re);
        Inverse_SO3_Naive_fftw_pc(bw, coeffs, data, ws_cx, ws_cx2, ws_re, &p1, wigners, flag);
        break;
    case NT:
        Inverse_SO3_Naive_fftw_nt(bw, coeffs, data, ws_cx, ws_re, &p1, flag);
        break;
    default:
        Inverse_SO3_Naive_fftw_W(bw, coeffs, data, flag);
        break;
    }
    fftw_destroy_plan(p1);
    fftw_free(wigners);
    fftw_free(ws_re);
    fftw_free(ws_cx2);
    fftw_free(ws_cx);
}

static void check_file(const char *dir, const char *file, int flag) {
    char path[4096];
    int bw = 0, v, l, m, mp;
    fftw_complex *ref_c = NULL, *ref_s = NULL;
    snprintf(path, sizeof path, "%s/%s", dir, file);
    if (!read_reference(path, &bw, &ref_c, &ref_s)) {
        fprintf(stderr, "cannot read %s\n", path);
        g_failures++;
        return;
    }
    {
        size_t n3 = (size_t)8 * bw * bw * bw, nc = (size_t)totalCoeffs_so3(bw);
        fftw_complex *coeffs = alloc_cx(nc), *samples = alloc_cx(n3);
        fftw_complex *cin = dup_cx(ref_c, nc), *sin_ = dup_cx(ref_s, n3);
        fftw_complex *cin_copy, *sin_copy;
        if (flag) {
            /* The real inverse must not read these blocks: poison them. */
            for (l = 0; l < bw; l++)
                for (m = -l; m <= l; m++)
                    for (mp = -l; mp <= l; mp++)
                        if (!real_block_read(m, mp)) {
                            cin[so3CoefLoc(m, mp, l, bw)][0] = NAN;
                            cin[so3CoefLoc(m, mp, l, bw)][1] = NAN;
                        }
        }
        cin_copy = dup_cx(cin, nc);
        sin_copy = dup_cx(sin_, n3);
        for (v = 0; v < NVARIANTS; v++) {
            char what[128];
            size_t i;
            double t0 = csecond(), t1;
            /* forward */
            memset(coeffs, 0, nc * sizeof(fftw_complex));
            run_forward((enum variant)v, bw, sin_, coeffs, flag);
            snprintf(what, sizeof what, "%s forward %s flag %d", file, variant_name[v], flag);
            CHECK_CLOSE(max_abs_diff(coeffs, ref_c, nc), TOL, what);
            CHECK(memcmp(sin_, sin_copy, n3 * sizeof(fftw_complex)) == 0);
            if (flag) {
                CHECK(symmetry_defect(bw, coeffs) == 0.0);
                for (l = 0; l < bw; l++) CHECK(coeffs[so3CoefLoc(0, 0, l, bw)][1] == 0.0);
            }
            /* inverse */
            memset(samples, 0, n3 * sizeof(fftw_complex));
            run_inverse((enum variant)v, bw, cin, samples, flag);
            snprintf(what, sizeof what, "%s inverse %s flag %d", file, variant_name[v], flag);
            CHECK_CLOSE(max_abs_diff(samples, ref_s, n3), TOL, what);
            CHECK(memcmp(cin, cin_copy, nc * sizeof(fftw_complex)) == 0);
            if (flag)
                for (i = 0; i < n3; i++) CHECK(samples[i][1] == 0.0);
            t1 = csecond();
            CHECK(t1 >= t0);
        }
        fftw_free(sin_copy);
        fftw_free(cin_copy);
        fftw_free(sin_);
        fftw_free(cin);
        fftw_free(samples);
        fftw_free(coeffs);
    }
    fftw_free(ref_s);
    fftw_free(ref_c);
}

int main(int argc, char **argv) {
    if (argc < 2) {
        fprintf(stderr, "usage: %s <testdata dir>\n", argv[0]);
        return EXIT_FAILURE;
    }
    check_file(argv[1], "transform_B4_complex.txt", 0);
    check_file(argv[1], "transform_B8_real.txt", 1);
    fftw_cleanup();
    return finish("test_soft_reference");
}
