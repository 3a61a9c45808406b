/* Degree weights and the whole matching (so3fft_correlation_find) through the C API:
 *  - a band-limited pattern (a sum of kernels a ((1 + mu.x)/2)^8, degree 8 < B) and the
 *    signal that is it rotated by a known rotation off the grid, both sampled from the
 *    formula: the correlation of each degree is largest at that rotation, so the refined peak
 *    is the rotation for uniform, given (decaying, band-pass) and estimated weights alike,
 *    complex and real;
 *  - find against correlate_argmax and refine on the same plan; noise-free inputs: tiny sigma
 *    and noise floors, a peak ratio above 1;
 *  - the weights a plan applies (so3fft_correlation_weights) and its degree limit;
 *  - weights and arguments refused with the Rust checks' messages, nothing written;
 *  - the float twins against the double functions on the same (widened) samples. */
#include "test_util.h"
#include "f32_twins.h"

#define BW 16
#define DEG 8
#define NBUMPS 5
#define NS (4 * BW * BW)
/* Refined rotations against the truth and against each other (radians). */
static const double SAME = 1e-8;
static const double PI = 3.14159265358979323846;
static const double TRUTH[3] = {0.7, 1.1, -0.4};

typedef struct {
    double mu[3], re, im;
} bump;

/* Rz(a) Ry(b) Rz(c), row-major, from Euler angles (a, b, c). */
static void euler_matrix(const double e[3], double r[9]) {
    const double ca = cos(e[0]), sa = sin(e[0]), cb = cos(e[1]), sb = sin(e[1]);
    const double cc = cos(e[2]), sc = sin(e[2]);
    r[0] = ca * cb * cc - sa * sc;
    r[1] = -ca * cb * sc - sa * cc;
    r[2] = ca * sb;
    r[3] = sa * cb * cc + ca * sc;
    r[4] = -sa * cb * sc + ca * cc;
    r[5] = sa * sb;
    r[6] = -sb * cc;
    r[7] = sb * sc;
    r[8] = cb;
}

/* The angle of the rotation between two rotations given by Euler angles:
 * ||R1 - R2||_F = 2 sqrt(2) sin(angle / 2). */
static double angle_between(const double a[3], const double b[3]) {
    double ra[9], rb[9], f = 0.0;
    int i;
    euler_matrix(a, ra);
    euler_matrix(b, rb);
    for (i = 0; i < 9; i++) f += (ra[i] - rb[i]) * (ra[i] - rb[i]);
    return 2.0 * asin(sqrt(f) / (2.0 * sqrt(2.0)));
}

static double match_angle(const so3fft_match *m, const double b[3]) {
    const double a[3] = {m->alpha, m->beta, m->gamma};
    return angle_between(a, b);
}

static double match_apart(const so3fft_match *m, const so3fft_match *n) {
    const double b[3] = {n->alpha, n->beta, n->gamma};
    return match_angle(m, b);
}

/* Samples on the S^2 grid of bandwidth BW (theta_j = pi (2j+1)/(4 BW), phi_k = pi k/BW, at
 * j 2BW + k) of sum_b a_b K((R mu_b) . x), K(t) = ((1 + t)/2)^DEG: the function of `bumps`
 * rotated by R. Real parts only (`real`) or interleaved complex values. */
static void sample(const bump *bumps, const double r[9], int real, double *out) {
    const int n = 2 * BW;
    int j, k, b, i;
    for (j = 0; j < n; j++) {
        const double theta = PI * (2 * j + 1) / (4.0 * BW);
        for (k = 0; k < n; k++) {
            const double phi = PI * k / BW;
            const double x[3] = {sin(theta) * cos(phi), sin(theta) * sin(phi), cos(theta)};
            double re = 0.0, im = 0.0;
            for (b = 0; b < NBUMPS; b++) {
                double t = 0.0, kv;
                for (i = 0; i < 3; i++) {
                    t += (r[3 * i] * bumps[b].mu[0] + r[3 * i + 1] * bumps[b].mu[1] +
                          r[3 * i + 2] * bumps[b].mu[2]) *
                         x[i];
                }
                kv = pow(0.5 * (1.0 + t), DEG);
                re += bumps[b].re * kv;
                im += bumps[b].im * kv;
            }
            if (real) {
                out[j * n + k] = re;
            } else {
                out[2 * (j * n + k)] = re;
                out[2 * (j * n + k) + 1] = im;
            }
        }
    }
}

/* The weights of plan kind `kind` (D + 1 = BW of them): 1 decaying, 2 band-pass. */
static void given_weights(int kind, double *w) {
    int l;
    for (l = 0; l < BW; l++) {
        w[l] = kind == 1 ? 1.0 / (1.0 + l) : (l >= 2 && l <= 7 ? 1.0 + 0.1 * l : 0.0);
    }
}

/* Weight kinds: 0 uniform, 1 decaying, 2 band-pass, 3 estimated from the noise. */
#define KINDS 4
static const char *kind_name[KINDS] = {"uniform", "decaying", "band-pass", "auto"};

static so3fft_correlation plan_d(int kind, int real) {
    const unsigned flags = real ? SO3FFT_REAL : 0;
    double w[BW];
    if (kind == 0) return so3fft_plan_correlation(BW, 0, -1, flags, 1);
    if (kind == 3) return so3fft_plan_correlation(BW, 0, -1, flags | SO3FFT_NOISE_WEIGHTS, 1);
    given_weights(kind, w);
    return so3fft_plan_correlation_weighted(BW, 0, -1, flags, 1, w);
}

static so3fftf_correlation plan_f(int kind, int real) {
    const unsigned flags = real ? SO3FFT_REAL : 0;
    double w[BW];
    if (kind == 0) return so3fftf_plan_correlation(BW, 0, -1, flags, 1);
    if (kind == 3) return so3fftf_plan_correlation(BW, 0, -1, flags | SO3FFT_NOISE_WEIGHTS, 1);
    given_weights(kind, w);
    return so3fftf_plan_correlation_weighted(BW, 0, -1, flags, 1, w);
}

static int find_d(so3fft_correlation p, int real, double *sig, double *pat, double *grid,
                  so3fft_match *m) {
    return real ? so3fft_correlation_find_real(p, sig, pat, grid, m)
                : so3fft_correlation_find(p, (so3fft_complex *)sig, (so3fft_complex *)pat,
                                          (so3fft_complex *)grid, m);
}

static int weights_d(so3fft_correlation p, int real, double *sig, double *pat, double *w) {
    return real ? so3fft_correlation_weights_real(p, sig, pat, w)
                : so3fft_correlation_weights(p, (so3fft_complex *)sig, (so3fft_complex *)pat, w);
}

/* The message of the last error contains `part`. */
static void check_message(const char *part, int line) {
    const char *msg = so3fft_last_error();
    if (!msg || !strstr(msg, part)) {
        fprintf(stderr, "test_noise.c:%d: expected \"%s\" in the message \"%s\"\n", line, part,
                msg ? msg : "(NULL)");
        g_failures++;
    }
}
#define CHECK_MSG(part) check_message(part, __LINE__)

/* Known optimum, every weight kind, find against argmax + refine; complex or real. */
static void known_optimum(const bump *bumps, int real) {
    const size_t nv = real ? NS : 2 * NS, ng = 8 * BW * BW * BW, gv = real ? ng : 2 * ng;
    double r[9], id[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
    double *sig = (double *)malloc(nv * sizeof(double)), *pat = (double *)malloc(nv * sizeof(double));
    double *grid = (double *)malloc(gv * sizeof(double)), *grid2 = (double *)malloc(gv * sizeof(double));
    so3fft_match uniform, m;
    memset(&uniform, 0, sizeof uniform);
    int kind, l;
    if (!sig || !pat || !grid || !grid2) exit(EXIT_FAILURE);
    euler_matrix(TRUTH, r);
    sample(bumps, id, real, pat);
    sample(bumps, r, real, sig);
    for (kind = 0; kind < KINDS; kind++) {
        so3fft_correlation p = plan_d(kind, real);
        double w[BW], given[BW], angles[3], value = 0.0, tr;
        ptrdiff_t at;
        CHECK(p != NULL);
        if (!p) {
            fprintf(stderr, "%s: %s\n", kind_name[kind], so3fft_last_error());
            continue;
        }
        CHECK(so3fft_correlation_degree_limit(p) == BW - 1);
        CHECK(find_d(p, real, sig, pat, grid, &m) == SO3FFT_OK);
        CHECK_NO_ERR();
        if (match_angle(&m, TRUTH) >= SAME) {
            fprintf(stderr, "%s %s: refined %.3e rad from the rotation\n", kind_name[kind],
                    real ? "real" : "complex", match_angle(&m, TRUTH));
            g_failures++;
        }
        if (kind == 0) {
            uniform = m;
        } else {
            CHECK(match_apart(&m, &uniform) < SAME);
        }
        /* noise-free inputs: sure of the peak, which stands out */
        CHECK(m.sigma >= 0.0 && m.sigma < 1e-9);
        tr = m.covariance[0] + m.covariance[4] + m.covariance[8];
        CHECK(fabs(sqrt(tr) - m.sigma) <= 1e-12 * m.sigma);
        CHECK(m.covariance[1] == m.covariance[3] && m.covariance[2] == m.covariance[6] &&
              m.covariance[5] == m.covariance[7]);
        CHECK(m.peak_ratio > 1.0);
        CHECK(m.signal_noise >= 0.0 && m.signal_noise < 1e-20);
        CHECK(m.pattern_noise >= 0.0 && m.pattern_noise < 1e-20);
        CHECK(m.value >= m.grid_value && m.grid_value > 0.0);
        /* the separation: 2 pi / (L + 1), L the highest degree weighted >= 0.1 of the most */
        if (kind == 0) CHECK(fabs(m.separation - 2 * PI / BW) < 1e-15);
        if (kind == 1) CHECK(fabs(m.separation - 2 * PI / 10) < 1e-15);
        if (kind == 2) CHECK(fabs(m.separation - 2 * PI / 8) < 1e-15);
        /* the same as correlate_argmax and refine */
        at = real ? so3fft_correlate_real_argmax(p, sig, pat, grid2, angles)
                  : so3fft_correlate_argmax(p, (so3fft_complex *)sig, (so3fft_complex *)pat,
                                            (so3fft_complex *)grid2, angles);
        CHECK(at == m.grid_index);
        CHECK(angles[0] == m.grid_alpha && angles[1] == m.grid_beta && angles[2] == m.grid_gamma);
        CHECK(memcmp(grid, grid2, gv * sizeof(double)) == 0);
        CHECK(so3fft_correlation_refine(p, sig, pat, angles, &value) == SO3FFT_OK);
        CHECK(fabs(angles[0] - m.alpha) < 1e-10 && fabs(angles[1] - m.beta) < 1e-10 &&
              fabs(angles[2] - m.gamma) < 1e-10);
        CHECK(fabs(value - m.value) <= 1e-12 * m.value);
        /* the weights applied */
        CHECK(weights_d(p, real, sig, pat, w) == SO3FFT_OK);
        if (kind == 0) {
            for (l = 0; l < BW; l++) CHECK(w[l] == 1.0);
        } else if (kind < 3) {
            given_weights(kind, given);
            CHECK(memcmp(w, given, sizeof w) == 0);
        } else {
            double max = 0.0;
            for (l = 0; l < BW; l++) {
                CHECK(w[l] >= 0.0 && w[l] <= 1.0);
                if (w[l] > max) max = w[l];
            }
            CHECK(max == 1.0);
            /* the degrees of the kernel carry signal: weighted */
            for (l = 0; l <= DEG; l++) CHECK(w[l] > 0.1);
        }
        /* the other kind of input is refused */
        CHECK(weights_d(p, !real, sig, pat, w) == SO3FFT_EINVAL);
        CHECK_MSG(real ? "complex correlation asked of a plan made for real inputs"
                       : "real correlation asked of a plan made for complex inputs");
        CHECK(find_d(p, !real, sig, pat, grid, &m) == SO3FFT_EINVAL);
        so3fft_destroy_correlation(p);
    }
    free(sig);
    free(pat);
    free(grid);
    free(grid2);
}

/* Weights and arguments the library refuses, with the messages of its checks. */
static void refused(void) {
    double w[BW], sig[2 * NS], pat[2 * NS], *grid;
    so3fft_match m, before;
    so3fft_correlation p;
    double raw[2 * sizeof(so3fft_match) / sizeof(double)];
    int l;
    for (l = 0; l < BW; l++) w[l] = 1.0;
    w[1] = -0.5;
    CHECK(so3fft_plan_correlation_weighted(BW, 0, -1, 0, 1, w) == NULL);
    CHECK_ERR(SO3FFT_EINVAL);
    CHECK_MSG("degree weight w_1 = -0.5: weights must be finite and >= 0");
    CHECK(so3fftf_plan_correlation_weighted(BW, 0, -1, 0, 1, w) == NULL);
    CHECK_ERR(SO3FFT_EINVAL);
    CHECK_MSG("degree weight w_1 = -0.5: weights must be finite and >= 0");
    w[1] = 1.0;
    w[2] = NAN;
    CHECK(so3fft_plan_correlation_weighted(BW, 0, -1, SO3FFT_REAL, 1, w) == NULL);
    CHECK_ERR(SO3FFT_EINVAL);
    CHECK_MSG("w_2 = NaN");
    w[2] = INFINITY;
    CHECK(so3fft_plan_correlation_weighted(BW, 0, -1, 0, 1, w) == NULL);
    CHECK_MSG("w_2 = inf");
    for (l = 0; l < BW; l++) w[l] = 0.0;
    CHECK(so3fft_plan_correlation_weighted(BW, 0, -1, 0, 1, w) == NULL);
    CHECK_ERR(SO3FFT_EINVAL);
    CHECK_MSG("every degree weight is 0");
    /* normalised: degree 0 does not count */
    w[0] = 1.0;
    CHECK(so3fft_plan_correlation_weighted(BW, 0, -1, SO3FFT_NORMALIZED, 1, w) == NULL);
    CHECK_ERR(SO3FFT_EINVAL);
    CHECK_MSG("every degree weight from degree 1 on is 0");
    CHECK(so3fft_plan_correlation_weighted(BW, 0, -1, 0, 1, NULL) == NULL);
    CHECK_ERR(SO3FFT_ENULL);
    CHECK_MSG("weights array is NULL");
    CHECK(so3fftf_plan_correlation_weighted(BW, 0, -1, 0, 1, NULL) == NULL);
    CHECK_ERR(SO3FFT_ENULL);
    for (l = 0; l < BW; l++) w[l] = 1.0;
    CHECK(so3fft_plan_correlation_weighted(BW, 0, -1, SO3FFT_NOISE_WEIGHTS, 1, w) == NULL);
    CHECK_ERR(SO3FFT_EINVAL);
    CHECK_MSG("SO3FFT_NOISE_WEIGHTS");
    CHECK(so3fftf_plan_correlation_weighted(BW, 0, -1, SO3FFT_NOISE_WEIGHTS, 1, w) == NULL);
    CHECK_ERR(SO3FFT_EINVAL);
    /* a degree limit the planner refuses: its message, the weights not read */
    CHECK(so3fft_plan_correlation_weighted(BW, 0, 1000000, 0, 1, w) == NULL);
    CHECK_ERR(SO3FFT_EINVAL);
    CHECK_MSG("degree limit 1000000");
    /* an unknown flag bit is still one */
    CHECK(so3fft_plan_correlation(BW, 0, -1, 256, 1) == NULL);
    CHECK_ERR(SO3FFT_EINVAL);
    /* the weights are copied: D + 1 of them for D = min(L, B_out) - 1 or the limit given */
    {
        double few[12];
        for (l = 0; l < 12; l++) few[l] = 1.0 + l;
        p = so3fft_plan_correlation_weighted(BW, 12, -1, SO3FFT_REAL, 1, few);
        CHECK(p != NULL && so3fft_correlation_degree_limit(p) == 11);
        so3fft_destroy_correlation(p);
        p = so3fft_plan_correlation_weighted(BW, 24, 4, 0, 1, few);
        CHECK(p != NULL && so3fft_correlation_degree_limit(p) == 4);
        so3fft_destroy_correlation(p);
    }
    CHECK(so3fft_correlation_degree_limit(NULL) == SO3FFT_ENULL);
    CHECK_ERR(SO3FFT_ENULL);
    CHECK(so3fftf_correlation_degree_limit(NULL) == SO3FFT_ENULL);

    /* find: the checks of correlate_argmax, and of the result; nothing written on error */
    p = so3fft_plan_correlation(BW, 0, -1, 0, 1);
    grid = (double *)malloc(2 * 8 * BW * BW * BW * sizeof(double));
    CHECK(p != NULL && grid != NULL);
    if (!p || !grid) exit(EXIT_FAILURE);
    for (l = 0; l < 2 * NS; l++) sig[l] = pat[l] = 0.25;
    memset(&m, 0xab, sizeof m);
    before = m;
    CHECK(so3fft_correlation_find(NULL, (so3fft_complex *)sig, (so3fft_complex *)pat,
                                  (so3fft_complex *)grid, &m) == SO3FFT_ENULL);
    CHECK_MSG("correlation plan is NULL");
    CHECK(so3fft_correlation_find(p, NULL, (so3fft_complex *)pat, (so3fft_complex *)grid, &m) ==
          SO3FFT_ENULL);
    CHECK_MSG("signal array is NULL");
    CHECK(so3fft_correlation_find(p, (so3fft_complex *)sig, (so3fft_complex *)pat, NULL, &m) ==
          SO3FFT_ENULL);
    CHECK(so3fft_correlation_find(p, (so3fft_complex *)sig, (so3fft_complex *)pat,
                                  (so3fft_complex *)grid, NULL) == SO3FFT_ENULL);
    CHECK_MSG("match array is NULL");
    CHECK(so3fft_correlation_find(p, (so3fft_complex *)sig, (so3fft_complex *)pat,
                                  (so3fft_complex *)sig, &m) == SO3FFT_EINVAL);
    CHECK_MSG("overlap");
    CHECK(so3fft_correlation_find(p, (so3fft_complex *)sig, (so3fft_complex *)pat,
                                  (so3fft_complex *)grid, (so3fft_match *)(void *)grid) ==
          SO3FFT_EINVAL);
    CHECK_MSG("the match result and the out array overlap");
    CHECK(so3fft_correlation_find(p, (so3fft_complex *)sig, (so3fft_complex *)pat,
                                  (so3fft_complex *)grid, (so3fft_match *)(void *)((char *)raw + 1)) ==
          SO3FFT_EINVAL);
    CHECK_MSG("not aligned");
    CHECK(so3fft_correlation_find_real(p, sig, pat, grid, &m) == SO3FFT_EINVAL);
    CHECK(memcmp(&m, &before, sizeof m) == 0);
    /* weights: NULL output, overlap with an input */
    CHECK(so3fft_correlation_weights(p, (so3fft_complex *)sig, (so3fft_complex *)pat, NULL) ==
          SO3FFT_ENULL);
    CHECK_MSG("weights array is NULL");
    CHECK(so3fft_correlation_weights(p, (so3fft_complex *)sig, (so3fft_complex *)pat, pat + 8) ==
          SO3FFT_EINVAL);
    CHECK(so3fft_correlation_weights(NULL, (so3fft_complex *)sig, (so3fft_complex *)pat, w) ==
          SO3FFT_ENULL);
    /* a constant pair: |C| the same everywhere, no maximum to be sure of */
    CHECK(so3fft_correlation_find(p, (so3fft_complex *)sig, (so3fft_complex *)pat,
                                  (so3fft_complex *)grid, &m) == SO3FFT_OK);
    CHECK(isinf(m.sigma) && m.value > 0.0);
    so3fft_destroy_correlation(p);
    free(grid);
}

/* The float twins against the double functions on the same (widened) samples. */
static void twins(const bump *bumps, int real) {
    const size_t nv = real ? NS : 2 * NS, ng = 8 * BW * BW * BW, gv = real ? ng : 2 * ng;
    double r[9], id[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
    double *sig = (double *)malloc(nv * sizeof(double)), *pat = (double *)malloc(nv * sizeof(double));
    double *grid = (double *)malloc(gv * sizeof(double));
    float *sig_f = (float *)malloc(nv * sizeof(float)), *pat_f = (float *)malloc(nv * sizeof(float));
    float *grid_f = (float *)malloc(gv * sizeof(float));
    size_t i;
    int kind, l;
    if (!sig || !pat || !grid || !sig_f || !pat_f || !grid_f) exit(EXIT_FAILURE);
    euler_matrix(TRUTH, r);
    sample(bumps, id, real, pat);
    sample(bumps, r, real, sig);
    for (i = 0; i < nv; i++) {
        sig_f[i] = (float)sig[i];
        pat_f[i] = (float)pat[i];
    }
    widen(sig_f, sig, nv);
    widen(pat_f, pat, nv);
    for (kind = 0; kind < KINDS; kind++) {
        so3fft_correlation pd = plan_d(kind, real);
        so3fftf_correlation pf = plan_f(kind, real);
        so3fft_match md, mf;
        double wd[BW], wf[BW];
        int rf, rwf;
        CHECK(pd != NULL && pf != NULL);
        if (!pd || !pf) continue;
        CHECK(so3fftf_correlation_degree_limit(pf) == BW - 1);
        CHECK(find_d(pd, real, sig, pat, grid, &md) == SO3FFT_OK);
        rf = real ? so3fftf_correlation_find_real(pf, sig_f, pat_f, grid_f, &mf)
                  : so3fftf_correlation_find(pf, (so3fftf_complex *)sig_f, (so3fftf_complex *)pat_f,
                                             (so3fftf_complex *)grid_f, &mf);
        CHECK(rf == SO3FFT_OK);
        CHECK(mf.grid_index == md.grid_index);
        CHECK(mf.grid_alpha == md.grid_alpha && mf.grid_beta == md.grid_beta &&
              mf.grid_gamma == md.grid_gamma);
        CHECK(fabs(mf.grid_value - md.grid_value) <= 1e-5 * md.grid_value);
        if (!(match_apart(&mf, &md) < SAME)) {
            fprintf(stderr, "%s %s: float and double refined %.3e rad apart\n", kind_name[kind],
                    real ? "real" : "complex", match_apart(&mf, &md));
            g_failures++;
        }
        CHECK(fabs(mf.value - md.value) <= 1e-10 * md.value);
        CHECK(fabs(mf.sigma - md.sigma) <= 1e-6 * md.sigma);
        CHECK(fabs(mf.signal_noise - md.signal_noise) <= 1e-9 * md.signal_noise + 1e-300);
        CHECK(mf.separation == md.separation);
        CHECK(rel_f_d(grid_f, grid, gv) < 1e-5);
        /* float samples are not exactly band-limited: still close to the rotation */
        CHECK(match_angle(&md, TRUTH) < 1e-5 && md.sigma < 1e-4);
        rwf = real ? so3fftf_correlation_weights_real(pf, sig_f, pat_f, wf)
                   : so3fftf_correlation_weights(pf, (so3fftf_complex *)sig_f,
                                                 (so3fftf_complex *)pat_f, wf);
        CHECK(rwf == SO3FFT_OK && weights_d(pd, real, sig, pat, wd) == SO3FFT_OK);
        for (l = 0; l < BW; l++) CHECK(fabs(wf[l] - wd[l]) <= 1e-9);
        /* the same refusals in both precisions */
        rf = real ? so3fftf_correlation_find_real(pf, sig_f, pat_f, grid_f, NULL)
                  : so3fftf_correlation_find(pf, (so3fftf_complex *)sig_f, (so3fftf_complex *)pat_f,
                                             (so3fftf_complex *)grid_f, NULL);
        CHECK(rf == SO3FFT_ENULL);
        CHECK_MSG("match array is NULL");
        so3fft_destroy_correlation(pd);
        so3fftf_destroy_correlation(pf);
    }
    free(sig);
    free(pat);
    free(grid);
    free(sig_f);
    free(pat_f);
    free(grid_f);
}

int main(void) {
    bump bumps[NBUMPS];
    unsigned long long seed = 20260601ULL;
    int b, real;
    for (b = 0; b < NBUMPS; b++) {
        double v[3], n;
        do {
            v[0] = rnd(&seed);
            v[1] = rnd(&seed);
            v[2] = rnd(&seed);
            n = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
        } while (n < 0.1 || n > 1.0);
        bumps[b].mu[0] = v[0] / n;
        bumps[b].mu[1] = v[1] / n;
        bumps[b].mu[2] = v[2] / n;
        bumps[b].re = 1.0 + 0.5 * rnd(&seed);
        bumps[b].im = 0.5 * rnd(&seed);
    }
    for (real = 0; real < 2; real++) {
        known_optimum(bumps, real);
        twins(bumps, real);
    }
    refused();
    return finish("test_noise");
}
