# so3fft::soft and so3fft::soft_static for an installed so3fft package (installed as
# so3fft-soft.cmake next to so3fftConfig.cmake, which includes it after defining so3fft::so3fft,
# so3fft_INCLUDE_DIR, _so3fft_LIBDIR and so3fft_FFTW3_LIBRARY):
#
#   find_package(so3fft CONFIG REQUIRED)
#   target_link_libraries(app PRIVATE so3fft::soft)          # libso3fft_soft.so, SOFT headers
#   target_link_libraries(app PRIVATE so3fft::soft_static)   # libso3fft_soft.a
if(TARGET so3fft::so3fft_static AND NOT TARGET so3fft::soft)
  set(_so3fft_soft_includes "${so3fft_INCLUDE_DIR}/so3fft/soft;${so3fft_INCLUDE_DIR}/so3fft")
  add_library(so3fft::soft SHARED IMPORTED)
  set_target_properties(so3fft::soft PROPERTIES
    IMPORTED_LOCATION "${_so3fft_LIBDIR}/libso3fft_soft.so.@PROJECT_VERSION@"
    IMPORTED_SONAME "libso3fft_soft.so.@SO3FFT_SOVERSION@"
    # The linker resolves libso3fft_soft's own needs in libso3fft.so.0 (-rpath-link).
    IMPORTED_LINK_DEPENDENT_LIBRARIES so3fft::so3fft
    INTERFACE_INCLUDE_DIRECTORIES "${_so3fft_soft_includes}"
    # SOFT clients call FFTW themselves (fftw_malloc, fftw_plan_many_dft).
    INTERFACE_LINK_LIBRARIES "${so3fft_FFTW3_LIBRARY};m")
  get_target_property(_so3fft_soft_deps so3fft::so3fft_static INTERFACE_LINK_LIBRARIES)
  add_library(so3fft::soft_static STATIC IMPORTED)
  set_target_properties(so3fft::soft_static PROPERTIES
    IMPORTED_LOCATION "${_so3fft_LIBDIR}/libso3fft_soft.a"
    IMPORTED_LINK_INTERFACE_LANGUAGES C
    INTERFACE_INCLUDE_DIRECTORIES "${_so3fft_soft_includes}"
    INTERFACE_LINK_LIBRARIES "${_so3fft_soft_deps}")
  unset(_so3fft_soft_deps)
  unset(_so3fft_soft_includes)
endif()
