# so3fft::soft for an installed so3fft package (installed as so3fft-soft.cmake next to
# so3fftConfig.cmake, which includes it after defining so3fft::so3fft and so3fft_INCLUDE_DIR):
#
#   find_package(so3fft CONFIG REQUIRED)
#   target_link_libraries(app PRIVATE so3fft::soft)   # SOFT 2.0 header names, libso3fft, fftw3
if(NOT TARGET so3fft::soft AND TARGET so3fft::so3fft)
  if(NOT so3fft_FFTW3_LIBRARY)
    find_library(so3fft_FFTW3_LIBRARY NAMES fftw3)
  endif()
  if(so3fft_FFTW3_LIBRARY)
    set(_so3fft_soft_fftw "${so3fft_FFTW3_LIBRARY}")
  else()
    set(_so3fft_soft_fftw fftw3)
  endif()
  add_library(so3fft::soft INTERFACE IMPORTED)
  set_target_properties(so3fft::soft PROPERTIES
    INTERFACE_INCLUDE_DIRECTORIES "${so3fft_INCLUDE_DIR}/so3fft/soft;${so3fft_INCLUDE_DIR}/so3fft"
    INTERFACE_LINK_LIBRARIES "so3fft::so3fft;${_so3fft_soft_fftw};m")
  unset(_so3fft_soft_fftw)
endif()
