/* Issue 24, "Also": a caller thread with a small stack makes a MEASURE plan.
 *
 * The caller's thread runs the FFTW planner (and, with MEASURE, FFTW's timing of candidate
 * plans, which puts buffers on the stack), so the planner needs some stack in the caller.
 * Each case runs a thread created with pthread_attr_setstacksize in a forked child with an
 * alarm; the thread makes a plan (MEASURE, 1 and 2 threads; B = 16 and 64) and runs a round
 * trip. A stack overflow is a SIGSEGV of the child.
 *
 *   attack_stack            asserts success at SAFE_STACK (the size to document)
 *   attack_stack sweep [B...]  prints the outcome for stacks of 16 KiB .. 1 MiB (information:
 *                           the smallest stack that works) */
#define _POSIX_C_SOURCE 200809L
#include <limits.h>
#include <pthread.h>

#include "attack.h"

/* The stack a caller's thread needs for so3fft's planners, with margin. Measured on main
 * (FFTW 3.3.10, x86-64, `attack_stack sweep 16 64 128 256`): ESTIMATE works from 16 KiB
 * (B = 16, 128, 256) or 24 KiB (B = 64); MEASURE needs 32 KiB at B = 16 and 48 KiB at
 * B = 64, 128, 256 (1 and 2 threads; smaller stacks: SIGSEGV). FFTW itself may put buffers
 * of up to 64 KiB on the stack (MAX_STACK_ALLOC), hence 256 KiB as the documented size. */
#define SAFE_STACK ((size_t)256 * 1024)

typedef struct {
    size_t stack;
    int b, flags, nthreads, rc;
} job;

static void *plan_thread(void *arg) {
    job *j = (job *)arg;
    so3fft_plan p = so3fft_plan_general(j->b, SO3FFT_BOTH, NULL, NULL, (unsigned)j->flags,
                                        j->nthreads);
    if (!p) {
        j->rc = 1;
        return NULL;
    }
    j->rc = round_trip(p, j->b, 3);
    so3fft_destroy_plan(p);
    return NULL;
}

static int body(void *arg) {
    job *j = (job *)arg;
    pthread_attr_t a;
    pthread_t t;
    j->rc = 9;
    if (pthread_attr_init(&a) != 0 || pthread_attr_setstacksize(&a, j->stack) != 0) return 8;
    if (pthread_create(&t, &a, plan_thread, j) != 0) return 7;
    pthread_join(t, NULL);
    return j->rc;
}

static int one(size_t stack, int b, int flags, int nthreads, int verbose) {
    job j;
    char buf[64];
    int o;
    j.stack = stack;
    j.b = b;
    j.flags = flags;
    j.nthreads = nthreads;
    o = run_forked(body, &j, 20);
    if (verbose || o != 0)
        printf("stack %4lu KiB, B=%d %s, %d thread(s): %s\n", (unsigned long)(stack >> 10), b,
               flags ? "MEASURE " : "ESTIMATE", nthreads, outcome_name(o, buf, sizeof buf));
    return o;
}

int main(int argc, char **argv) {
    static const int bs[] = {16, 64};
    unsigned i, k;
    int t, f;
    if (argc > 1 && strcmp(argv[1], "sweep") == 0) {
        static const size_t kib[] = {16, 24, 32, 48, 64, 80, 96, 112, 128, 160, 192, 256, 512, 1024};
        int a, nb = argc > 2 ? argc - 2 : 2;
        for (f = 0; f <= 1; f++)
            for (a = 0; a < nb; a++)
                for (t = 1; t <= 2; t++)
                    for (k = 0; k < sizeof kib / sizeof kib[0]; k++)
                        if (one(kib[k] << 10, argc > 2 ? atoi(argv[2 + a]) : bs[a], f, t, 1) == 0)
                            break;
        return 0;
    }
    for (i = 0; i < 2; i++)
        for (t = 1; t <= 2; t++)
            if (one(SAFE_STACK, bs[i], SO3FFT_MEASURE, t, 1) != 0) g_failures++;
    return finish("attack_stack");
}
