# The native libraries (zstd, pugixml, zlib) as TETSTREAM_ZSTD, TETSTREAM_PUGIXML and
# TETSTREAM_ZLIB, and tetstream_static_cli(target), which links a program statically.
#
# Why the CLI is one static executable: it starts in about half the time (the dynamic loader
# binds libstdc++'s symbols at each start, and the CLI starts twice when it restarts itself for
# huge pages), and the one file runs on any x86-64 Linux, with no libzstd or pugixml installed and an
# older glibc, so it can be copied to the cluster where a simulation's results are and pack them
# there. It reads files and starts threads only: nothing of glibc that needs shared objects at
# run time (name services, iconv, dlopen).
#
# Only the CLI links the archives: the tests and benchmarks keep the shared libraries, as do the
# sanitizer and fuzzing builds. Each library below is a generator expression that the linking
# program decides by its TETSTREAM_STATIC property.
set(TETSTREAM_ZSTD PkgConfig::ZSTD)
set(TETSTREAM_PUGIXML PkgConfig::PUGIXML)
set(TETSTREAM_ZLIB ZLIB::ZLIB)
set(TETSTREAM_STATIC_CLI_ACTIVE OFF)

if(TETSTREAM_STATIC_CLI AND NOT TETSTREAM_SANITIZE AND NOT TETSTREAM_FUZZ AND CMAKE_SYSTEM_NAME STREQUAL "Linux")
  find_library(TETSTREAM_ZSTD_ARCHIVE NAMES libzstd.a HINTS ${ZSTD_LIBRARY_DIRS})
  find_library(TETSTREAM_PUGIXML_ARCHIVE NAMES libpugixml.a HINTS ${PUGIXML_LIBRARY_DIRS})
  find_library(TETSTREAM_ZLIB_ARCHIVE NAMES libz.a)
  find_library(TETSTREAM_LIBC_ARCHIVE NAMES libc.a)
  if(TETSTREAM_ZSTD_ARCHIVE AND TETSTREAM_PUGIXML_ARCHIVE AND TETSTREAM_ZLIB_ARCHIVE AND TETSTREAM_LIBC_ARCHIVE)
    set(TETSTREAM_STATIC_CLI_ACTIVE ON)
    set(is_static "$<BOOL:$<TARGET_PROPERTY:TETSTREAM_STATIC>>")
    set(TETSTREAM_ZSTD "$<IF:${is_static},${TETSTREAM_ZSTD_ARCHIVE},PkgConfig::ZSTD>")
    set(TETSTREAM_PUGIXML "$<IF:${is_static},${TETSTREAM_PUGIXML_ARCHIVE},PkgConfig::PUGIXML>")
    set(TETSTREAM_ZLIB "$<IF:${is_static},${TETSTREAM_ZLIB_ARCHIVE},ZLIB::ZLIB>")
    unset(is_static)
  else()
    message(STATUS "tetstream: the CLI links the shared libraries (a static archive of zstd, pugixml, zlib or libc is missing)")
  endif()
endif()

function(tetstream_static_cli target)
  if(TETSTREAM_STATIC_CLI_ACTIVE)
    set_target_properties(${target} PROPERTIES TETSTREAM_STATIC ON)
    target_link_options(${target} PRIVATE -static)
  endif()
endfunction()
