/* Every SOFT-layer header compiles after <fftw3.h>, twice (include guards), as strict C. */
#include <fftw3.h>

#include "csecond.h"
#include "makeWigner.h"
#include "makeweights.h"
#include "rotate_so3_fftw.h"
#include "rotate_so3_utils.h"
#include "s2_cospmls.h"
#include "s2_legendreTransforms.h"
#include "s2_primitive.h"
#include "s2_semi_fly.h"
#include "s2_semi_memo.h"
#include "so3_correlate_fftw.h"
#include "soft_fftw.h"
#include "soft_fftw_nt.h"
#include "soft_fftw_pc.h"
#include "utils_so3.h"
#include "wrap_fftw.h"

#include "csecond.h"
#include "makeWigner.h"
#include "makeweights.h"
#include "rotate_so3_fftw.h"
#include "rotate_so3_utils.h"
#include "s2_cospmls.h"
#include "s2_legendreTransforms.h"
#include "s2_primitive.h"
#include "s2_semi_fly.h"
#include "s2_semi_memo.h"
#include "so3_correlate_fftw.h"
#include "soft_fftw.h"
#include "soft_fftw_nt.h"
#include "soft_fftw_pc.h"
#include "utils_so3.h"
#include "wrap_fftw.h"

int soft_header_check(void);
int soft_header_check(void) { return MAX(1, 2) + MIN(1, 2) + ABS(-1) + (M_PI > 3.0) + (PI > 3.0); }
