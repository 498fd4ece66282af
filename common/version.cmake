# SPDX-License-Identifier: GPL-3.0-or-later
# version.cmake (cmake -P): writes OUT from TEMPLATE with AMFI_VERSION_STRING
# = VERSION, plus "+DESCRIBE" (git describe --always --dirty) when SRC is a
# git checkout and git is installed. Rewrites OUT only when it changes.
set(AMFI_VERSION_STRING "${VERSION}")
if(EXISTS "${SRC}/.git")
  find_program(GIT_EXECUTABLE git)
  if(GIT_EXECUTABLE)
    execute_process(COMMAND "${GIT_EXECUTABLE}" -C "${SRC}" describe --always --dirty
                    OUTPUT_VARIABLE describe OUTPUT_STRIP_TRAILING_WHITESPACE
                    RESULT_VARIABLE rc ERROR_QUIET)
    if(rc EQUAL 0 AND describe)
      set(AMFI_VERSION_STRING "${VERSION}+${describe}")
    endif()
  endif()
endif()
configure_file("${TEMPLATE}" "${OUT}" @ONLY)
