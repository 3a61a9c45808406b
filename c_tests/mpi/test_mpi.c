/* Distributed plans through the C API (include/so3fft_mpi.h), run under mpirun -np 1..4 by
 * scripts/test.sh: every rank's part of an order-limited shape against a single-process
 * partial plan (bitwise: the same kernel lanes and sums), a plan run in groups of pairs
 * (to rounding), real transforms, and collective errors (a NULL array on one rank,
 * different shapes). */
#include <mpi.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "so3fft_mpi.h"
#include "../check.h"

static so3fft_complex *alloc_cx(ptrdiff_t n) {
    so3fft_complex *p = (so3fft_complex *)calloc((size_t)(n > 0 ? n : 1), sizeof(so3fft_complex));
    if (!p) exit(EXIT_FAILURE);
    return p;
}

int main(int argc, char **argv) {
    int rank, size, provided, j0 = -1, j1 = -1, t, l, m, mp;
    unsigned long long seed = 5;
    so3fft_shape s;
    so3fft_partial_options o;
    so3fft_partial single;
    so3fft_mpi_plan p;
    ptrdiff_t nc, ns, sl, lnc, lns, i;
    so3fft_complex *c, *x, *lc, *lx, *back;
    /* Before MPI_Init: a clear error, not a crash inside MPI (the Fortran-handle planner: the
     * header's one converts the communicator, which MPI forbids before MPI_Init). */
    s = so3fft_shape_default(4);
    CHECK(so3fft_mpi_plan_partial_fortran(&s, NULL, SO3FFT_ESTIMATE, 0) == NULL);
    CHECK(so3fft_last_error_code() == SO3FFT_EINVAL);
    CHECK(strstr(so3fft_last_error(), "MPI is not initialised") != NULL);

    MPI_Init_thread(&argc, &argv, MPI_THREAD_SERIALIZED, &provided);
    MPI_Comm_rank(MPI_COMM_WORLD, &rank);
    MPI_Comm_size(MPI_COMM_WORLD, &size);

    s = so3fft_shape_default(10);
    s.m_max = 6;
    s.mp_max = 4;
    s.B_grid = 11;
    s.n_alpha = 13;
    s.n_gamma = 9;
    memset(&o, 0, sizeof o);
    o.nthreads = 1;
    single = so3fft_plan_partial(&s, &o, SO3FFT_ESTIMATE | SO3FFT_REAL);
    p = so3fft_mpi_plan_partial(&s, &o, SO3FFT_ESTIMATE | SO3FFT_REAL, MPI_COMM_WORLD);
    CHECK(single != NULL && p != NULL);
    nc = so3fft_partial_num_coeffs(single);
    ns = so3fft_partial_num_samples(single);
    sl = (ptrdiff_t)s.n_alpha * s.n_gamma;
    CHECK(so3fft_mpi_local_pairs(p, &j0, &j1) == SO3FFT_OK && 0 <= j0 && j0 <= j1 && j1 <= 11);
    lnc = so3fft_mpi_local_num_coeffs(p);
    lns = so3fft_mpi_local_num_samples(p);
    CHECK(lns == 2 * (j1 - j0) * sl && lnc >= 0);
    c = alloc_cx(nc);
    back = alloc_cx(lnc);
    x = alloc_cx(ns);
    lc = alloc_cx(lnc);
    lx = alloc_cx(lns);
    for (i = 0; i < nc; i++) {
        c[i][0] = rnd(&seed);
        c[i][1] = rnd(&seed);
    }
    /* This rank's coefficients, from the global array. */
    for (l = 0; l < s.L; l++)
        for (m = -s.m_max; m <= s.m_max; m++)
            for (mp = -s.mp_max; mp <= s.mp_max; mp++) {
                int owner = -1;
                ptrdiff_t gi = so3fft_shape_coef_index(&s, l, m, mp);
                ptrdiff_t at = so3fft_mpi_coef_owner(p, l, m, mp, &owner);
                CHECK((gi < 0) == (at < 0));
                if (gi >= 0 && owner == rank) {
                    CHECK(at < lnc);
                    memcpy(lc[at], c[gi], sizeof(so3fft_complex));
                }
            }
    /* Complex: the local slices of the single-process inverse, bitwise. */
    CHECK(so3fft_partial_inverse(single, c, x) == SO3FFT_OK);
    CHECK(so3fft_mpi_inverse(p, lc, lx) == SO3FFT_OK);
    for (t = 0; t < 2 * (j1 - j0); t++) {
        int k = t < j1 - j0 ? j0 + t : 2 * 11 - j1 + (t - (j1 - j0));
        CHECK(memcmp(lx + t * sl, x + k * sl, (size_t)sl * sizeof(so3fft_complex)) == 0);
    }
    /* Round trip. */
    CHECK(so3fft_mpi_forward(p, lx, back) == SO3FFT_OK);
    {
        double e = 0.0, all = 0.0;
        for (i = 0; i < lnc; i++) {
            double d = fabs(back[i][0] - lc[i][0]) + fabs(back[i][1] - lc[i][1]);
            if (d > e) e = d;
        }
        MPI_Allreduce(&e, &all, 1, MPI_DOUBLE, MPI_MAX, MPI_COMM_WORLD);
        CHECK(all < 1e-12);
    }
    CHECK(so3fft_mpi_groups(p) == 1 && so3fft_mpi_local_workspace(p) >= 0);
    /* A small workspace cap: the pairs run in groups; the same round trip. */
    {
        so3fft_partial_options small = o;
        so3fft_mpi_plan pg;
        double e = 0.0, all = 0.0;
        small.max_workspace = 1;
        pg = so3fft_mpi_plan_partial(&s, &small, SO3FFT_ESTIMATE, MPI_COMM_WORLD);
        CHECK(pg != NULL);
        if (pg) {
            CHECK(so3fft_mpi_groups(pg) > 1);
            CHECK(so3fft_mpi_inverse(pg, lc, lx) == SO3FFT_OK);
            for (t = 0; t < 2 * (j1 - j0); t++) {
                int k = t < j1 - j0 ? j0 + t : 2 * 11 - j1 + (t - (j1 - j0));
                for (i = 0; i < sl; i++) {
                    double d = fabs(lx[t * sl + i][0] - x[k * sl + i][0]) +
                               fabs(lx[t * sl + i][1] - x[k * sl + i][1]);
                    if (d > e) e = d;
                }
            }
            CHECK(so3fft_mpi_forward(pg, lx, back) == SO3FFT_OK);
            for (i = 0; i < lnc; i++) {
                double d = fabs(back[i][0] - lc[i][0]) + fabs(back[i][1] - lc[i][1]);
                if (d > e) e = d;
            }
            MPI_Allreduce(&e, &all, 1, MPI_DOUBLE, MPI_MAX, MPI_COMM_WORLD);
            CHECK(all < 1e-12);
            so3fft_mpi_destroy_plan(pg);
        }
    }
    /* A NULL array on one rank: every rank gets the same error code. */
    CHECK(so3fft_mpi_inverse(p, lc, rank == size - 1 ? NULL : lx) == SO3FFT_EINVAL);
    so3fft_mpi_destroy_plan(p);
    /* Different shapes on the ranks: NULL on every rank (with more than one rank). */
    if (size > 1) {
        so3fft_shape t2 = so3fft_shape_default(rank == 0 ? 6 : 7);
        CHECK(so3fft_mpi_plan_partial(&t2, NULL, 0, MPI_COMM_WORLD) == NULL);
        CHECK(so3fft_last_error_code() == SO3FFT_EINVAL);
    }
    /* A bad shape on one rank only. */
    {
        so3fft_shape bad = so3fft_shape_default(6);
        if (rank == 0) bad.n_alpha = 3;
        CHECK(so3fft_mpi_plan_partial(&bad, NULL, 0, MPI_COMM_WORLD) == NULL);
    }
    so3fft_destroy_partial(single);
    free(c);
    free(back);
    free(x);
    free(lc);
    free(lx);
    {
        int mine = g_failures, total = 0;
        MPI_Allreduce(&mine, &total, 1, MPI_INT, MPI_SUM, MPI_COMM_WORLD);
        MPI_Finalize();
        if (rank == 0) printf("test_mpi on %d ranks: %s\n", size, total ? "FAILED" : "all checks passed");
        return total ? EXIT_FAILURE : EXIT_SUCCESS;
    }
}
