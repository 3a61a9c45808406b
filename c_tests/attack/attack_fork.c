/* Issue 24, case 4: fork() while another thread is inside an so3fft planner, or executing.
 *
 * In a driver process (itself a forked child with an alarm), a thread loops making and
 * destroying so3fft plans (variant `estimate`: ESTIMATE; `measure`: MEASURE, 2 threads) or
 * executing one plan (variant `execute`: 2 worker threads). The driver's main thread forks
 * children at pseudo-random moments; each child makes a plan, runs a round trip and exits 0.
 * Every child must finish within its alarm (a child that inherited a held planner lock or
 * FFTW state in the middle of a plan hangs or crashes).
 *
 *   attack_fork [children per variant]      (default 20) */
#define _POSIX_C_SOURCE 200809L
#include <pthread.h>

#include "attack.h"

enum { CHILD_ALARM_S = 5, DRIVER_ALARM_S = 40, MAXCH = 64 };
enum { V_ESTIMATE, V_MEASURE, V_EXECUTE };

static volatile int g_stop;
static int g_variant, g_nchildren = 20;
static so3fft_plan g_exec_plan;

static void *busy_thread(void *arg) {
    int i = 0;
    (void)arg;
    while (!g_stop) {
        if (g_variant == V_EXECUTE) {
            round_trip(g_exec_plan, 12, (unsigned long long)i);
        } else {
            int b = 6 + 2 * (i % 4);
            so3fft_plan p = so3fft_plan_general(
                b, SO3FFT_BOTH, NULL, NULL,
                g_variant == V_MEASURE ? SO3FFT_MEASURE : SO3FFT_ESTIMATE,
                g_variant == V_MEASURE ? 2 : 1);
            so3fft_destroy_plan(p);
        }
        i++;
    }
    return NULL;
}

/* In the child: a fresh plan (the parent's variant's rigor) and a round trip. */
static int child_work(void) {
    int b = 8, rc;
    so3fft_plan p = so3fft_plan_general(
        b, SO3FFT_BOTH, NULL, NULL, g_variant == V_MEASURE ? SO3FFT_MEASURE : SO3FFT_ESTIMATE, 2);
    if (!p) {
        fprintf(stderr, "child: plan failed: %d \"%s\"\n", so3fft_last_error_code(),
                so3fft_last_error());
        return 1;
    }
    rc = round_trip(p, b, 5);
    so3fft_destroy_plan(p);
    return rc;
}

static int driver(void *arg) {
    pthread_t t;
    pid_t pids[MAXCH];
    int i, n = g_nchildren < MAXCH ? g_nchildren : MAXCH, ok = 0, hang = 0, sig = 0, other = 0;
    unsigned long long seed = 12345 + (unsigned long long)g_variant;
    char buf[64];
    (void)arg;
    if (g_variant == V_EXECUTE) {
        g_exec_plan = so3fft_plan_general(12, SO3FFT_BOTH, NULL, NULL, SO3FFT_ESTIMATE, 2);
        if (!g_exec_plan) return 3;
    }
    if (pthread_create(&t, NULL, busy_thread, NULL) != 0) return 3;
    sleep_us(20000);
    for (i = 0; i < n; i++) {
        sleep_us(2000 + (long)(20000.0 * (rnd(&seed) + 1.0) / 2.0));
        fflush(NULL);
        pids[i] = fork();
        if (pids[i] == 0) {
            signal(SIGALRM, SIG_DFL);
            alarm(CHILD_ALARM_S);
            _exit(child_work());
        }
    }
    for (i = 0; i < n; i++) {
        int o = pids[i] < 0 ? OUT_NOFORK : wait_outcome(pids[i]);
        if (o == 0) {
            ok++;
        } else {
            fprintf(stderr, "  child %d: %s\n", i, outcome_name(o, buf, sizeof buf));
            if (o == OUT_HANG)
                hang++;
            else if (o < 0)
                sig++;
            else
                other++;
        }
    }
    g_stop = 1;
    pthread_join(t, NULL);
    if (g_exec_plan) so3fft_destroy_plan(g_exec_plan);
    printf("  %d children: %d ok, %d hang, %d signal, %d other\n", n, ok, hang, sig, other);
    return ok == n ? 0 : 1;
}

int main(int argc, char **argv) {
    static const char *names[] = {"planning ESTIMATE", "planning MEASURE (2 threads)",
                                  "executing (2 threads)"};
    char buf[64];
    if (argc > 1) g_nchildren = atoi(argv[1]);
    for (g_variant = V_ESTIMATE; g_variant <= V_EXECUTE; g_variant++) {
        int o;
        printf("fork while another thread is %s:\n", names[g_variant]);
        o = run_forked(driver, NULL, DRIVER_ALARM_S);
        if (o != 0) {
            fprintf(stderr, "variant %s: driver %s\n", names[g_variant],
                    outcome_name(o, buf, sizeof buf));
            g_failures++;
        }
    }
    return finish("attack_fork");
}
