/* SOFT-style client test of the S^2 transforms (s2_semi_memo.h, s2_semi_fly.h): every
 * reference file of tests/data/s2 through FST/InvFST _memo and _fly, for several cutoffs,
 * with SOFT-sized buffers followed by guard zones, workspaces and inputs checked unchanged,
 * the negative orders of a dataformat = 1 inverse poisoned with NaN, client tables and FFTW
 * plans made as SOFT's clients make them; then bad arguments (rejected, nothing written).
 * Usage: test_soft_s2 <testdata dir> (the directory holding s2/) */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <fftw3.h>

#include "makeweights.h"
#include "s2_cospmls.h"
#include "s2_primitive.h"
#include "s2_semi_fly.h"
#include "s2_semi_memo.h"

#include "../check.h"
#include "s2_test_util.h"

#define FWD_TOL 1e-13 /* absolute (coefficients are O(1)) */
#define INV_TOL 1e-13 /* relative to the largest sample */

static double *dup_doubles(const double *a, size_t n) {
    double *c = guarded_alloc(n);
    memcpy(c, a, n * sizeof(double));
    return c;
}

/* A reference file: bandwidth, samples (split) and coefficients (split, seanindex order). */
struct reference {
    int bw;
    double *sre, *sim, *cre, *cim;
};

static int read_reference(const char *dir, const char *file, struct reference *ref) {
    char path[4096], line[512], name[64];
    int count, i, got = 0;
    FILE *fp;
    snprintf(path, sizeof path, "%s/s2/%s", dir, file);
    fp = fopen(path, "r");
    if (!fp) {
        perror(path);
        return 0;
    }
    ref->bw = 0;
    while (fgets(line, sizeof line, fp)) {
        if (line[0] == '#') continue;
        if (sscanf(line, "B %d", &ref->bw) == 1) {
            size_t b = (size_t)ref->bw;
            ref->sre = guarded_alloc(4 * b * b);
            ref->sim = guarded_alloc(4 * b * b);
            ref->cre = guarded_alloc(b * b);
            ref->cim = guarded_alloc(b * b);
            continue;
        }
        if (sscanf(line, "section %63s %d", name, &count) != 2 || ref->bw < 1) continue;
        for (i = 0; i < count; i++) {
            int a, c, d;
            double re, im;
            if (!fgets(line, sizeof line, fp)) break;
            if (strcmp(name, "samples") == 0 &&
                sscanf(line, "%d %d %lf %lf", &a, &c, &re, &im) == 4) {
                ref->sre[a * 2 * ref->bw + c] = re;
                ref->sim[a * 2 * ref->bw + c] = im;
            } else if (strcmp(name, "coefs") == 0 &&
                       sscanf(line, "%d %d %d %lf %lf", &a, &c, &d, &re, &im) == 5) {
                CHECK(a == seanindex(d, c, ref->bw));
                ref->cre[a] = re;
                ref->cim[a] = im;
            }
        }
        got++;
    }
    fclose(fp);
    return ref->bw >= 1 && got == 2;
}

static void free_reference(struct reference *ref) {
    free(ref->sre);
    free(ref->sim);
    free(ref->cre);
    free(ref->cim);
}

static double max_abs2(const double *re, const double *im, size_t n) {
    double m = 0.0;
    size_t i;
    for (i = 0; i < n; i++) {
        double v = hypot(re[i], im[i]);
        if (v > m) m = v;
    }
    return m;
}

static double max_diff2(const double *re, const double *im, const double *wre, const double *wim,
                        size_t n) {
    double m = 0.0;
    size_t i;
    for (i = 0; i < n; i++) {
        double d = hypot(re[i] - wre[i], im[i] - wim[i]);
        if (!(d <= m)) m = d; /* NaN propagates */
    }
    return m;
}

/* Client set-up of SOFT's S^2 test programs: weights, Legendre tables, FFTW plans. */
struct client {
    int bw, cutoff;
    double *weights, *space, *tspace, *table_ws;
    double **table, **ttable;
    double *plan_in, *plan_out; /* arrays the plans are made on (FFTW_ESTIMATE) */
    fftw_plan dct, idct, fft, ifft;
};

static void client_setup(struct client *c, int bw, int cutoff, double *rdata, double *idata,
                         double *ws) {
    size_t tsize = (size_t)Reduced_Naive_TableSize(bw, cutoff) +
                   (size_t)Reduced_SpharmonicTableSize(bw, cutoff);
    fftw_iodim dims, howmany;
    c->bw = bw;
    c->cutoff = cutoff;
    c->weights = guarded_alloc((size_t)(4 * bw));
    makeweights(bw, c->weights);
    c->space = guarded_alloc(tsize);
    c->tspace = guarded_alloc(tsize);
    c->table_ws = guarded_alloc((size_t)(16 * bw));
    c->table = SemiNaive_Naive_Pml_Table(bw, cutoff, c->space, c->table_ws);
    c->ttable = Transpose_SemiNaive_Naive_Pml_Table(c->table, bw, cutoff, c->tspace, c->table_ws);
    CHECK(c->table != NULL && c->ttable != NULL);
    CHECK(canaries_intact(c->space, tsize, tsize + GUARD));
    CHECK(canaries_intact(c->tspace, tsize, tsize + GUARD));
    CHECK(canaries_intact(c->table_ws, 0, (size_t)(16 * bw) + GUARD));
    c->plan_in = guarded_alloc((size_t)(2 * bw));
    c->plan_out = guarded_alloc((size_t)(2 * bw));
    c->dct = fftw_plan_r2r_1d(2 * bw, c->plan_in, c->plan_out, FFTW_REDFT10, FFTW_ESTIMATE);
    c->idct = fftw_plan_r2r_1d(2 * bw, c->plan_in, c->plan_out, FFTW_REDFT01, FFTW_ESTIMATE);
    dims.n = 2 * bw;
    dims.is = 1;
    dims.os = 2 * bw;
    howmany.n = 2 * bw;
    howmany.is = 2 * bw;
    howmany.os = 1;
    c->fft = fftw_plan_guru_split_dft(1, &dims, 1, &howmany, rdata, idata, ws,
                                      ws + 4 * bw * bw, FFTW_ESTIMATE);
    dims.is = 2 * bw;
    dims.os = 1;
    howmany.is = 1;
    howmany.os = 2 * bw;
    c->ifft = fftw_plan_guru_split_dft(1, &dims, 1, &howmany, rdata, idata, ws,
                                       ws + 4 * bw * bw, FFTW_ESTIMATE);
}

static void client_teardown(struct client *c) {
    fftw_destroy_plan(c->dct);
    fftw_destroy_plan(c->idct);
    fftw_destroy_plan(c->fft);
    fftw_destroy_plan(c->ifft);
    free(c->table); /* pointer arrays from malloc, released by the client */
    free(c->ttable);
    free(c->space);
    free(c->tspace);
    free(c->table_ws);
    free(c->plan_in);
    free(c->plan_out);
    free(c->weights);
}

static size_t fst_workspace(int bw, int memo) {
    size_t b = (size_t)bw;
    return memo ? 8 * b * b + 7 * b : 10 * b * b + 21 * b;
}

static size_t inv_workspace(int bw, int memo) {
    size_t b = (size_t)bw;
    return memo ? 8 * b * b + 10 * b : 10 * b * b + 24 * b;
}

/* Forward of the file's samples with dataformat, both variants, cutoffs 0, bw/2, bw. */
static void check_forward(const char *dir, const char *file, int dataformat) {
    struct reference ref;
    int memo, ic, cutoffs[3];
    size_t ns, nc;
    if (!read_reference(dir, file, &ref)) {
        fprintf(stderr, "cannot read %s\n", file);
        g_failures++;
        return;
    }
    ns = 4 * (size_t)ref.bw * ref.bw;
    nc = (size_t)ref.bw * ref.bw;
    cutoffs[0] = 0;
    cutoffs[1] = ref.bw / 2;
    cutoffs[2] = ref.bw;
    for (memo = 0; memo < 2; memo++)
        for (ic = 0; ic < 3; ic++) {
            double *rdata = dup_doubles(ref.sre, ns), *idata = dup_doubles(ref.sim, ns);
            double *rc = guarded_alloc(nc), *icf = guarded_alloc(nc);
            size_t nws = fst_workspace(ref.bw, memo);
            double *ws = guarded_alloc(nws), *w_copy;
            struct client cl;
            char what[256];
            client_setup(&cl, ref.bw, cutoffs[ic], rdata, idata, ws);
            w_copy = dup_doubles(cl.weights, (size_t)(4 * ref.bw));
            if (memo)
                FST_semi_memo(rdata, idata, rc, icf, ref.bw, cl.table, ws, dataformat,
                              cutoffs[ic], &cl.dct, &cl.fft, cl.weights);
            else
                FST_semi_fly(rdata, idata, rc, icf, ref.bw, ws, dataformat, cutoffs[ic],
                             &cl.dct, &cl.fft, cl.weights);
            snprintf(what, sizeof what, "%s %s cutoff %d dataformat %d", file,
                     memo ? "FST_semi_memo" : "FST_semi_fly", cutoffs[ic], dataformat);
            {
                double err = max_diff2(rc, icf, ref.cre, ref.cim, nc);
                if (!(err <= FWD_TOL)) {
                    fprintf(stderr, "%s: error %.3e\n", what, err);
                    g_failures++;
                }
            }
            CHECK(canaries_intact(rc, nc, nc + GUARD));
            CHECK(canaries_intact(icf, nc, nc + GUARD));
            CHECK(canaries_intact(ws, 0, nws + GUARD)); /* the workspace is not even written */
            CHECK(memcmp(rdata, ref.sre, ns * sizeof(double)) == 0);
            CHECK(memcmp(idata, ref.sim, ns * sizeof(double)) == 0);
            CHECK(memcmp(w_copy, cl.weights, (size_t)(4 * ref.bw) * sizeof(double)) == 0);
            CHECK(canaries_intact(rdata, ns, ns + GUARD));
            CHECK(canaries_intact(idata, ns, ns + GUARD));
            if (dataformat == 1) { /* negative orders exactly (-1)^m conj(fhat(l, m)) */
                int l, m;
                for (m = 1; m < ref.bw; m++)
                    for (l = m; l < ref.bw; l++) {
                        int p = seanindex(m, l, ref.bw), q = seanindex(-m, l, ref.bw);
                        double s = (m % 2) ? -1.0 : 1.0;
                        CHECK(rc[q] == s * rc[p] && icf[q] == -s * icf[p]);
                    }
            }
            client_teardown(&cl);
            free(w_copy);
            free(ws);
            free(rc);
            free(icf);
            free(rdata);
            free(idata);
        }
    free_reference(&ref);
}

/* Inverse of the file's coefficients with dataformat, both variants, cutoffs 0, bw/2, bw. */
static void check_inverse(const char *dir, const char *file, int dataformat) {
    struct reference ref;
    int memo, ic, cutoffs[3];
    size_t ns, nc;
    if (!read_reference(dir, file, &ref)) {
        fprintf(stderr, "cannot read %s\n", file);
        g_failures++;
        return;
    }
    ns = 4 * (size_t)ref.bw * ref.bw;
    nc = (size_t)ref.bw * ref.bw;
    if (dataformat == 1) { /* must not be read */
        int l, m;
        for (m = 1; m < ref.bw; m++)
            for (l = m; l < ref.bw; l++) {
                ref.cre[seanindex(-m, l, ref.bw)] = NAN;
                ref.cim[seanindex(-m, l, ref.bw)] = NAN;
            }
    }
    cutoffs[0] = 0;
    cutoffs[1] = ref.bw / 2;
    cutoffs[2] = ref.bw;
    for (memo = 0; memo < 2; memo++)
        for (ic = 0; ic < 3; ic++) {
            double *rc = dup_doubles(ref.cre, nc), *icf = dup_doubles(ref.cim, nc);
            double *rdata = guarded_alloc(ns), *idata = guarded_alloc(ns);
            size_t nws = inv_workspace(ref.bw, memo);
            double *ws = guarded_alloc(nws);
            struct client cl;
            char what[256];
            double scale = max_abs2(ref.sre, ref.sim, ns), err;
            client_setup(&cl, ref.bw, cutoffs[ic], rdata, idata, ws);
            if (memo)
                InvFST_semi_memo(rc, icf, rdata, idata, ref.bw, cl.ttable, ws, dataformat,
                                 cutoffs[ic], &cl.idct, &cl.ifft);
            else
                InvFST_semi_fly(rc, icf, rdata, idata, ref.bw, ws, dataformat, cutoffs[ic],
                                &cl.idct, &cl.ifft);
            snprintf(what, sizeof what, "%s %s cutoff %d dataformat %d", file,
                     memo ? "InvFST_semi_memo" : "InvFST_semi_fly", cutoffs[ic], dataformat);
            err = max_diff2(rdata, idata, ref.sre, ref.sim, ns) / scale;
            if (!(err <= INV_TOL)) {
                fprintf(stderr, "%s: relative error %.3e\n", what, err);
                g_failures++;
            }
            CHECK(canaries_intact(rdata, ns, ns + GUARD));
            CHECK(canaries_intact(idata, ns, ns + GUARD));
            CHECK(canaries_intact(ws, 0, nws + GUARD));
            /* inputs unchanged (NaN poison compared bitwise) */
            CHECK(memcmp(rc, ref.cre, nc * sizeof(double)) == 0);
            CHECK(memcmp(icf, ref.cim, nc * sizeof(double)) == 0);
            client_teardown(&cl);
            free(ws);
            free(rc);
            free(icf);
            free(rdata);
            free(idata);
        }
    free_reference(&ref);
}

/* Calls with one bad argument: each is rejected and writes nothing. */
static void check_bad_arguments(void) {
    const int bw = 4;
    size_t ns = 4 * bw * bw, nc = bw * bw, i;
    double *rdata = guarded_alloc(ns), *idata = guarded_alloc(ns);
    double *rc = guarded_alloc(nc), *icf = guarded_alloc(nc);
    double *ws = guarded_alloc(fst_workspace(bw, 0) + inv_workspace(bw, 0));
    double *weights = guarded_alloc(4 * bw);
    int bad_bw[4] = {0, -1, 2049, -2147483647 - 1};
    makeweights(bw, weights);
    for (i = 0; i < 4; i++) {
        FST_semi_fly(rdata, idata, rc, icf, bad_bw[i], ws, 0, 0, NULL, NULL, weights);
        FST_semi_memo(rdata, idata, rc, icf, bad_bw[i], NULL, ws, 0, 0, NULL, NULL, weights);
        InvFST_semi_fly(rc, icf, rdata, idata, bad_bw[i], ws, 0, 0, NULL, NULL);
        InvFST_semi_memo(rc, icf, rdata, idata, bad_bw[i], NULL, ws, 0, 0, NULL, NULL);
    }
    /* cutoff outside 0..bw, dataformat other than 0/1 */
    FST_semi_memo(rdata, idata, rc, icf, bw, NULL, ws, 0, -1, NULL, NULL, weights);
    FST_semi_fly(rdata, idata, rc, icf, bw, ws, 0, bw + 1, NULL, NULL, weights);
    InvFST_semi_memo(rc, icf, rdata, idata, bw, NULL, ws, 1, bw + 1, NULL, NULL);
    InvFST_semi_fly(rc, icf, rdata, idata, bw, ws, 0, -1, NULL, NULL);
    FST_semi_fly(rdata, idata, rc, icf, bw, ws, 2, bw, NULL, NULL, weights);
    InvFST_semi_fly(rc, icf, rdata, idata, bw, ws, -1, bw, NULL, NULL);
    /* NULL arrays (outputs still checked untouched) */
    FST_semi_fly(NULL, idata, rc, icf, bw, ws, 0, bw, NULL, NULL, weights);
    FST_semi_fly(rdata, NULL, rc, icf, bw, ws, 0, bw, NULL, NULL, weights);
    FST_semi_memo(rdata, idata, NULL, icf, bw, NULL, ws, 0, bw, NULL, NULL, weights);
    FST_semi_memo(rdata, idata, rc, NULL, bw, NULL, ws, 0, bw, NULL, NULL, weights);
    InvFST_semi_memo(NULL, icf, rdata, idata, bw, NULL, ws, 0, bw, NULL, NULL);
    InvFST_semi_memo(rc, NULL, rdata, idata, bw, NULL, ws, 0, bw, NULL, NULL);
    InvFST_semi_fly(rc, icf, NULL, idata, bw, ws, 0, bw, NULL, NULL);
    InvFST_semi_fly(rc, icf, rdata, NULL, bw, ws, 0, bw, NULL, NULL);
    /* one output array for both parts */
    FST_semi_fly(rdata, idata, rc, rc, bw, ws, 0, bw, NULL, NULL, weights);
    InvFST_semi_fly(rc, icf, rdata, rdata, bw, ws, 0, bw, NULL, NULL);
    CHECK(canaries_intact(rdata, 0, ns + GUARD) && canaries_intact(idata, 0, ns + GUARD));
    CHECK(canaries_intact(rc, 0, nc + GUARD) && canaries_intact(icf, 0, nc + GUARD));
    CHECK(canaries_intact(ws, 0, fst_workspace(bw, 0) + inv_workspace(bw, 0) + GUARD));
    free(weights);
    free(ws);
    free(rc);
    free(icf);
    free(rdata);
    free(idata);
}

/* Round trip of random band-limited coefficients at a few bandwidths (1, 2, 3, 5, 16):
 * InvFST then FST reproduces them, for both data formats. */
static void check_round_trip(void) {
    int bws[5] = {1, 2, 3, 5, 16}, ib, df;
    unsigned long long seed = 17;
    for (ib = 0; ib < 5; ib++)
        for (df = 0; df < 2; df++) {
            int bw = bws[ib], l, m;
            size_t ns = 4 * (size_t)bw * bw, nc = (size_t)bw * bw, i;
            double *cre = guarded_alloc(nc), *cim = guarded_alloc(nc);
            double *rdata = guarded_alloc(ns), *idata = guarded_alloc(ns);
            double *ore = guarded_alloc(nc), *oim = guarded_alloc(nc);
            double *weights = guarded_alloc(4 * (size_t)bw), err = 0.0;
            for (i = 0; i < nc; i++) {
                cre[i] = rnd(&seed);
                cim[i] = rnd(&seed);
            }
            if (df == 1) /* a real function: Hermitian, fhat(l, 0) real */
                for (l = 0; l < bw; l++) {
                    cim[seanindex(0, l, bw)] = 0.0;
                    for (m = 1; m <= l; m++) {
                        double s = (m % 2) ? -1.0 : 1.0;
                        cre[seanindex(-m, l, bw)] = s * cre[seanindex(m, l, bw)];
                        cim[seanindex(-m, l, bw)] = -s * cim[seanindex(m, l, bw)];
                    }
                }
            makeweights(bw, weights);
            InvFST_semi_fly(cre, cim, rdata, idata, bw, NULL, df, bw, NULL, NULL);
            if (df == 1)
                for (i = 0; i < ns; i++) CHECK(idata[i] == 0.0);
            FST_semi_fly(rdata, idata, ore, oim, bw, NULL, df, bw, NULL, NULL, weights);
            for (i = 0; i < nc; i++) {
                double d = hypot(ore[i] - cre[i], oim[i] - cim[i]);
                if (!(d <= err)) err = d;
            }
            if (!(err <= 1e-13)) {
                fprintf(stderr, "round trip bw %d dataformat %d: error %.3e\n", bw, df, err);
                g_failures++;
            }
            free(weights);
            free(ore);
            free(oim);
            free(rdata);
            free(idata);
            free(cre);
            free(cim);
        }
}

int main(int argc, char **argv) {
    if (argc < 2) {
        fprintf(stderr, "usage: %s <testdata dir>\n", argv[0]);
        return EXIT_FAILURE;
    }
    check_forward(argv[1], "fst_B4_complex.txt", 0);
    check_forward(argv[1], "fst_B8_complex.txt", 0);
    check_forward(argv[1], "fst_B8_real.txt", 1);
    check_forward(argv[1], "fst_B8_real.txt", 0);
    check_forward(argv[1], "fst_B4_realmode_complexinput.txt", 1);
    check_inverse(argv[1], "inv_B4_complex.txt", 0);
    check_inverse(argv[1], "inv_B8_complex.txt", 0);
    check_inverse(argv[1], "inv_B8_real.txt", 1);
    check_inverse(argv[1], "inv_B8_real.txt", 0);
    check_inverse(argv[1], "inv_B4_realmode_asymmetric.txt", 1);
    check_round_trip();
    fprintf(stderr, "(the following error lines are expected: bad arguments)\n");
    check_bad_arguments();
    fftw_cleanup();
    return finish("test_soft_s2");
}
