# so3fft's SOFT 2.0 drop-in layer: CMake target, install rules, pkg-config file and tests.
# Included by the top-level CMakeLists.txt (after so3fft::so3fft is defined):
#
#   include(cmake/soft.cmake)
#
# Provides
#   so3fft::soft        INTERFACE target: SOFT's header names (include/soft) + libso3fft + fftw3.
#                       A SOFT client's CMake build changes one line:
#                         target_link_libraries(app PRIVATE soft1 fftw3 m)  ->  so3fft::soft
#   <prefix>/include/so3fft/soft/*.h              the headers (soft_fftw.h, utils_so3.h, ...),
#                                                  also as so3fft/soft20/*.h: a client may include
#                                                  them bare, as "soft/..." or as "soft20/..."
#   <libdir>/cmake/soft20/soft20Config.cmake       find_package(soft20): targets soft20::soft20
#                                                  and soft20 (= so3fft::soft), for codes built
#                                                  against the CMake repackaging of SOFT 2.0
#   <libdir>/pkgconfig/so3fft-soft.pc              `pkg-config --cflags --libs so3fft-soft`
#   <libdir>/cmake/so3fft/so3fft-soft.cmake        so3fft::soft for find_package(so3fft); the
#                                                  package config includes it when present.
#   tests (SO3FFT_BUILD_TESTS): c_tests/soft, CTest labels `soft` and `valgrind`.
include_guard(GLOBAL)
include(GNUInstallDirs)

get_filename_component(_so3fft_soft_root "${CMAKE_CURRENT_LIST_DIR}/.." ABSOLUTE)
set(SO3FFT_SOFT_INCLUDE_DIR "${_so3fft_soft_root}/include/soft")

if(NOT SO3FFT_FFTW3_LIBRARY)
  find_library(SO3FFT_FFTW3_LIBRARY NAMES fftw3 REQUIRED)
endif()

# --- build-tree target ----------------------------------------------------------------------
add_library(so3fft_soft INTERFACE)
add_library(so3fft::soft ALIAS so3fft_soft)
# "x.h", "soft/x.h" and "soft20/x.h" all resolve (soft20/ is a link in the build tree).
set(_so3fft_soft20_dir "${CMAKE_BINARY_DIR}/soft20-include")
file(MAKE_DIRECTORY "${_so3fft_soft20_dir}")
file(CREATE_LINK "${SO3FFT_SOFT_INCLUDE_DIR}" "${_so3fft_soft20_dir}/soft20" SYMBOLIC)
target_include_directories(so3fft_soft INTERFACE
  "$<BUILD_INTERFACE:${SO3FFT_SOFT_INCLUDE_DIR}>"
  "$<BUILD_INTERFACE:${_so3fft_soft_root}/include>"
  "$<BUILD_INTERFACE:${_so3fft_soft20_dir}>")
# SOFT clients call FFTW themselves (fftw_malloc, fftw_plan_many_dft): link fftw3 for them.
target_link_libraries(so3fft_soft INTERFACE so3fft::so3fft "${SO3FFT_FFTW3_LIBRARY}" m)

# --- install --------------------------------------------------------------------------------
install(DIRECTORY "${SO3FFT_SOFT_INCLUDE_DIR}/"
  DESTINATION "${CMAKE_INSTALL_INCLUDEDIR}/so3fft/soft"
  FILES_MATCHING PATTERN "*.h")
install(DIRECTORY "${SO3FFT_SOFT_INCLUDE_DIR}/"
  DESTINATION "${CMAKE_INSTALL_INCLUDEDIR}/so3fft/soft20"
  FILES_MATCHING PATTERN "*.h")
install(FILES "${CMAKE_CURRENT_LIST_DIR}/soft20Config.cmake"
  DESTINATION "${CMAKE_INSTALL_LIBDIR}/cmake/soft20")
install(FILES "${CMAKE_CURRENT_LIST_DIR}/soft-package.cmake"
  DESTINATION "${CMAKE_INSTALL_LIBDIR}/cmake/so3fft"
  RENAME so3fft-soft.cmake)

# pkg-config, relocatable through ${pcfiledir}.
file(RELATIVE_PATH SO3FFT_SOFT_PC_TO_PREFIX "/prefix/${CMAKE_INSTALL_LIBDIR}/pkgconfig" "/prefix")
string(REGEX REPLACE "/$" "" SO3FFT_SOFT_PC_TO_PREFIX "${SO3FFT_SOFT_PC_TO_PREFIX}")
configure_file("${CMAKE_CURRENT_LIST_DIR}/so3fft-soft.pc.in"
               "${CMAKE_BINARY_DIR}/so3fft-soft.pc" @ONLY)
install(FILES "${CMAKE_BINARY_DIR}/so3fft-soft.pc"
  DESTINATION "${CMAKE_INSTALL_LIBDIR}/pkgconfig")

# --- tests ----------------------------------------------------------------------------------
if(SO3FFT_BUILD_TESTS OR (NOT DEFINED SO3FFT_BUILD_TESTS AND PROJECT_IS_TOP_LEVEL))
  enable_testing()
  add_subdirectory("${_so3fft_soft_root}/c_tests/soft" "${CMAKE_BINARY_DIR}/c_tests/soft")
endif()
