# Driver of the downstream tests (cmake -P). Installs the build tree into a temporary prefix,
# moves the installed tree elsewhere (it must be relocatable), then builds and runs the
# program main.c against it:
#   KIND=cmake      separate CMake project: find_package(so3fft CONFIG REQUIRED), links
#                   so3fft::so3fft and so3fft::so3fft_static; the static executable must still
#                   run once the prefix is gone.
#   KIND=soft20     a SOFT 2.0 client project: find_package(soft20), headers included bare, as
#                   soft/... and as soft20/...
#   KIND=pkgconfig  `pkg-config --cflags --libs so3fft` (shared) and
#                   `pkg-config --static --cflags --libs so3fft` with -static (fully static);
#                   the same for a SOFT client with so3fft-soft.
#   KIND=mpi        an MPI program (mpi/main.c) built by a CMake project linking so3fft::mpi
#                   and with `pkg-config --cflags --libs so3fft-mpi`, each run on 2 ranks.
# Inputs: KIND, BUILD_DIR, WORK_DIR, SOURCE_DIR, C_COMPILER, GENERATOR; for a build with
# SO3FFT_MPI: MPI=ON, MPIEXEC, MPIEXEC_NUMPROC_FLAG, MPIEXEC_FLAGS (comma-separated).
cmake_minimum_required(VERSION 3.21)

function(run)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE rc)
  if(NOT rc EQUAL 0)
    string(REPLACE ";" " " cmd "${ARGN}")
    message(FATAL_ERROR "command failed (${rc}): ${cmd}")
  endif()
endfunction()

function(capture out)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE rc OUTPUT_VARIABLE o
                  OUTPUT_STRIP_TRAILING_WHITESPACE)
  if(NOT rc EQUAL 0)
    string(REPLACE ";" " " cmd "${ARGN}")
    message(FATAL_ERROR "command failed (${rc}): ${cmd}")
  endif()
  set(${out} "${o}" PARENT_SCOPE)
endfunction()

file(REMOVE_RECURSE "${WORK_DIR}")
file(MAKE_DIRECTORY "${WORK_DIR}")
run("${CMAKE_COMMAND}" --install "${BUILD_DIR}" --prefix "${WORK_DIR}/stage")
# Relocation: the package must work from wherever it ends up.
file(RENAME "${WORK_DIR}/stage" "${WORK_DIR}/prefix")
set(prefix "${WORK_DIR}/prefix")

file(GLOB_RECURSE pcfile "${prefix}/*/so3fft.pc")
file(GLOB_RECURSE configfile "${prefix}/*/so3fftConfig.cmake")
file(GLOB_RECURSE solink "${prefix}/*/libso3fft.so")
if(NOT pcfile OR NOT configfile OR NOT solink OR NOT EXISTS "${prefix}/include/so3fft.h")
  message(FATAL_ERROR "incomplete install tree under ${prefix}")
endif()
get_filename_component(libdir "${solink}" DIRECTORY)
foreach(link libso3fft.so libso3fft.so.0)
  if(NOT IS_SYMLINK "${libdir}/${link}")
    message(FATAL_ERROR "${libdir}/${link} is not a symlink")
  endif()
endforeach()
file(GLOB real "${libdir}/libso3fft.so.*.*.*")
if(NOT real OR IS_SYMLINK "${real}" OR NOT EXISTS "${libdir}/libso3fft.a")
  message(FATAL_ERROR "missing libso3fft.so.X.Y.Z or libso3fft.a in ${libdir}")
endif()

if(KIND STREQUAL "cmake")
  run("${CMAKE_COMMAND}" -S "${SOURCE_DIR}" -B "${WORK_DIR}/build" -G "${GENERATOR}"
      "-DCMAKE_C_COMPILER=${C_COMPILER}" "-DCMAKE_PREFIX_PATH=${prefix}"
      -DCMAKE_BUILD_TYPE=Release)
  run("${CMAKE_COMMAND}" --build "${WORK_DIR}/build")
  run("${CMAKE_CTEST_COMMAND}" --test-dir "${WORK_DIR}/build" --output-on-failure)
  # The static executable does not need the installed tree any more; the shared one does.
  file(RENAME "${prefix}" "${WORK_DIR}/gone")
  run("${WORK_DIR}/build/use_static")
  execute_process(COMMAND "${WORK_DIR}/build/use_shared" RESULT_VARIABLE rc
                  OUTPUT_QUIET ERROR_QUIET)
  if(rc EQUAL 0)
    message(FATAL_ERROR "use_shared ran without the installed libso3fft.so: not linked dynamically?")
  endif()
  message(STATUS "downstream CMake project: OK")
elseif(KIND STREQUAL "soft20")
  run("${CMAKE_COMMAND}" -S "${SOURCE_DIR}/soft20" -B "${WORK_DIR}/build" -G "${GENERATOR}"
      "-DCMAKE_C_COMPILER=${C_COMPILER}" "-DCMAKE_PREFIX_PATH=${prefix}"
      -DCMAKE_BUILD_TYPE=Release)
  run("${CMAKE_COMMAND}" --build "${WORK_DIR}/build")
  run("${CMAKE_CTEST_COMMAND}" --test-dir "${WORK_DIR}/build" --output-on-failure)
  # The static programs do not need the installed tree any more.
  file(RENAME "${prefix}" "${WORK_DIR}/gone")
  run("${WORK_DIR}/build/soft20_client_static")
  run("${WORK_DIR}/build/both_static")
  message(STATUS "downstream soft20 client: OK")
elseif(KIND STREQUAL "pkgconfig")
  find_program(PKG_CONFIG pkg-config REQUIRED)
  get_filename_component(pcdir "${pcfile}" DIRECTORY)
  set(ENV{PKG_CONFIG_PATH} "${pcdir}")
  capture(version "${PKG_CONFIG}" --modversion so3fft)
  message(STATUS "pkg-config so3fft version ${version}")
  capture(pc_libdir "${PKG_CONFIG}" --variable=libdir so3fft)

  # Shared library.
  capture(flags "${PKG_CONFIG}" --cflags --libs so3fft)
  message(STATUS "pkg-config --cflags --libs so3fft: ${flags}")
  separate_arguments(flags UNIX_COMMAND "${flags}")
  run("${C_COMPILER}" -Wall -Wextra -Werror "${SOURCE_DIR}/main.c" -o "${WORK_DIR}/use_pc_shared"
      ${flags} -lm "-Wl,-rpath,${pc_libdir}")
  run("${WORK_DIR}/use_pc_shared")

  # A SOFT client on the SOFT library alone: the linker and the loader find libso3fft.so.0
  # next to libso3fft_soft.so (its RUNPATH), with nothing about it on the link line.
  capture(soft_flags "${PKG_CONFIG}" --cflags --libs so3fft-soft)
  message(STATUS "pkg-config --cflags --libs so3fft-soft: ${soft_flags}")
  separate_arguments(soft_flags UNIX_COMMAND "${soft_flags}")
  run("${C_COMPILER}" -Wall -Wextra -Werror "${SOURCE_DIR}/soft20/main.c"
      -o "${WORK_DIR}/use_pc_soft_shared" ${soft_flags} "-Wl,-rpath,${pc_libdir}")
  run("${WORK_DIR}/use_pc_soft_shared")
  capture(soft_sflags "${PKG_CONFIG}" --static --cflags --libs so3fft-soft)
  message(STATUS "pkg-config --static --cflags --libs so3fft-soft: ${soft_sflags}")
  separate_arguments(soft_sflags UNIX_COMMAND "${soft_sflags}")

  # Fully static program: -static makes the linker take libso3fft.a and the static FFTW.
  capture(sflags "${PKG_CONFIG}" --static --cflags --libs so3fft)
  message(STATUS "pkg-config --static --cflags --libs so3fft: ${sflags}")
  separate_arguments(sflags UNIX_COMMAND "${sflags}")
  run("${C_COMPILER}" -Wall -Wextra -Werror -static "${SOURCE_DIR}/main.c"
      -o "${WORK_DIR}/use_pc_static" ${sflags} -lm)
  run("${C_COMPILER}" -Wall -Wextra -Werror -static "${SOURCE_DIR}/soft20/main.c"
      -o "${WORK_DIR}/use_pc_soft_static" ${soft_sflags})
  file(RENAME "${prefix}" "${WORK_DIR}/gone")
  run("${WORK_DIR}/use_pc_static")
  run("${WORK_DIR}/use_pc_soft_static")
  message(STATUS "pkg-config: OK")
elseif(KIND STREQUAL "mpi")
  file(GLOB_RECURSE mpi_pcfile "${prefix}/*/so3fft-mpi.pc")
  if(NOT mpi_pcfile OR NOT EXISTS "${prefix}/include/so3fft_mpi.h")
    message(FATAL_ERROR "so3fft-mpi.pc or so3fft_mpi.h not installed under ${prefix}")
  endif()
  string(REPLACE "," ";" flags "${MPIEXEC_FLAGS}")
  set(mpiexec "${MPIEXEC}" ${flags} ${MPIEXEC_NUMPROC_FLAG} 2)

  run("${CMAKE_COMMAND}" -S "${SOURCE_DIR}/mpi" -B "${WORK_DIR}/build" -G "${GENERATOR}"
      "-DCMAKE_C_COMPILER=${C_COMPILER}" "-DCMAKE_PREFIX_PATH=${prefix}"
      -DCMAKE_BUILD_TYPE=Release)
  run("${CMAKE_COMMAND}" --build "${WORK_DIR}/build")
  run(${mpiexec} "${WORK_DIR}/build/use_mpi")

  find_program(PKG_CONFIG pkg-config REQUIRED)
  get_filename_component(pcdir "${mpi_pcfile}" DIRECTORY)
  set(ENV{PKG_CONFIG_PATH} "${pcdir}")
  capture(pc_libdir "${PKG_CONFIG}" --variable=libdir so3fft-mpi)
  capture(flags "${PKG_CONFIG}" --cflags --libs so3fft-mpi)
  message(STATUS "pkg-config --cflags --libs so3fft-mpi: ${flags}")
  separate_arguments(flags UNIX_COMMAND "${flags}")
  run("${C_COMPILER}" -Wall -Wextra -Werror "${SOURCE_DIR}/mpi/main.c"
      -o "${WORK_DIR}/use_pc_mpi" ${flags} -lm "-Wl,-rpath,${pc_libdir}")
  run(${mpiexec} "${WORK_DIR}/use_pc_mpi")
  message(STATUS "downstream MPI program (so3fft::mpi, so3fft-mpi.pc): OK")
else()
  message(FATAL_ERROR "unknown KIND '${KIND}'")
endif()
