/*
 * One precision of the FFT stage model (see fft_stage_f32.c): included twice, with
 *   R      the real type (double, float),
 *   X(n)   FFTW's name of that precision (fftw_n, fftwf_n),
 *   P(n)   this file's names of that precision (n_f64, n_f32).
 *
 * The transform set is src/engine/fft_stage.rs's for a full transform (N = B - 1, every
 * order present), and the copies around it are src/engine/copies.rs's.
 */

/* The plans of one slice shape (FftStage). */
typedef struct {
    int na, ng, n, rs, hs;   /* rows, row length, N, row strides of work and half buffers */
    long nslots;             /* (2N + 1)^2 values of a slice's lane row */
    X(plan) inv_cols[2], fwd_cols[2], inv_rows, fwd_rows;
    X(plan) r2c, c2r, cols_minus, cols_plus;
} P(stage);

/* One worker's buffers: work and half buffers, and K distinct slices in the output and
 * lane-row rings (so that successive slices are not in the cache, as in a transform). */
typedef struct {
    X(complex) *w, *half;
    X(complex) *out;    /* K slices of na ng complex values (the caller's samples) */
    R *outr;            /* K slices of na ng reals (real samples) */
    X(complex) *lanes;  /* K lane rows of nslots values (the DWT stage's side) */
    int k;
    /* Seconds in the parts of the complex stage (see PART_NAMES), summed over slices. */
    double part[NPARTS];
} P(work);

static void *P(alloc)(size_t bytes) {
    void *p = NULL;
    if (posix_memalign(&p, 4096, bytes ? bytes : 1) != 0) {
        fprintf(stderr, "out of memory (%zu bytes)\n", bytes);
        exit(1);
    }
    memset(p, 0, bytes);
    return p;
}

static X(plan) P(check)(X(plan) p, const char *what) {
    if (!p) {
        fprintf(stderr, "could not plan %s\n", what);
        exit(1);
    }
    return p;
}

/* Columns c .. c + howmany of the work buffer (stride `stride`) over alpha, in place. */
static X(plan) P(col_plan)(X(complex) *buf, int na, int howmany, int at, int stride, int sign,
                           unsigned flags) {
    if (howmany == 0) return NULL;
    return P(check)(X(plan_many_dft)(1, &na, howmany, buf + at, NULL, stride, 1, buf + at, NULL,
                                     stride, 1, sign, flags),
                    "columns");
}

/* The plans of FftStage::new for B, rows padded by `pad` complex values, planned with
 * `flags` on page-aligned buffers like the engine's. */
static void P(stage_new)(P(stage) *s, int b, int pad, int real, unsigned flags) {
    int na = 2 * b, ng = 2 * b, n = b - 1;
    s->na = na, s->ng = ng, s->n = n, s->rs = ng + pad, s->hs = ng / 2 + 1 + pad;
    s->nslots = (long)(2 * n + 1) * (2 * n + 1);
    X(complex) *a = P(alloc)(sizeof(X(complex)) * na * s->rs);
    X(complex) *bb = P(alloc)(sizeof(X(complex)) * na * s->rs);
    s->inv_cols[0] = P(col_plan)(a, na, n + 1, 0, s->rs, FFTW_FORWARD, flags);
    s->inv_cols[1] = P(col_plan)(a, na, n, ng - n, s->rs, FFTW_FORWARD, flags);
    s->fwd_cols[0] = P(col_plan)(a, na, n + 1, 0, s->rs, FFTW_BACKWARD, flags);
    s->fwd_cols[1] = P(col_plan)(a, na, n, ng - n, s->rs, FFTW_BACKWARD, flags);
    /* 2N + 1 >= ng / 2: the inverse's rows run in place, then stream to the slice. */
    s->inv_rows = P(check)(X(plan_many_dft)(1, &ng, na, a, NULL, 1, s->rs, a, NULL, 1, s->rs,
                                            FFTW_FORWARD, flags),
                           "rows");
    s->fwd_rows = P(check)(X(plan_many_dft)(1, &ng, na, a, NULL, 1, s->rs, a, NULL, 1, s->rs,
                                            FFTW_BACKWARD, flags),
                           "rows");
    s->r2c = s->c2r = s->cols_minus = s->cols_plus = NULL;
    if (real) {
        R *reals = (R *)bb;
        s->r2c = P(check)(X(plan_many_dft_r2c)(1, &ng, na, reals, NULL, 1, ng, a, NULL, 1, s->hs,
                                               flags | FFTW_PRESERVE_INPUT),
                          "r2c");
        s->c2r = P(check)(X(plan_many_dft_c2r)(1, &ng, na, a, NULL, 1, s->hs, reals, NULL, 1, ng,
                                               flags),
                          "c2r");
        s->cols_minus = P(col_plan)(a, na, n + 1, 0, s->hs, FFTW_FORWARD, flags);
        s->cols_plus = P(col_plan)(a, na, n + 1, 0, s->hs, FFTW_BACKWARD, flags);
    }
    free(a);
    free(bb);
}

static void P(stage_free)(P(stage) *s) {
    X(plan) all[] = {s->inv_cols[0], s->inv_cols[1], s->fwd_cols[0], s->fwd_cols[1], s->inv_rows,
                     s->fwd_rows, s->r2c, s->c2r, s->cols_minus, s->cols_plus};
    for (size_t i = 0; i < sizeof all / sizeof all[0]; i++)
        if (all[i]) X(destroy_plan)(all[i]);
}

static void P(work_new)(P(work) *w, const P(stage) *s, int k, int real) {
    size_t slice = (size_t)s->na * s->ng;
    w->k = k;
    w->w = P(alloc)(sizeof(X(complex)) * s->na * s->rs);
    w->half = P(alloc)(sizeof(X(complex)) * s->na * s->hs);
    w->out = real ? NULL : P(alloc)(sizeof(X(complex)) * slice * k);
    w->outr = real ? P(alloc)(sizeof(R) * slice * k) : NULL;
    w->lanes = P(alloc)(sizeof(X(complex)) * s->nslots * k);
    /* Deterministic lane values in [-1, 1). */
    unsigned long long x = 12345;
    for (long i = 0; i < s->nslots * k; i++)
        for (int c = 0; c < 2; c++) {
            x = x * 6364136223846793005ULL + 1442695040888963407ULL;
            w->lanes[i][c] = (R)((double)(x >> 11) / (double)(1ULL << 52) - 1.0);
        }
}

static void P(work_free)(P(work) *w) {
    free(w->w);
    free(w->half);
    free(w->out);
    free(w->outr);
    free(w->lanes);
}

/* copy_rows: `rows` rows of `len` values; streaming stores where the destination allows. */
static void P(copy_rows)(const X(complex) *src, int ss, X(complex) *dst, int ds, int rows,
                         int len, int stream) {
    size_t row = sizeof(X(complex)) * len;
    if (stream && ((uintptr_t)dst % 16 == 0) && (sizeof(X(complex)) * ds) % 16 == 0 &&
        row % 16 == 0) {
        for (int r = 0; r < rows; r++) {
            const char *s = (const char *)(src + (size_t)r * ss);
            char *d = (char *)(dst + (size_t)r * ds);
            for (size_t i = 0; i < row; i += 16)
                _mm_stream_si128((__m128i *)(d + i), _mm_loadu_si128((const __m128i *)(s + i)));
        }
        _mm_sfence();
        return;
    }
    for (int r = 0; r < rows; r++)
        memcpy(dst + (size_t)r * ds, src + (size_t)r * ss, row);
}

/* Complex inverse of lane row `k` into output slice `k` (Engine::scatter + FftStage::inverse). */
static void P(inverse)(const P(stage) *s, P(work) *wk, const slots *t, int k, double *tc) {
    X(complex) *w = wk->w, *out = wk->out + (size_t)k * s->na * s->ng;
    {
        double t0 = now();
        /* The row and column M, M' = B that no slot fills (zero before the transform). */
        memset(w + (size_t)(s->na / 2) * s->rs, 0, sizeof(X(complex)) * s->ng);
        for (int r = 0; r < s->na; r++) w[(size_t)r * s->rs + s->ng / 2][0] = w[(size_t)r * s->rs + s->ng / 2][1] = 0;
        const X(complex) *lane = wk->lanes + (size_t)k * s->nslots;
        for (long i = 0; i < t->n; i++) {
            X(complex) *d = w + t->work[i];
            (*d)[0] = lane[t->at[i]][0];
            (*d)[1] = lane[t->at[i]][1];
        }
        *tc += now() - t0;
    }
    double t0 = now(), t1, t2, t3;
    X(execute_dft)(s->inv_cols[0], w, w);
    X(execute_dft)(s->inv_cols[1], w + (s->ng - s->n), w + (s->ng - s->n));
    t1 = now();
    X(execute_dft)(s->inv_rows, w, w);
    t2 = now();
    P(copy_rows)(w, s->rs, out, s->ng, s->na, s->ng, 1);
    t3 = now();
    wk->part[0] += t1 - t0, wk->part[1] += t2 - t1, wk->part[2] += t3 - t2;
}

/* Complex forward of output slice `k` into lane row `k` (FftStage::forward + Engine::gather). */
static void P(forward)(const P(stage) *s, P(work) *wk, const slots *t, int k, double *tc,
                       R weight) {
    X(complex) *w = wk->w, *in = wk->out + (size_t)k * s->na * s->ng;
    double t0 = now(), t1, t2, t3;
    P(copy_rows)(in, s->ng, w, s->rs, s->na, s->ng, 0);
    t1 = now();
    X(execute_dft)(s->fwd_rows, w, w);
    t2 = now();
    X(execute_dft)(s->fwd_cols[0], w, w);
    X(execute_dft)(s->fwd_cols[1], w + (s->ng - s->n), w + (s->ng - s->n));
    t3 = now();
    wk->part[3] += t1 - t0, wk->part[4] += t2 - t1, wk->part[5] += t3 - t2;
    {
        double t0 = now();
        X(complex) *lane = wk->lanes + (size_t)k * s->nslots;
        for (long i = 0; i < t->n; i++) {
            const X(complex) *v = w + t->work[i];
            lane[t->at[i]][0] = (*v)[0] * weight;
            lane[t->at[i]][1] = (*v)[1] * weight;
        }
        *tc += now() - t0;
    }
}

/* Real inverse (Engine::scatter_real + FftStage::inverse_real). */
static void P(inverse_real)(const P(stage) *s, P(work) *wk, const slots *t, int k, double *tc) {
    X(complex) *h = wk->half;
    R *out = wk->outr + (size_t)k * s->na * s->ng;
    {
        double t0 = now();
        /* Row M = B and column M' = B (c2r destroys its input: cleared every slice). */
        memset(h + (size_t)(s->na / 2) * s->hs, 0, sizeof(X(complex)) * (s->ng / 2 + 1));
        for (int r = 0; r < s->na; r++) h[(size_t)r * s->hs + s->ng / 2][0] = h[(size_t)r * s->hs + s->ng / 2][1] = 0;
        const X(complex) *lane = wk->lanes + (size_t)k * s->nslots;
        for (long i = 0; i < t->n; i++) {
            unsigned idx = t->real[i];
            if (idx & CONJ) continue;
            h[idx][0] = lane[t->at[i]][0];
            h[idx][1] = -lane[t->at[i]][1];
        }
        *tc += now() - t0;
    }
    X(execute_dft)(s->cols_plus, h, h);
    X(execute_dft_c2r)(s->c2r, h, out);
}

/* Real forward (FftStage::forward_real + Engine::gather_real). */
static void P(forward_real)(const P(stage) *s, P(work) *wk, const slots *t, int k, double *tc,
                            R weight) {
    X(complex) *h = wk->half;
    R *in = wk->outr + (size_t)k * s->na * s->ng;
    X(execute_dft_r2c)(s->r2c, in, h);
    X(execute_dft)(s->cols_minus, h, h);
    {
        double t0 = now();
        X(complex) *lane = wk->lanes + (size_t)k * s->nslots;
        for (long i = 0; i < t->n; i++) {
            unsigned idx = t->real[i];
            const X(complex) *v = h + (idx & ~CONJ);
            R im = (idx & CONJ) ? (*v)[1] : -(*v)[1];
            lane[t->at[i]][0] = (*v)[0] * weight;
            lane[t->at[i]][1] = im * weight;
        }
        *tc += now() - t0;
    }
}

/* The worker's K slices, each inverse then forward; adds the seconds spent in the
 * scatters and gathers (with their clears) to `*tc`. The weight makes each round trip the
 * identity, so the values stay of one size however often the slices are transformed. */
static void P(run)(const P(stage) *s, P(work) *wk, const slots *t, int real, double *tc) {
    R weight = (R)(1.0 / ((double)s->na * s->ng));
    for (int k = 0; k < wk->k; k++) {
        if (real) {
            P(inverse_real)(s, wk, t, k, tc);
            P(forward_real)(s, wk, t, k, tc, weight);
        } else {
            P(inverse)(s, wk, t, k, tc);
            P(forward)(s, wk, t, k, tc, weight);
        }
    }
}

/* Complex round trip of lane row 0 (weight 1 / (na ng)): max relative change of the slots
 * (a check that the model is a transform and its inverse). */
static double P(round_trip_error)(const P(stage) *s, P(work) *wk, const slots *t) {
    size_t n = (size_t)s->nslots;
    double *keep = malloc(sizeof(double) * 2 * n), err = 0, big = 0;
    for (size_t i = 0; i < n; i++) keep[2 * i] = wk->lanes[i][0], keep[2 * i + 1] = wk->lanes[i][1];
    double tc = 0;
    P(inverse)(s, wk, t, 0, &tc);
    P(forward)(s, wk, t, 0, &tc, (R)(1.0 / ((double)s->na * s->ng)));
    for (size_t i = 0; i < 2 * n; i++) {
        double d = fabs((double)((R *)wk->lanes)[i] - keep[i]);
        err = d > err ? d : err;
        big = fabs(keep[i]) > big ? fabs(keep[i]) : big;
    }
    free(keep);
    return err / big;
}
