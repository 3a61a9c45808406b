/* A SOFT 2.0 client's includes in the three spellings found in the wild, and a transform:
 * the inverse of one coefficient, forward again, gives it back. */
#include <math.h>
#include <stdio.h>

#include <fftw3.h>

#include "soft/utils_so3.h"
#include "soft20/wrap_fftw.h"
#include "soft_fftw.h"

int main(void) {
    int bw = 4, i, n = totalCoeffs_so3(bw);
    fftw_complex *c = (fftw_complex *)fftw_malloc(sizeof(fftw_complex) * (size_t)n);
    fftw_complex *c2 = (fftw_complex *)fftw_malloc(sizeof(fftw_complex) * (size_t)n);
    fftw_complex *s = (fftw_complex *)fftw_malloc(sizeof(fftw_complex) * 8 * 64);
    double err = 0.0;
    for (i = 0; i < n; i++) c[i][0] = c[i][1] = 0.0;
    c[so3CoefLoc(1, -2, 3, bw)][0] = 1.0;
    Inverse_SO3_Naive_fftw_W(bw, c, s, 0);
    Forward_SO3_Naive_fftw_W(bw, s, c2, 0);
    for (i = 0; i < n; i++) err = fmax(err, hypot(c2[i][0] - c[i][0], c2[i][1] - c[i][1]));
    printf("soft20 client: round trip error %.3e\n", err);
    fftw_free(c);
    fftw_free(c2);
    fftw_free(s);
    return err < 1e-12 ? 0 : 1;
}
