# SPDX-License-Identifier: GPL-3.0-or-later
# Every library and program the build needs, found in one place. A missing one
# stops the configure step with the Debian package that provides it
# (scripts/install-deps.sh installs them all).
find_package(PkgConfig QUIET)
if(NOT PKG_CONFIG_FOUND)
  message(FATAL_ERROR "pkg-config not found: apt-get install pkg-config (or run scripts/install-deps.sh)")
endif()

# amfi_require_pkg(PREFIX MODULE DEBIAN_PACKAGE): pkg_check_modules with an
# IMPORTED_TARGET PkgConfig::PREFIX, or a FATAL_ERROR naming the package.
function(amfi_require_pkg prefix module debpkg)
  pkg_check_modules(${prefix} QUIET IMPORTED_TARGET GLOBAL ${module})
  if(NOT ${prefix}_FOUND)
    message(FATAL_ERROR "amfi needs ${module} (pkg-config module '${module}' not found): "
      "apt-get install ${debpkg}   (or run scripts/install-deps.sh)")
  endif()
endfunction()

# amfi_require_program(VAR NAME DEBIAN_PACKAGE)
function(amfi_require_program var name debpkg)
  find_program(${var} ${name})
  if(NOT ${var})
    message(FATAL_ERROR "amfi needs the program ${name}: apt-get install ${debpkg}   (or run scripts/install-deps.sh)")
  endif()
endfunction()

amfi_require_pkg(LAPACKE lapacke liblapacke-dev)
amfi_require_pkg(OPENBLAS openblas libopenblas-dev)
amfi_require_pkg(YAML yaml-0.1 libyaml-dev)
amfi_require_pkg(ZLIB zlib zlib1g-dev)
amfi_require_pkg(CMOCKA cmocka libcmocka-dev)
amfi_require_pkg(SQLITE sqlite3 libsqlite3-dev)
amfi_require_pkg(SYSTEMD libsystemd libsystemd-dev)
amfi_require_pkg(JANSSON jansson libjansson-dev)
amfi_require_pkg(PQ libpq libpq-dev)  # amfi-sync (fleet/): the central PostgreSQL
amfi_require_pkg(LCM lcm "liblcm-dev libglib2.0-dev")
amfi_require_pkg(SODIUM libsodium libsodium-dev)  # the signed bus (messages/amfi_auth.c)
amfi_require_program(LCM_GEN_EXECUTABLE lcm-gen liblcm-bin)
amfi_require_program(AMFI_SCDOC scdoc scdoc)

find_library(GSL_LIBRARY gsl)
find_path(GSL_INCLUDE_DIR gsl/gsl_rng.h)
if(NOT GSL_LIBRARY OR NOT GSL_INCLUDE_DIR)
  message(FATAL_ERROR "amfi needs GSL: apt-get install libgsl-dev   (or run scripts/install-deps.sh)")
endif()

find_package(Threads REQUIRED)

# Where systemd wants units, sysusers.d and tmpfiles.d files (pkg-config
# systemd, from the systemd package); overridable for other layouts.
pkg_get_variable(_sd_unitdir systemd systemdsystemunitdir)
pkg_get_variable(_sd_sysusersdir systemd sysusersdir)
pkg_get_variable(_sd_tmpfilesdir systemd tmpfilesdir)
if(NOT _sd_unitdir)
  set(_sd_unitdir /lib/systemd/system)
endif()
if(NOT _sd_sysusersdir)
  set(_sd_sysusersdir /usr/lib/sysusers.d)
endif()
if(NOT _sd_tmpfilesdir)
  set(_sd_tmpfilesdir /usr/lib/tmpfiles.d)
endif()
set(AMFI_SYSTEMD_UNITDIR ${_sd_unitdir} CACHE PATH "systemd system unit directory")
set(AMFI_SYSUSERSDIR ${_sd_sysusersdir} CACHE PATH "sysusers.d directory")
set(AMFI_TMPFILESDIR ${_sd_tmpfilesdir} CACHE PATH "tmpfiles.d directory")
