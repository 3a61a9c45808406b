/* Issue 24, FFTW wisdom: export, import, forget, and reproducible results.
 *
 *  - error paths: NULL arguments, a string that is not wisdom, a missing file, an unwritable
 *    path, an unknown FFT threading value: each an error code with a message;
 *  - a MEASURE plan leaves wisdom; exported to a string and to a file, both read back;
 *  - reproducible bits: the parent makes a MEASURE plan on two threads (FFT threading fixed
 *    to slices across workers), transforms random data and exports its wisdom; a forked
 *    child forgets all wisdom, imports the file, plans again and must get the same bits;
 *  - the SOFT layer with SO3FFT_SOFT_WISDOM: a child whose environment names a file makes a
 *    SOFT transform; the file then exists and is FFTW wisdom. */
#define _POSIX_C_SOURCE 200809L
#include <stdlib.h>

#include "attack.h"
#include "wrap_fftw.h"

enum { B = 24 };

static char g_file[64], g_soft_file[64];

/* Forward of `s` with a fresh MEASURE plan on two threads into `c`; 0 on success. */
static int measured_forward(so3fft_complex *s, so3fft_complex *c) {
    so3fft_plan p = so3fft_plan_general(B, SO3FFT_FORWARD, NULL, NULL, SO3FFT_MEASURE, 2);
    int r;
    if (!p) return 1;
    r = so3fft_execute_forward(p, s, c);
    so3fft_destroy_plan(p);
    return r != SO3FFT_OK;
}

static so3fft_complex *g_samples, *g_parent;
static size_t g_wisdom_len;

/* Length of the exported wisdom text (0 on failure). */
static size_t wisdom_len(void) {
    char *t = so3fft_export_wisdom_to_string();
    size_t n = t ? strlen(t) : 0;
    free(t);
    return n;
}

static int child_with_wisdom(void *arg) {
    size_t nc = so3fft_num_coeffs(B);
    so3fft_complex *c = alloc_cx(nc);
    (void)arg;
    so3fft_forget_wisdom();
    /* forgotten: less than the parent's; imported: all of it again */
    if (wisdom_len() >= g_wisdom_len) return 6;
    if (so3fft_import_wisdom_from_filename(g_file) != SO3FFT_OK) return 3;
    if (wisdom_len() != g_wisdom_len) return 7;
    if (measured_forward(g_samples, c) != 0) return 4;
    return memcmp(c, g_parent, nc * sizeof *c) == 0 ? 0 : 5;
}

static int child_soft(void *arg) {
    int b = 8;
    size_t nc = (size_t)(4 * b * b * b - b) / 3, ns = (size_t)8 * b * b * b;
    fftw_complex *s = (fftw_complex *)fftw_malloc(ns * sizeof(fftw_complex));
    fftw_complex *c = (fftw_complex *)fftw_malloc(nc * sizeof(fftw_complex));
    (void)arg;
    if (!s || !c) return 2;
    setenv("SO3FFT_SOFT_WISDOM", g_soft_file, 1);
    fill_random((so3fft_complex *)s, ns, 3);
    Forward_SO3_Naive_fftw_W(b, s, c, 0);
    so3fft_forget_wisdom();
    return so3fft_import_wisdom_from_filename(g_soft_file) == SO3FFT_OK ? 0 : 6;
}

int main(void) {
    size_t nc = so3fft_num_coeffs(B), ns = so3fft_num_samples(B);
    char *text;
    int o;
    char buf[64];

    /* error paths */
    CHECK(so3fft_import_wisdom_from_string(NULL) == SO3FFT_ENULL);
    CHECK_ERR(SO3FFT_ENULL);
    CHECK(so3fft_import_wisdom_from_string("(not wisdom") == SO3FFT_EINVAL);
    CHECK_ERR(SO3FFT_EINVAL);
    CHECK(so3fft_import_wisdom_from_filename("/nonexistent/so3fft.wisdom") == SO3FFT_EINVAL);
    CHECK_ERR(SO3FFT_EINVAL);
    CHECK(so3fft_export_wisdom_to_filename("/nonexistent/dir/so3fft.wisdom") == SO3FFT_EINVAL);
    CHECK_ERR(SO3FFT_EINVAL);
    CHECK(so3fft_export_wisdom_to_filename(NULL) == SO3FFT_ENULL);
    CHECK(so3fft_plan_with_fft_threading(7) == SO3FFT_EINVAL);
    CHECK_ERR(SO3FFT_EINVAL);
    CHECK(so3fft_planner_fft_threading() == 0);

    /* a measured plan's wisdom, through a string and a file */
    snprintf(g_file, sizeof g_file, "/tmp/so3fft_wisdom_%ld", (long)getpid());
    snprintf(g_soft_file, sizeof g_soft_file, "/tmp/so3fft_soft_wisdom_%ld", (long)getpid());
    CHECK(so3fft_plan_with_fft_threading(SO3FFT_FFT_SLICES_ACROSS_WORKERS) == SO3FFT_OK);
    CHECK(so3fft_planner_fft_threading() == SO3FFT_FFT_SLICES_ACROSS_WORKERS);
    g_samples = alloc_cx(ns);
    g_parent = alloc_cx(nc);
    fill_random(g_samples, ns, 11);
    CHECK(measured_forward(g_samples, g_parent) == 0);
    text = so3fft_export_wisdom_to_string();
    CHECK(text != NULL && strncmp(text, "(fftw-3", 7) == 0);
    g_wisdom_len = text ? strlen(text) : 0;
    if (text) {
        CHECK(so3fft_import_wisdom_from_string(text) == SO3FFT_OK);
        CHECK_NO_ERR();
        free(text);
    }
    CHECK(so3fft_export_wisdom_to_filename(g_file) == SO3FFT_OK);
    CHECK_NO_ERR();

    /* the same wisdom in another process gives the same bits */
    o = run_forked(child_with_wisdom, NULL, 30);
    if (o != 0) {
        fprintf(stderr, "child with imported wisdom: %s (3 import, 4 plan, 5 bits differ, 6 not forgotten, "
                "7 not imported)\n",
                outcome_name(o, buf, sizeof buf));
        g_failures++;
    }

    /* the SOFT layer's wisdom file */
    o = run_forked(child_soft, NULL, 30);
    if (o != 0) {
        fprintf(stderr, "SOFT child with SO3FFT_SOFT_WISDOM: %s\n",
                outcome_name(o, buf, sizeof buf));
        g_failures++;
    }
    CHECK(so3fft_plan_with_fft_threading(0) == SO3FFT_OK);
    unlink(g_file);
    unlink(g_soft_file);
    free(g_samples);
    free(g_parent);
    return finish("attack_wisdom");
}
