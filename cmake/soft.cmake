# so3fft's SOFT 2.0 drop-in layer: libso3fft_soft, CMake targets, install rules, pkg-config file
# and tests. Included by the top-level CMakeLists.txt (after so3fft::so3fft is defined):
#
#   include(cmake/soft.cmake)
#
# libso3fft_soft holds SOFT's function names, each a one-line forwarder to the libso3fft entry
# point that implements it (src/soft/soft_names.c); libso3fft itself exports only so3fft_*.
#   libso3fft_soft.so.0   needs libso3fft.so.0 (found next to it: RUNPATH $ORIGIN)
#   libso3fft_soft.a      the forwarders and the whole library object: a SOFT client links this
#                         one archive; with libso3fft.a too, in either order, nothing is doubled
#
# Provides
#   so3fft::soft         libso3fft_soft.so, SOFT's header names (include/soft) and fftw3. A SOFT
#                        client's CMake build changes one line:
#                          target_link_libraries(app PRIVATE soft1 fftw3 m)  ->  so3fft::soft
#   so3fft::soft_static  the same with libso3fft_soft.a and its link dependencies
#   <prefix>/include/so3fft/soft/*.h              the headers (soft_fftw.h, utils_so3.h, ...),
#                                                  also as so3fft/soft20/*.h: a client may include
#                                                  them bare, as "soft/..." or as "soft20/..."
#   <libdir>/cmake/soft20/soft20Config.cmake       find_package(soft20): targets soft20::soft20
#                                                  and soft20 (= so3fft::soft), for codes built
#                                                  against the CMake repackaging of SOFT 2.0
#   <libdir>/pkgconfig/so3fft-soft.pc              `pkg-config --cflags --libs so3fft-soft`
#   <libdir>/cmake/so3fft/so3fft-soft.cmake        so3fft::soft and so3fft::soft_static for
#                                                  find_package(so3fft); the package config
#                                                  includes it when present.
#   tests (SO3FFT_BUILD_TESTS): c_tests/soft, CTest labels `soft` and `valgrind`.
include_guard(GLOBAL)
include(GNUInstallDirs)

get_filename_component(_so3fft_soft_root "${CMAKE_CURRENT_LIST_DIR}/.." ABSOLUTE)
set(SO3FFT_SOFT_INCLUDE_DIR "${_so3fft_soft_root}/include/soft")

if(NOT SO3FFT_FFTW3_LIBRARY)
  find_library(SO3FFT_FFTW3_LIBRARY NAMES fftw3 REQUIRED)
endif()

# --- libso3fft_soft ---------------------------------------------------------------------------
# "x.h", "soft/x.h" and "soft20/x.h" all resolve (soft20/ is a link in the build tree).
set(_so3fft_soft20_dir "${CMAKE_BINARY_DIR}/soft20-include")
file(MAKE_DIRECTORY "${_so3fft_soft20_dir}")
file(CREATE_LINK "${SO3FFT_SOFT_INCLUDE_DIR}" "${_so3fft_soft20_dir}/soft20" SYMBOLIC)
set(_so3fft_soft_includes
  "${SO3FFT_SOFT_INCLUDE_DIR}" "${_so3fft_soft_root}/include" "${_so3fft_soft20_dir}")

# The forwarders, compiled once for both libraries.
add_library(so3fft_soft_names OBJECT "${_so3fft_soft_root}/src/soft/soft_names.c")
target_include_directories(so3fft_soft_names PRIVATE "${SO3FFT_SOFT_INCLUDE_DIR}")
set_target_properties(so3fft_soft_names PROPERTIES
  POSITION_INDEPENDENT_CODE ON C_STANDARD 99 C_STANDARD_REQUIRED ON C_EXTENSIONS OFF)
target_compile_options(so3fft_soft_names PRIVATE -Wall -Wextra -pedantic -Werror)

add_library(so3fft_soft SHARED $<TARGET_OBJECTS:so3fft_soft_names>)
add_library(so3fft::soft ALIAS so3fft_soft)
set_target_properties(so3fft_soft PROPERTIES
  OUTPUT_NAME so3fft_soft
  VERSION "${PROJECT_VERSION}"
  SOVERSION "${SO3FFT_SOVERSION}"
  LIBRARY_OUTPUT_DIRECTORY "${SO3FFT_LIB_DIR}"
  # libso3fft.so.0 is installed next to it.
  INSTALL_RPATH "$ORIGIN")
target_link_libraries(so3fft_soft PRIVATE so3fft::so3fft)
target_link_options(so3fft_soft PRIVATE -Wl,--no-undefined)
target_include_directories(so3fft_soft INTERFACE "$<BUILD_INTERFACE:${_so3fft_soft_includes}>")
# SOFT clients call FFTW themselves (fftw_malloc, fftw_plan_many_dft): link fftw3 for them.
target_link_libraries(so3fft_soft INTERFACE "${SO3FFT_FFTW3_LIBRARY}" m)

set(SO3FFT_SOFT_ARCHIVE "${SO3FFT_LIB_DIR}/libso3fft_soft.a")
add_custom_command(OUTPUT "${SO3FFT_SOFT_ARCHIVE}"
  COMMAND "${CMAKE_COMMAND}" -E rm -f "${SO3FFT_SOFT_ARCHIVE}"
  COMMAND "${CMAKE_AR}" rcs "${SO3FFT_SOFT_ARCHIVE}" $<TARGET_OBJECTS:so3fft_soft_names>
          "${SO3FFT_OBJECT}"
  DEPENDS so3fft_soft_names $<TARGET_OBJECTS:so3fft_soft_names> "${SO3FFT_OBJECT}" so3fft_cargo
  COMMENT "Creating libso3fft_soft.a"
  VERBATIM COMMAND_EXPAND_LISTS)
add_custom_target(so3fft_soft_archive ALL DEPENDS "${SO3FFT_SOFT_ARCHIVE}")
add_library(so3fft::soft_static STATIC IMPORTED GLOBAL)
set_target_properties(so3fft::soft_static PROPERTIES
  IMPORTED_LOCATION "${SO3FFT_SOFT_ARCHIVE}"
  IMPORTED_LINK_INTERFACE_LANGUAGES C
  INTERFACE_INCLUDE_DIRECTORIES "${_so3fft_soft_includes}"
  INTERFACE_LINK_LIBRARIES "${SO3FFT_STATIC_DEPS}")
add_dependencies(so3fft::soft_static so3fft_soft_archive)

# --- install --------------------------------------------------------------------------------
install(TARGETS so3fft_soft LIBRARY DESTINATION "${CMAKE_INSTALL_LIBDIR}")
install(FILES "${SO3FFT_SOFT_ARCHIVE}" DESTINATION "${CMAKE_INSTALL_LIBDIR}")
install(DIRECTORY "${SO3FFT_SOFT_INCLUDE_DIR}/"
  DESTINATION "${CMAKE_INSTALL_INCLUDEDIR}/so3fft/soft"
  FILES_MATCHING PATTERN "*.h")
install(DIRECTORY "${SO3FFT_SOFT_INCLUDE_DIR}/"
  DESTINATION "${CMAKE_INSTALL_INCLUDEDIR}/so3fft/soft20"
  FILES_MATCHING PATTERN "*.h")
install(FILES "${CMAKE_CURRENT_LIST_DIR}/soft20Config.cmake"
  DESTINATION "${CMAKE_INSTALL_LIBDIR}/cmake/soft20")
configure_file("${CMAKE_CURRENT_LIST_DIR}/soft-package.cmake"
               "${CMAKE_BINARY_DIR}/so3fft-soft.cmake" @ONLY)
install(FILES "${CMAKE_BINARY_DIR}/so3fft-soft.cmake"
  DESTINATION "${CMAKE_INSTALL_LIBDIR}/cmake/so3fft")

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
