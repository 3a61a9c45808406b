/* A downstream MPI program on the installed so3fft_mpi.h: a distributed round trip at B = 8
 * over the ranks of MPI_COMM_WORLD; exits non-zero on every rank if it fails on any. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include <so3fft_mpi.h>

int main(int argc, char **argv) {
    int rank, provided, bad = 0, any = 1;
    so3fft_shape s;
    so3fft_mpi_plan p;
    ptrdiff_t nc, ns, i;
    so3fft_complex *c, *x, *back;

    MPI_Init_thread(&argc, &argv, MPI_THREAD_SERIALIZED, &provided);
    MPI_Comm_rank(MPI_COMM_WORLD, &rank);
    s = so3fft_shape_default(8);
    /* Collective: NULL on every rank if it fails on one. */
    p = so3fft_mpi_plan_partial(&s, NULL, SO3FFT_ESTIMATE, MPI_COMM_WORLD);
    if (!p) {
        fprintf(stderr, "rank %d: %s\n", rank, so3fft_last_error());
        MPI_Finalize();
        return EXIT_FAILURE;
    }
    nc = so3fft_mpi_local_num_coeffs(p);
    ns = so3fft_mpi_local_num_samples(p);
    /* One more than needed: a rank may hold no coefficients, and calloc(0) may give NULL. */
    c = calloc((size_t)nc + 1, sizeof *c);
    x = calloc((size_t)ns + 1, sizeof *x);
    back = calloc((size_t)nc + 1, sizeof *back);
    if (!c || !x || !back) MPI_Abort(MPI_COMM_WORLD, EXIT_FAILURE);
    for (i = 0; i < nc; i++) {
        c[i][0] = (double)((rank + 3 * i) % 7) / 7.0;
        c[i][1] = (double)((rank + 5 * i) % 11) / 11.0;
    }
    if (so3fft_mpi_inverse(p, c, x) != SO3FFT_OK || so3fft_mpi_forward(p, x, back) != SO3FFT_OK) {
        fprintf(stderr, "rank %d: %s\n", rank, so3fft_last_error());
        bad = 1;
    }
    for (i = 0; i < nc && !bad; i++)
        if (fabs(back[i][0] - c[i][0]) + fabs(back[i][1] - c[i][1]) > 1e-12) bad = 1;
    MPI_Allreduce(&bad, &any, 1, MPI_INT, MPI_MAX, MPI_COMM_WORLD);
    so3fft_mpi_destroy_plan(p);
    free(c);
    free(x);
    free(back);
    MPI_Finalize();
    if (rank == 0) printf("so3fft_mpi downstream: %s\n", any ? "FAILED" : "OK");
    return any ? EXIT_FAILURE : EXIT_SUCCESS;
}
