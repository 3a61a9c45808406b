# Turns cargo's libso3fft.a into one relocatable object whose only global symbols are so3fft_*
# and so3fftf_* (the single-precision API), and the archives built on it (cmake -P; run by the
# so3fft_cargo target):
#
#   cmake -DIN=<cargo's libso3fft.a> -DOBJECT=<so3fft.o> -DARCHIVE=<libso3fft.a>
#         -DLINKER=ld -DOBJCOPY=objcopy -DAR=ar -P localize-archive.cmake
#
# Why: a Rust static library defines, with default visibility, every symbol of the Rust runtime
# (std, core, alloc, rust_eh_personality) and of the library. Linked into a C program, those
# collide with the program's own names and with a second Rust library. Linking all members into
# one object (ld -r) and making every symbol but the API local (objcopy) leaves nothing to
# collide; the API's calls inside the object are already resolved.
#
# The bitcode sections that rustc embeds for LTO (.llvmbc, .llvmcmd) are removed: the object is
# linked as machine code, and GNU ar and nm, through the LLVM linker plugin some systems install,
# fail on bitcode of a newer LLVM.
foreach(_v IN ITEMS IN OBJECT ARCHIVE LINKER OBJCOPY AR)
  if(NOT DEFINED ${_v} OR "${${_v}}" STREQUAL "")
    message(FATAL_ERROR "localize-archive.cmake: -D${_v}=... is required")
  endif()
endforeach()

# Nothing to do when the archive is newer than cargo's output.
if(EXISTS "${ARCHIVE}" AND EXISTS "${OBJECT}" AND NOT "${IN}" IS_NEWER_THAN "${ARCHIVE}")
  return()
endif()

function(_run)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE _rc ERROR_VARIABLE _err)
  if(NOT _rc EQUAL 0)
    string(REPLACE ";" " " _cmd "${ARGN}")
    message(FATAL_ERROR "localize-archive.cmake: `${_cmd}` failed (${_rc}): ${_err}")
  endif()
endfunction()

set(_all "${OBJECT}.all.o")
_run("${LINKER}" -r --whole-archive "${IN}" -o "${_all}")
_run("${OBJCOPY}" --wildcard "--keep-global-symbol=so3fft_*" "--keep-global-symbol=so3fftf_*"
     --remove-section=.llvmbc --remove-section=.llvmcmd "${_all}" "${OBJECT}")
file(REMOVE "${_all}" "${ARCHIVE}")
_run("${AR}" rcs "${ARCHIVE}" "${OBJECT}")
