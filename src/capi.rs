//! C ABI (see include/so3fft.h).
