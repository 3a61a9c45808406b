// A C++ translation unit using the C API: RAII ownership of plans, std::vector and
// std::complex<double> arrays (layout-compatible with so3fft_complex), exceptions on error.
#include <algorithm>
#include <complex>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "so3fft.h"

namespace {

struct PlanDeleter {
    void operator()(so3fft_plan_s *p) const { so3fft_destroy_plan(p); }
};
typedef std::unique_ptr<so3fft_plan_s, PlanDeleter> Plan;

void check(int code) {
    if (code != SO3FFT_OK) {
        throw std::runtime_error(std::string("so3fft: ") + so3fft_last_error());
    }
}

so3fft_complex *cx(std::vector<std::complex<double> > &v) {
    return reinterpret_cast<so3fft_complex *>(v.data());
}

}  // namespace

int main() {
    const int B = 6;
    try {
        std::printf("so3fft %s (header %s)\n", so3fft_version(), SO3FFT_VERSION);
        Plan plan(so3fft_plan_both(B, SO3FFT_ESTIMATE));
        if (!plan) check(so3fft_last_error_code());
        std::vector<std::complex<double> > coeffs(so3fft_num_coeffs(B)), samples(so3fft_num_samples(B)),
            back(so3fft_num_coeffs(B));
        for (int l = 0; l < B; ++l)
            for (int m = -l; m <= l; ++m)
                for (int mp = -l; mp <= l; ++mp)
                    coeffs[static_cast<std::size_t>(so3fft_coef_index(B, l, m, mp))] =
                        std::complex<double>(1.0 / (1 + l), 0.1 * m - 0.05 * mp);
        check(so3fft_execute_inverse(plan.get(), cx(coeffs), cx(samples)));
        check(so3fft_execute_forward(plan.get(), cx(samples), cx(back)));
        double err = 0.0;
        for (std::size_t i = 0; i < coeffs.size(); ++i) err = std::max(err, std::abs(back[i] - coeffs[i]));
        std::printf("C++ round trip B=%d: max error %.3g\n", B, err);
        if (!(err <= 1e-12)) return EXIT_FAILURE;

        // errors become exceptions
        bool threw = false;
        try {
            check(so3fft_execute(plan.get()));
        } catch (const std::runtime_error &e) {
            threw = so3fft_last_error_code() == SO3FFT_ENULL && std::string(e.what()).size() > 8;
        }
        if (!threw) return EXIT_FAILURE;
        Plan bad(so3fft_plan_forward(0, nullptr, nullptr, 0));
        if (bad || so3fft_last_error_code() != SO3FFT_EBANDWIDTH) return EXIT_FAILURE;
    } catch (const std::exception &e) {
        std::fprintf(stderr, "%s\n", e.what());
        return EXIT_FAILURE;
    }
    std::printf("test_cxx: all checks passed\n");
    return EXIT_SUCCESS;
}
