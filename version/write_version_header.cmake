# cmake -DSOURCE_DIR=... -DOUTPUT=... -DVERSION=... -P write_version_header.cmake
# Writes OUTPUT with CDPR_VERSION and CDPR_GIT_DESCRIBE ("" outside a git
# checkout, e.g. a source package), touching it only when that changes.
set(describe "")
find_program(GIT git)
if(GIT AND EXISTS "${SOURCE_DIR}/.git")
  execute_process(COMMAND "${GIT}" -C "${SOURCE_DIR}" describe --always --dirty --tags
                  OUTPUT_VARIABLE describe OUTPUT_STRIP_TRAILING_WHITESPACE ERROR_QUIET RESULT_VARIABLE status)
  if(NOT status EQUAL 0)
    set(describe "")
  endif()
endif()
set(text "#pragma once\n#define CDPR_VERSION \"${VERSION}\"\n#define CDPR_GIT_DESCRIBE \"${describe}\"\n")
if(EXISTS "${OUTPUT}")
  file(READ "${OUTPUT}" old)
endif()
if(NOT old STREQUAL text)
  file(WRITE "${OUTPUT}" "${text}")
endif()
