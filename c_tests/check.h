/* Check macros and helpers shared by the C test suites (C API and SOFT layer). */
#ifndef SO3FFT_CHECK_H
#define SO3FFT_CHECK_H

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static int g_failures = 0;

#define CHECK(cond)                                                                    \
    do {                                                                               \
        if (!(cond)) {                                                                 \
            fprintf(stderr, "%s:%d: CHECK failed: %s\n", __FILE__, __LINE__, #cond);   \
            g_failures++;                                                              \
        }                                                                              \
    } while (0)

static inline int finish(const char *name) {
    if (g_failures) {
        fprintf(stderr, "%s: %d check(s) failed\n", name, g_failures);
        return EXIT_FAILURE;
    }
    printf("%s: all checks passed\n", name);
    return EXIT_SUCCESS;
}

/* Deterministic pseudo-random numbers in [-1, 1). */
static inline double rnd(unsigned long long *state) {
    *state = *state * 6364136223846793005ULL + 1442695040888963407ULL;
    return (double)(*state >> 11) / 4503599627370496.0 - 1.0;
}

#ifdef _POSIX_C_SOURCE
#include <sys/wait.h>
#include <unistd.h>

/* Runs `body(arg)` in a child made by fork() and returns the byte it returns, or -1 if the
 * child did not report (it crashed, or hung and alarm() ended it after 60 s). The child
 * reports through a pipe, not its exit status, which valgrind sets when it finds the
 * memory that the parent's vanished threads held. */
static inline int in_forked_child(unsigned char (*body)(void *), void *arg) {
    int fd[2], status = -1, got = -1;
    unsigned char code;
    pid_t pid;
    if (pipe(fd) != 0) return -1;
    fflush(NULL);
    pid = fork();
    if (pid == 0) {
        alarm(60);
        close(fd[0]);
        code = body(arg);
        _exit(write(fd[1], &code, 1) == 1 ? 0 : 3);
    }
    close(fd[1]);
    if (pid > 0) {
        if (read(fd[0], &code, 1) == 1) got = code;
        if (waitpid(pid, &status, 0) != pid || !WIFEXITED(status)) got = -1;
    }
    close(fd[0]);
    return got;
}
#endif

#endif /* SO3FFT_CHECK_H */
