/* Issue 24, cases 2 and 3: planning and executing with little address space left.
 *
 * In a forked child the address space is capped (setrlimit(RLIMIT_AS)) at its current size
 * (/proc/self/statm) plus a headroom; the child then makes a plan and, if it was made,
 * executes a round trip on arrays allocated before the cap. Every outcome must be a success
 * or SO3FFT_ENOMEM (plan NULL, or execute returning it): no hang (the alarm), no abort
 * (FFTW's `alloc.c:29: assertion failed: p`), no other signal, no other error code.
 *
 *   attack_headroom estimate   ESTIMATE, 1 thread, B = 16 and 64: headroom 20 kB .. 24 MB
 *   attack_headroom measure    MEASURE, 2 threads, B = 64: headroom 30 .. 60 MB
 *   attack_headroom soft       the SOFT layer's Forward/Inverse_SO3_Naive_fftw_W (MEASURE,
 *                              2 threads, the layer's defaults) at B = 16 and 64 under caps:
 *                              either the output is right or the call printed its one error
 *                              line; no hang, no signal.
 *   attack_headroom range B estimate|measure|soft nthreads lo_MB hi_MB step_MB
 *                              any sweep (for measuring the margin; not a CTest case)
 * Each line of output gives the headroom and the outcome, so the margin FFTW needs can be
 * read off. Seen on main (FFTW 3.3.10): ESTIMATE B = 16 aborts at 22-154 kB (FFTW's alloc.c)
 * and 172-271 kB (a Rust infallible allocation in plan/blocks.rs); B = 64 aborts at
 * 0.84-1.06 MB; MEASURE 2 threads B = 64 aborts at 40.5 MB and hangs at 42-48 MB (FFTW's
 * fftw_spawn_loop waiting for a thread it could not start); the SOFT `_W` calls hang at
 * 9-13 MB (B = 16) and 42-48 MB (B = 64). */
#define _POSIX_C_SOURCE 200809L
#include <fcntl.h>
#include <fftw3.h>

#include "attack.h"
#include "wrap_fftw.h"

enum { ST_OK = 0, ST_ENOMEM_PLAN = 10, ST_ENOMEM_EXEC = 11, ST_BADCODE = 1, ST_WRONG = 2,
       ST_SETUP = 3, ST_SOFT_ERR = 12 };

typedef struct {
    int b, flags, nthreads, soft;
    size_t headroom;
} job;

static int native_body(void *arg) {
    job *j = (job *)arg;
    size_t nc = so3fft_num_coeffs(j->b), ns = so3fft_num_samples(j->b);
    so3fft_complex *c = alloc_cx(nc), *c2 = alloc_cx(nc), *s = alloc_cx(ns);
    so3fft_plan p;
    int r;
    double err;
    fill_random(c, nc, 7);
    memset(s, 0, ns * sizeof *s);
    memset(c2, 0, nc * sizeof *c2);
    if (cap_address_space(j->headroom) != 0) return ST_SETUP;
    p = so3fft_plan_general(j->b, SO3FFT_BOTH, NULL, NULL, (unsigned)j->flags, j->nthreads);
    if (!p) {
        if (so3fft_last_error_code() == SO3FFT_ENOMEM) return ST_ENOMEM_PLAN;
        fprintf(stderr, "plan NULL with code %d \"%s\"\n", so3fft_last_error_code(),
                so3fft_last_error());
        return ST_BADCODE;
    }
    r = so3fft_execute_inverse(p, c, s);
    if (r == SO3FFT_OK) r = so3fft_execute_forward(p, s, c2);
    so3fft_destroy_plan(p);
    if (r == SO3FFT_ENOMEM) return ST_ENOMEM_EXEC;
    if (r != SO3FFT_OK) return ST_BADCODE;
    err = max_abs_diff(c, c2, nc);
    return err <= 1e-10 ? ST_OK : ST_WRONG;
}

/* The SOFT layer has no error channel: a failed call prints one line to stderr. The child's
 * stderr goes to a file made before the cap, whose size tells whether a line was printed. */
static int soft_body(void *arg) {
    job *j = (job *)arg;
    size_t nc = (size_t)(4 * j->b * j->b * j->b - j->b) / 3, ns = (size_t)8 * j->b * j->b * j->b;
    fftw_complex *c = (fftw_complex *)malloc(nc * sizeof(fftw_complex));
    fftw_complex *c2 = (fftw_complex *)malloc(nc * sizeof(fftw_complex));
    fftw_complex *s = (fftw_complex *)malloc(ns * sizeof(fftw_complex));
    char path[] = "/tmp/so3fft_attack_XXXXXX";
    int fd = mkstemp(path);
    off_t before, after;
    if (!c || !c2 || !s || fd < 0) return ST_SETUP;
    unlink(path);
    fflush(stderr);
    dup2(fd, 2);
    fill_random((so3fft_complex *)c, nc, 9);
    memset(s, 0, ns * sizeof *s);
    memset(c2, 0, nc * sizeof *c2);
    before = lseek(fd, 0, SEEK_END);
    if (cap_address_space(j->headroom) != 0) return ST_SETUP;
    Inverse_SO3_Naive_fftw_W(j->b, c, s, 0);
    Forward_SO3_Naive_fftw_W(j->b, s, c2, 0);
    after = lseek(fd, 0, SEEK_END);
    if (max_abs_diff((so3fft_complex *)c, (so3fft_complex *)c2, nc) <= 1e-10) return ST_OK;
    return after > before ? ST_SOFT_ERR : ST_WRONG;
}

static int g_counts[5]; /* ok, enomem, hang, signal, other */

static void sweep(int b, int flags, int nthreads, int soft, size_t lo, size_t hi, double mul,
                  size_t step, unsigned alarm_s) {
    job j;
    size_t h;
    char buf[64];
    j.b = b;
    j.flags = flags;
    j.nthreads = nthreads;
    j.soft = soft;
    for (h = lo; h <= hi; h = mul > 1.0 ? (size_t)((double)h * mul) : h + step) {
        double t0 = now_s();
        int o;
        const char *verdict;
        j.headroom = h;
        o = run_forked(soft ? soft_body : native_body, &j, alarm_s);
        if (o == ST_OK) {
            verdict = "ok: plan and round trip";
            g_counts[0]++;
        } else if (o == ST_ENOMEM_PLAN || o == ST_ENOMEM_EXEC || o == ST_SOFT_ERR) {
            verdict = o == ST_ENOMEM_PLAN ? "ok: SO3FFT_ENOMEM from the planner"
                      : o == ST_ENOMEM_EXEC ? "ok: SO3FFT_ENOMEM from execute"
                                            : "ok: SOFT layer reported an error";
            g_counts[1]++;
        } else if (o == OUT_HANG) {
            verdict = "FAIL: hang";
            g_counts[2]++;
            g_failures++;
        } else if (o < 0) {
            verdict = "FAIL: killed by a signal";
            g_counts[3]++;
            g_failures++;
        } else {
            verdict = o == ST_WRONG ? "FAIL: wrong result without an error"
                      : o == ST_BADCODE ? "FAIL: error code other than SO3FFT_ENOMEM"
                                        : "FAIL: test set-up";
            g_counts[4]++;
            g_failures++;
        }
        printf("%s B=%d %s %d thread(s) headroom %8.3f MB: %-14s %s (%.2f s)\n",
               soft ? "SOFT _W" : "native", b, flags ? "MEASURE " : "ESTIMATE", nthreads,
               (double)h / 1e6, outcome_name(o, buf, sizeof buf), verdict, now_s() - t0);
        fflush(stdout);
    }
}

int main(int argc, char **argv) {
    const char *mode = argc > 1 ? argv[1] : "estimate";
    /* the SOFT layer's plans: MEASURE on two threads whatever the machine */
    setenv("SO3FFT_SOFT_THREADS", "2", 1);
    setenv("SO3FFT_SOFT_RIGOR", "measure", 1);
    if (strcmp(mode, "estimate") == 0) {
        sweep(16, SO3FFT_ESTIMATE, 1, 0, 20000, 24000000, 1.12, 0, 5);
        sweep(64, SO3FFT_ESTIMATE, 1, 0, 20000, 24000000, 1.12, 0, 5);
    } else if (strcmp(mode, "measure") == 0) {
        sweep(64, SO3FFT_MEASURE, 2, 0, 30000000, 60000000, 0.0, 2000000, 4);
    } else if (strcmp(mode, "soft") == 0) {
        sweep(16, 1, 2, 1, 1000000, 41000000, 0.0, 4000000, 4);
        sweep(64, 1, 2, 1, 30000000, 60000000, 0.0, 3000000, 4);
    } else if (strcmp(mode, "range") == 0 && argc == 8) {
        /* range B estimate|measure|soft nthreads lo_MB hi_MB step_MB: for measuring margins */
        int soft = strcmp(argv[3], "soft") == 0;
        sweep(atoi(argv[2]), soft || strcmp(argv[3], "measure") == 0, atoi(argv[4]), soft,
              (size_t)(atof(argv[5]) * 1e6), (size_t)(atof(argv[6]) * 1e6), 0.0,
              (size_t)(atof(argv[7]) * 1e6), 8);
    } else {
        fprintf(stderr, "usage: attack_headroom estimate|measure|soft\n");
        return 2;
    }
    printf("attack_headroom %s: %d ok, %d ENOMEM/reported, %d hang, %d signal, %d other\n", mode,
           g_counts[0], g_counts[1], g_counts[2], g_counts[3], g_counts[4]);
    return finish("attack_headroom");
}
