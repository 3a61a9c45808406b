/* Issue 24, case 1: the host program is inside FFTW's planner when so3fft makes its first plan.
 *
 * Each round is a fresh child made by fork() (so3fft has made no plan in it yet): a host
 * thread loops fftw_plan_dft_2d(FFTW_MEASURE), executes the plan on known data, checks the
 * result against a direct DFT and destroys the plan; after 50 ms the main thread (variant
 * `one`) or three threads (variant `many`) make, execute and destroy so3fft plans (ESTIMATE,
 * one thread, B = 4 .. 10). Every round must end with exit 0 within its alarm: no signal
 * (double free, SIGFPE, SIGSEGV were seen), no hang, no wrong host FFT, no failed plan.
 *
 * Variant `control`: as `one`, but the host calls fftw_make_planner_thread_safe() before its
 * thread starts (a check of the test itself: this passes with the unfixed library too).
 *
 *   attack_host_fftw one|many|control [rounds]      (default 30 rounds) */
#define _POSIX_C_SOURCE 200809L
#include <fftw3.h>
#include <pthread.h>

#include "attack.h"

enum { ALARM_S = 10, PLANS_PER_THREAD = 6 };

static volatile int g_stop;
static int g_host_bad; /* host FFT results that differ from the direct DFT */
static int g_control;  /* the host makes FFTW's planner thread-safe itself first */

static void *host_thread(void *arg) {
    int it = 0;
    (void)arg;
    while (!g_stop) {
        int n = 12 + 4 * (it % 4), i, j, k, l; /* 12, 16, 20, 24 */
        fftw_complex *in = (fftw_complex *)fftw_malloc(sizeof(fftw_complex) * n * n);
        fftw_complex *out = (fftw_complex *)fftw_malloc(sizeof(fftw_complex) * n * n);
        fftw_plan p = fftw_plan_dft_2d(n, n, in, out, FFTW_FORWARD, FFTW_MEASURE);
        if (p) {
            double err = 0.0;
            for (i = 0; i < n * n; i++) {
                in[i][0] = cos(0.37 * i + it);
                in[i][1] = sin(0.11 * i * i);
            }
            fftw_execute(p);
            /* a few outputs against the direct DFT */
            for (k = 0; k < n; k += 5) {
                for (l = 0; l < n; l += 7) {
                    double re = 0.0, im = 0.0;
                    for (i = 0; i < n; i++) {
                        for (j = 0; j < n; j++) {
                            double a = -2.0 * 3.14159265358979323846 * ((double)(i * k) / n + (double)(j * l) / n);
                            double x = in[i * n + j][0], y = in[i * n + j][1];
                            re += x * cos(a) - y * sin(a);
                            im += x * sin(a) + y * cos(a);
                        }
                    }
                    err = fmax(err, hypot(out[k * n + l][0] - re, out[k * n + l][1] - im));
                }
            }
            if (!(err <= 1e-9)) {
                fprintf(stderr, "host FFT %dx%d wrong: error %.3e\n", n, n, err);
                g_host_bad++;
            }
            fftw_destroy_plan(p);
        } else {
            fprintf(stderr, "host fftw_plan_dft_2d returned NULL\n");
            g_host_bad++;
        }
        fftw_free(in);
        fftw_free(out);
        it++;
    }
    return NULL;
}

static void *so3fft_planner(void *arg) {
    int *bad = (int *)arg, i;
    for (i = 0; i < PLANS_PER_THREAD; i++) {
        int b = 4 + 2 * (i % 4);
        so3fft_plan p = so3fft_plan_general(b, SO3FFT_BOTH, NULL, NULL, SO3FFT_ESTIMATE, 1);
        if (!p) {
            fprintf(stderr, "so3fft plan B = %d failed: %d \"%s\"\n", b,
                    so3fft_last_error_code(), so3fft_last_error());
            (*bad)++;
            continue;
        }
        if (round_trip(p, b, 100 + (unsigned long long)i) != 0) (*bad)++;
        so3fft_destroy_plan(p);
    }
    return NULL;
}

static int round_body(void *arg) {
    int nplanners = *(int *)arg, i, bad[4] = {0, 0, 0, 0}, total = 0;
    pthread_t host, pl[4];
    if (g_control) fftw_make_planner_thread_safe();
    if (pthread_create(&host, NULL, host_thread, NULL) != 0) return 2;
    sleep_us(50000);
    if (nplanners == 1) {
        so3fft_planner(&bad[0]);
    } else {
        for (i = 0; i < nplanners; i++) pthread_create(&pl[i], NULL, so3fft_planner, &bad[i]);
        for (i = 0; i < nplanners; i++) pthread_join(pl[i], NULL);
    }
    g_stop = 1;
    pthread_join(host, NULL);
    for (i = 0; i < 4; i++) total += bad[i];
    if (g_host_bad) return 3;
    return total ? 4 : 0;
}

int main(int argc, char **argv) {
    int many = argc > 1 && strcmp(argv[1], "many") == 0;
    g_control = argc > 1 && strcmp(argv[1], "control") == 0;
    int rounds = argc > 2 ? atoi(argv[2]) : 30, r, nplanners = many ? 3 : 1;
    int ok = 0, hang = 0, sig = 0, wrong_host = 0, other = 0;
    char buf[64];
    for (r = 0; r < rounds; r++) {
        int o = run_forked(round_body, &nplanners, ALARM_S);
        if (o == 0) {
            ok++;
            continue;
        }
        fprintf(stderr, "round %d: %s%s\n", r, outcome_name(o, buf, sizeof buf),
                o == 3 ? " (wrong host FFT result)" : o == 4 ? " (so3fft plan/round trip failed)" : "");
        if (o == OUT_HANG)
            hang++;
        else if (o < 0)
            sig++;
        else if (o == 3)
            wrong_host++;
        else
            other++;
        g_failures++;
    }
    printf("attack_host_fftw %s: %d rounds: %d ok, %d signal, %d hang, %d wrong host FFT, "
           "%d other\n", argc > 1 ? argv[1] : "one", rounds, ok, sig, hang, wrong_host, other);
    return finish("attack_host_fftw");
}
