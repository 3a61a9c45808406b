/* Allocation failure is reported, not fatal.
 *
 * 1. In forked children whose address space is capped with setrlimit(RLIMIT_AS) at a few
 *    tens to hundreds of MiB above their current size, a bandwidth-512 plan cannot get its
 *    buffers (its chunk buffer alone is at least 512 MiB by default; each beta slice is
 *    16 MiB): the planner must return NULL with SO3FFT_ENOMEM, and the library must stay
 *    usable under the same cap. The caps are relative to the child's current address
 *    space, so the test does not depend on the machine's memory size. (On a machine too
 *    small for B = 512 arrays, the planner's own memory check reports SO3FFT_ENOMEM first,
 *    which is also correct.)
 * 2. A bandwidth-1024 plan without a cap either succeeds (machines with enough memory for
 *    the 160 GB of arrays it implies) or fails with SO3FFT_ENOMEM; it must not crash.
 * 3. Under a cap of 256 MiB, a small plan with 1024 worker threads (whose stacks need far
 *    more address space) fails with SO3FFT_ENOMEM, not as an invalid argument.
 *
 * The parent reports a child killed by a signal (an abort on an infallible allocation, or
 * the OOM killer) as a failure. */
#define _POSIX_C_SOURCE 200809L
#include <signal.h>
#include <sys/resource.h>
#include <sys/types.h>
#include <sys/wait.h>
#include <unistd.h>

#include "test_util.h"

/* Current virtual memory size of this process in bytes (from /proc/self/statm). */
static size_t vm_size(void) {
    unsigned long pages = 0;
    FILE *f = fopen("/proc/self/statm", "r");
    if (f) {
        if (fscanf(f, "%lu", &pages) != 1) pages = 0;
        fclose(f);
    }
    return (size_t)pages * (size_t)sysconf(_SC_PAGESIZE);
}

/* The child's exit status for plan `p`, made by the step `what`: a NULL plan must come with
 * SO3FFT_ENOMEM; a plan that was made is destroyed and passes only if `may_succeed`. */
static int outcome(so3fft_plan p, const char *what, int may_succeed) {
    printf("%s: %s, code %d, \"%s\"\n", what, p ? "plan created" : "NULL",
           so3fft_last_error_code(), so3fft_last_error());
    if (p) {
        so3fft_destroy_plan(p);
        return may_succeed ? 0 : 1;
    }
    CHECK_ERR(SO3FFT_ENOMEM);
    return g_failures ? 1 : 0;
}

static int child(size_t headroom, int direction) {
    struct rlimit rl;
    size_t now = vm_size();
    so3fft_plan p;
    if (now == 0) {
        fprintf(stderr, "cannot read /proc/self/statm\n");
        return 2;
    }
    if (headroom == 0) {
        p = so3fft_plan_general(1024, direction, NULL, NULL, SO3FFT_ESTIMATE, 1);
        return outcome(p, "B=1024 without a cap", 1);
    }
    rl.rlim_cur = rl.rlim_max = (rlim_t)(now + headroom);
    if (setrlimit(RLIMIT_AS, &rl) != 0) {
        perror("setrlimit");
        return 2;
    }
    if (direction == 0) {
        p = so3fft_plan_general(2, SO3FFT_BOTH, NULL, NULL, SO3FFT_ESTIMATE, 1024);
        return outcome(p, "B=2 with 1024 threads under the cap", 0);
    }
    p = so3fft_plan_general(512, direction, NULL, NULL, SO3FFT_ESTIMATE, 1);
    if (p != NULL) {
        fprintf(stderr, "B=512 plan succeeded within %lu MiB of extra address space\n",
                (unsigned long)(headroom >> 20));
        so3fft_destroy_plan(p);
        return 1;
    }
    CHECK_ERR(SO3FFT_ENOMEM);
    printf("B=512, direction %d, headroom %lu MiB: NULL, code %d, \"%s\"\n", direction,
           (unsigned long)(headroom >> 20), so3fft_last_error_code(), so3fft_last_error());
    /* still usable under the same cap */
    p = so3fft_plan_general(4, direction, NULL, NULL, SO3FFT_ESTIMATE, 1);
    CHECK(p != NULL);
    CHECK_NO_ERR();
    so3fft_destroy_plan(p);
    return g_failures ? 1 : 0;
}

static void run_child(size_t headroom, int direction) {
    int status = 0;
    pid_t pid;
    fflush(stdout);
    fflush(stderr);
    pid = fork();
    if (pid < 0) {
        perror("fork");
        g_failures++;
        return;
    }
    if (pid == 0) {
        int rc = child(headroom, direction);
        fflush(stdout);
        fflush(stderr);
        _exit(rc);
    }
    if (waitpid(pid, &status, 0) != pid) {
        perror("waitpid");
        g_failures++;
        return;
    }
    if (WIFSIGNALED(status)) {
        fprintf(stderr, "child (headroom %lu MiB) killed by signal %d: allocation failure was fatal\n",
                (unsigned long)(headroom >> 20), WTERMSIG(status));
        g_failures++;
    } else if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) {
        fprintf(stderr, "child (headroom %lu MiB) failed with status %d\n",
                (unsigned long)(headroom >> 20), WEXITSTATUS(status));
        g_failures++;
    }
}

int main(void) {
    /* Several caps, so the failure happens at different allocations of the planner. */
    run_child((size_t)48 << 20, SO3FFT_FORWARD);
    run_child((size_t)160 << 20, SO3FFT_INVERSE);
    run_child((size_t)400 << 20, SO3FFT_BOTH);
    run_child(0, SO3FFT_BOTH);
    run_child((size_t)256 << 20, 0);
    return finish("test_oom");
}
