# SPDX-License-Identifier: GPL-3.0-or-later
# Debian's hardening flags (what dpkg-buildflags gives with
# DEB_BUILD_MAINT_OPTIONS=hardening=+all) for every optimised tree that is not
# a sanitizer tree: _FORTIFY_SOURCE=2, the strong stack protector, stack clash
# protection, control-flow protection (x86), position-independent executables
# and full RELRO (-z relro -z now). scripts/package.sh adds the distribution's
# own flags (dpkg-buildflags) on top; tests/package/deb.sh checks the packaged
# programs with hardening-check (devscripts).
#
# Not in the ASan/UBSan, TSan or libFuzzer trees: _FORTIFY_SOURCE replaces
# the libc calls the sanitizers intercept by their __*_chk variants (the
# sanitizers then miss what they should report, or report the checks
# themselves), and the stack protector and stack-clash probes change the
# frames ASan lays out. Nor in Debug trees: _FORTIFY_SOURCE needs -O1 or more
# (glibc warns, and warnings are errors).
include(CheckCCompilerFlag)
include(CheckPIESupported)

set(_amfi_harden_default ON)
if(AMFI_SANITIZE OR AMFI_TSAN OR AMFI_FUZZ)
  set(_amfi_harden_default OFF)
endif()
option(AMFI_HARDEN "Debian's hardening flags (fortify, stack protector, PIE, relro/now); off in sanitizer trees"
  ${_amfi_harden_default})
if(AMFI_HARDEN AND (AMFI_SANITIZE OR AMFI_TSAN OR AMFI_FUZZ))
  message(FATAL_ERROR "AMFI_HARDEN conflicts with AMFI_SANITIZE, AMFI_TSAN and AMFI_FUZZ "
    "(_FORTIFY_SOURCE hides the libc calls the sanitizers intercept): leave it off in a sanitizer tree")
endif()

string(TOUPPER "${CMAKE_BUILD_TYPE}" _amfi_bt)
set(AMFI_HARDENED OFF)
if(AMFI_HARDEN AND _amfi_bt MATCHES "^(RELEASE|RELWITHDEBINFO|MINSIZEREL)$")
  set(AMFI_HARDENED ON)
  # PIE: -fPIE for every object (static libraries included) and -pie at link
  # (policy CMP0083, NEW with cmake_minimum_required 3.14 or later).
  check_pie_supported(LANGUAGES C)
  set(CMAKE_POSITION_INDEPENDENT_CODE ON)
  # A _FORTIFY_SOURCE from the caller's flags (dpkg-buildflags' CPPFLAGS)
  # would be redefined: undefine first.
  add_compile_options(-U_FORTIFY_SOURCE -D_FORTIFY_SOURCE=2 -fstack-protector-strong)
  foreach(flag -fstack-clash-protection -fcf-protection)
    string(MAKE_C_IDENTIFIER "AMFI_HAS${flag}" var)
    check_c_compiler_flag(${flag} ${var})
    if(${var})
      add_compile_options(${flag})
    endif()
  endforeach()
  add_link_options(LINKER:-z,relro LINKER:-z,now)
endif()
message(STATUS "amfi: hardening flags ${AMFI_HARDENED} (AMFI_HARDEN=${AMFI_HARDEN}, build type ${CMAKE_BUILD_TYPE})")
