/* Reader of the correlation reference files of tests/data/s2 (cor_*.txt): scalar lines
 * `key value`, sections `section NAME COUNT` of `j k re im` lines. Shared by the C tests of
 * the native matching API and of the SOFT layer's softFFTWCor2. */
#ifndef SO3FFT_S2_REFERENCE_H
#define SO3FFT_S2_REFERENCE_H

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

typedef struct {
    int bw, is_real, ii, jj, kk;
    double alpha, beta, gamma;
    double *sig, *pat; /* interleaved complex, (2bw)^2 values */
} cor_case;

/* Reads a cor_*.txt file: scalar lines `key value`, sections `section NAME COUNT` of
 * `j k re im` lines. 0 on success. */
static inline int read_case(const char *dir, const char *name, cor_case *c) {
    char path[1024], line[512], key[64];
    FILE *fp;
    double v;
    memset(c, 0, sizeof *c);
    snprintf(path, sizeof path, "%s/s2/%s", dir, name);
    fp = fopen(path, "r");
    if (!fp) {
        fprintf(stderr, "cannot open %s\n", path);
        return 1;
    }
    while (fgets(line, sizeof line, fp)) {
        int count, i;
        if (line[0] == '#') continue;
        if (sscanf(line, "section %63s %d", key, &count) == 2) {
            int n = 2 * c->bw;
            double *dst = (double *)calloc((size_t)(2 * n * n), sizeof(double));
            if (!dst || strcmp(key, "signal") * strcmp(key, "pattern") != 0) {
                free(dst);
                fclose(fp);
                return 1;
            }
            for (i = 0; i < count; i++) {
                int j, k;
                double re, im;
                if (!fgets(line, sizeof line, fp) ||
                    sscanf(line, "%d %d %lf %lf", &j, &k, &re, &im) != 4) {
                    fclose(fp);
                    free(dst);
                    return 1;
                }
                dst[2 * (j * n + k)] = re;
                dst[2 * (j * n + k) + 1] = im;
            }
            if (strcmp(key, "signal") == 0)
                c->sig = dst;
            else
                c->pat = dst;
        } else if (sscanf(line, "%63s %lf", key, &v) == 2) {
            if (!strcmp(key, "B")) c->bw = (int)v;
            if (!strcmp(key, "isReal")) c->is_real = (int)v;
            if (!strcmp(key, "ii")) c->ii = (int)v;
            if (!strcmp(key, "jj")) c->jj = (int)v;
            if (!strcmp(key, "kk")) c->kk = (int)v;
            if (!strcmp(key, "alpha")) c->alpha = v;
            if (!strcmp(key, "beta")) c->beta = v;
            if (!strcmp(key, "gamma")) c->gamma = v;
        }
    }
    fclose(fp);
    return c->sig && c->pat ? 0 : 1;
}

/* Real parts of an interleaved array (what a client passes for real data). */
static inline double *real_parts(const double *z, int n) {
    double *r = (double *)malloc((size_t)n * sizeof(double));
    int i;
    if (r)
        for (i = 0; i < n; i++) r[i] = z[2 * i];
    return r;
}

#endif /* SO3FFT_S2_REFERENCE_H */
