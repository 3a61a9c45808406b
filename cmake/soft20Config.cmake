# find_package(soft20) for codes built against the CMake repackaging of SOFT 2.0: maps its
# targets onto so3fft's SOFT layer (so3fft::soft). Installed as
# <libdir>/cmake/soft20/soft20Config.cmake next to so3fft's own package.
#
#   find_package(soft20 REQUIRED)
#   target_link_libraries(app PRIVATE soft20::soft20)   # or: soft20
#
# Headers resolve bare ("soft_fftw.h"), as "soft/soft_fftw.h" and as "soft20/soft_fftw.h".
include(CMakeFindDependencyMacro)
find_dependency(so3fft CONFIG PATHS "${CMAKE_CURRENT_LIST_DIR}/../so3fft" NO_DEFAULT_PATH)
if(NOT TARGET so3fft::soft)
  set(soft20_FOUND FALSE)
  set(soft20_NOT_FOUND_MESSAGE "so3fft was found without its SOFT layer (so3fft::soft)")
  return()
endif()
foreach(_t soft20::soft20 soft20)
  if(NOT TARGET ${_t})
    add_library(${_t} INTERFACE IMPORTED)
    set_target_properties(${_t} PROPERTIES INTERFACE_LINK_LIBRARIES so3fft::soft)
  endif()
endforeach()
unset(_t)
set(soft20_VERSION 2.0)
