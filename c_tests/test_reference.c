/* Reference transforms (tests/data) through the C API, both directions:
 * forward(samples) = coefficients and inverse(coefficients) = samples to 1e-13.
 * Usage: test_reference <testdata dir> */
#include "test_util.h"

#define TOL 1e-13

typedef struct {
    int B;
    size_t nc, ns;
    so3fft_complex *coef;    /* in so3fft layout */
    so3fft_complex *samples; /* in so3fft layout */
} reference;

/* Reads a transform_B*_*.txt file: header lines starting with '#', "B <b>",
 * "coef <n>" then n lines "l M Mp re im", "sample <n>" then n lines "k j1 j2 re im". */
static int read_reference(const char *path, reference *r) {
    FILE *f = fopen(path, "r");
    char line[512];
    size_t i, count = 0, seen_c = 0, seen_s = 0;
    int section = 0; /* 1 = coef, 2 = sample */
    memset(r, 0, sizeof *r);
    if (!f) {
        fprintf(stderr, "cannot open %s\n", path);
        return -1;
    }
    while (fgets(line, sizeof line, f)) {
        unsigned long n;
        int a, b, c;
        double re, im;
        if (line[0] == '#' || line[0] == '\n') {
            continue;
        }
        if (sscanf(line, "B %d", &a) == 1) {
            r->B = a;
            r->nc = so3fft_num_coeffs(a);
            r->ns = so3fft_num_samples(a);
            if (r->nc == 0 || r->ns == 0) {
                fprintf(stderr, "%s: bad bandwidth %d\n", path, a);
                fclose(f);
                return -1;
            }
            r->coef = alloc_cx(r->nc);
            r->samples = alloc_cx(r->ns);
            for (i = 0; i < r->nc; i++) r->coef[i][0] = r->coef[i][1] = NAN;
            for (i = 0; i < r->ns; i++) r->samples[i][0] = r->samples[i][1] = NAN;
            continue;
        }
        if (sscanf(line, "coef %lu", &n) == 1) {
            section = 1;
            count = n;
            continue;
        }
        if (sscanf(line, "sample %lu", &n) == 1) {
            section = 2;
            count = n;
            continue;
        }
        if (r->B == 0 || sscanf(line, "%d %d %d %lf %lf", &a, &b, &c, &re, &im) != 5) {
            fprintf(stderr, "%s: cannot parse line: %s", path, line);
            fclose(f);
            return -1;
        }
        if (section == 1) {
            ptrdiff_t k = so3fft_coef_index(r->B, a, b, c);
            if (k < 0) {
                fprintf(stderr, "%s: invalid coefficient (%d,%d,%d): %s\n", path, a, b, c,
                        so3fft_last_error());
                fclose(f);
                return -1;
            }
            r->coef[k][0] = re;
            r->coef[k][1] = im;
            seen_c++;
        } else if (section == 2) {
            /* line order: k(beta) j1(alpha) j2(gamma) */
            ptrdiff_t k = so3fft_sample_index(r->B, b, a, c);
            if (k < 0 || (size_t)k != (size_t)a * 4 * r->B * r->B + (size_t)b * 2 * r->B + c) {
                fprintf(stderr, "%s: bad sample index for (%d,%d,%d)\n", path, a, b, c);
                fclose(f);
                return -1;
            }
            r->samples[k][0] = re;
            r->samples[k][1] = im;
            seen_s++;
        }
    }
    fclose(f);
    (void)count;
    if (r->B == 0 || seen_c != r->nc || seen_s != r->ns) {
        fprintf(stderr, "%s: incomplete file (%lu of %lu coefficients, %lu of %lu samples)\n",
                path, (unsigned long)seen_c, (unsigned long)r->nc, (unsigned long)seen_s,
                (unsigned long)r->ns);
        return -1;
    }
    return 0;
}

static void check_file(const char *dir, const char *name, unsigned flags) {
    char path[4096];
    reference r;
    so3fft_complex *c, *s;
    so3fft_plan pf, pi, pb;
    double e;
    snprintf(path, sizeof path, "%s/%s", dir, name);
    if (read_reference(path, &r) != 0) {
        g_failures++;
        return;
    }
    c = alloc_cx(r.nc);
    s = alloc_cx(r.ns);

    /* Plans with arrays, so3fft_execute. */
    pf = so3fft_plan_forward(r.B, r.samples, c, flags);
    pi = so3fft_plan_inverse(r.B, r.coef, s, flags);
    CHECK(pf != NULL && pi != NULL);
    if (pf && pi) {
        CHECK(so3fft_execute(pf) == SO3FFT_OK);
        CHECK_NO_ERR();
        e = max_abs_diff(c, r.coef, r.nc);
        printf("%s forward (execute):   max error %.3g\n", name, e);
        CHECK(e <= TOL);
        CHECK(so3fft_execute(pi) == SO3FFT_OK);
        e = max_abs_diff(s, r.samples, r.ns);
        printf("%s inverse (execute):   max error %.3g\n", name, e);
        CHECK(e <= TOL);
    }
    so3fft_destroy_plan(pf);
    so3fft_destroy_plan(pi);

    /* A plan for both directions with new-array execute. */
    memset(c, 0, r.nc * sizeof *c);
    memset(s, 0, r.ns * sizeof *s);
    pb = so3fft_plan_both(r.B, flags | SO3FFT_MEASURE);
    CHECK(pb != NULL);
    if (pb) {
        CHECK(so3fft_execute_forward(pb, r.samples, c) == SO3FFT_OK);
        e = max_abs_diff(c, r.coef, r.nc);
        printf("%s forward (new-array): max error %.3g\n", name, e);
        CHECK(e <= TOL);
        CHECK(so3fft_execute_inverse(pb, r.coef, s) == SO3FFT_OK);
        e = max_abs_diff(s, r.samples, r.ns);
        printf("%s inverse (new-array): max error %.3g\n", name, e);
        CHECK(e <= TOL);
    }
    so3fft_destroy_plan(pb);
    free(c);
    free(s);
    free(r.coef);
    free(r.samples);
}

int main(int argc, char **argv) {
    if (argc != 2) {
        fprintf(stderr, "usage: %s <testdata dir>\n", argv[0]);
        return EXIT_FAILURE;
    }
    check_file(argv[1], "transform_B4_complex.txt", SO3FFT_ESTIMATE);
    check_file(argv[1], "transform_B8_real.txt", SO3FFT_REAL);
    return finish("test_reference");
}
