/* Helpers of the attack tests (issue 24): every case runs in a child made by fork() with an
 * alarm, and the parent classifies how it ended, so a hang or an abort fails the case instead
 * of stalling or killing the test program. */
#ifndef SO3FFT_ATTACK_H
#define SO3FFT_ATTACK_H

#include <errno.h>
#include <signal.h>
#include <stdio.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/types.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include "../test_util.h"

/* How a child ended: its exit code (>= 0), OUT_HANG (its alarm fired), or -signal. */
enum { OUT_HANG = -1000, OUT_NOFORK = -1001 };

static inline const char *outcome_name(int o, char *buf, size_t n) {
    if (o == OUT_HANG)
        snprintf(buf, n, "HANG (alarm)");
    else if (o == OUT_NOFORK)
        snprintf(buf, n, "fork failed");
    else if (o < 0)
        snprintf(buf, n, "SIGNAL %d (%s)", -o, strsignal(-o));
    else
        snprintf(buf, n, "exit %d", o);
    return buf;
}

/* Waits for `pid` and classifies its end. */
static inline int wait_outcome(pid_t pid) {
    int status = 0;
    while (waitpid(pid, &status, 0) != pid) {
        if (errno != EINTR) return OUT_NOFORK;
    }
    if (WIFEXITED(status)) return WEXITSTATUS(status);
    if (WIFSIGNALED(status)) return WTERMSIG(status) == SIGALRM ? OUT_HANG : -WTERMSIG(status);
    return OUT_NOFORK;
}

/* Runs body(arg) in a forked child that has `seconds` to finish; returns its outcome. */
static inline int run_forked(int (*body)(void *), void *arg, unsigned seconds) {
    pid_t pid;
    fflush(NULL);
    pid = fork();
    if (pid < 0) return OUT_NOFORK;
    if (pid == 0) {
        int rc;
        signal(SIGALRM, SIG_DFL);
        alarm(seconds);
        rc = body(arg);
        fflush(NULL);
        _exit(rc);
    }
    return wait_outcome(pid);
}

/* Current virtual memory size of this process in bytes (/proc/self/statm). */
static inline size_t vm_size(void) {
    unsigned long pages = 0;
    FILE *f = fopen("/proc/self/statm", "r");
    if (f) {
        if (fscanf(f, "%lu", &pages) != 1) pages = 0;
        fclose(f);
    }
    return (size_t)pages * (size_t)sysconf(_SC_PAGESIZE);
}

/* Caps the address space at the current size plus `headroom` bytes; 0 on success. */
static inline int cap_address_space(size_t headroom) {
    struct rlimit rl;
    size_t now = vm_size();
    if (now == 0) return -1;
    rl.rlim_cur = rl.rlim_max = (rlim_t)(now + headroom);
    return setrlimit(RLIMIT_AS, &rl);
}

static inline void sleep_us(long us) {
    struct timespec ts;
    ts.tv_sec = us / 1000000;
    ts.tv_nsec = (us % 1000000) * 1000;
    while (nanosleep(&ts, &ts) != 0 && errno == EINTR) {
    }
}

static inline double now_s(void) {
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* Inverse then forward of random coefficients with plan `p` (made with SO3FFT_BOTH) at
 * bandwidth b: 0 if the round trip holds, else 1 (error message on stderr). */
static inline int round_trip(so3fft_plan p, int b, unsigned long long seed) {
    size_t nc = so3fft_num_coeffs(b), ns = so3fft_num_samples(b);
    so3fft_complex *c = (so3fft_complex *)malloc(nc * sizeof(so3fft_complex));
    so3fft_complex *c2 = (so3fft_complex *)malloc(nc * sizeof(so3fft_complex));
    so3fft_complex *s = (so3fft_complex *)malloc(ns * sizeof(so3fft_complex));
    int rc = 0;
    double err;
    if (!c || !c2 || !s) {
        free(c);
        free(c2);
        free(s);
        return 2; /* the caller's arrays: not the library's failure */
    }
    fill_random(c, nc, seed);
    if (so3fft_execute_inverse(p, c, s) != SO3FFT_OK ||
        so3fft_execute_forward(p, s, c2) != SO3FFT_OK) {
        fprintf(stderr, "execute failed: %d \"%s\"\n", so3fft_last_error_code(),
                so3fft_last_error());
        rc = 1;
    } else if (!((err = max_abs_diff(c, c2, nc)) <= 1e-10)) {
        fprintf(stderr, "round trip error %.3e at B = %d\n", err, b);
        rc = 1;
    }
    free(c);
    free(c2);
    free(s);
    return rc;
}

#endif /* SO3FFT_ATTACK_H */
