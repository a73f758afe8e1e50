# An error case of edmodel: one line on stderr matching EXPECT, exit code
# EXPECT_RC (default 2), nothing on stdout, and no output file.
#
# EDMODEL, TOOL, WORK: the programs and the test's directory.
# SETUP, SETUP2: optional helper commands (edmodelTestTool arguments).
# GARBAGE: optional file to fill with text that is no image or mesh.
# ARGS: edmodel arguments. ABSENT: files that must not exist afterwards.
# WITH_VTK_PRESENT: for the errors of a build without VTK: when edmodel is
# built with VTK, the run must succeed instead and write these files.
cmake_minimum_required(VERSION 3.16)
include(${CMAKE_CURRENT_LIST_DIR}/EdmodelTestCommon.cmake)

if(NOT DEFINED EXPECT_RC)
  set(EXPECT_RC 2)
endif()
edm_fresh_work()
foreach(setup SETUP SETUP2)
  if(${setup})
    edm_run_helper("${TOOL}|${${setup}}")
  endif()
endforeach()

if(GARBAGE)
  edm_expand(garbage "${GARBAGE}")
  file(WRITE "${garbage}" "this is not an image\n")
endif()

edm_expand(arguments "${ARGS}")
execute_process(COMMAND ${EDMODEL} ${arguments} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
message(STATUS "edmodel ${arguments}\nexit code ${rc}\nstderr: ${err}stdout: ${out}")
if(WITH_VTK_PRESENT AND EDM_WITH_VTK)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "built with VTK, edmodel should succeed here")
  endif()
  edm_expand(present "${WITH_VTK_PRESENT}")
  foreach(file IN LISTS present)
    if(NOT EXISTS "${file}")
      message(FATAL_ERROR "edmodel did not write ${file}")
    endif()
  endforeach()
  edm_check_no_leftovers()
  return()
endif()
if(NOT rc STREQUAL "${EXPECT_RC}")
  message(FATAL_ERROR "exit code ${rc}, expected ${EXPECT_RC}")
endif()
if(NOT err MATCHES "^edmodel: [^\n]+\n$")
  message(FATAL_ERROR "stderr is not one line starting with 'edmodel: '")
endif()
if(NOT err MATCHES "${EXPECT}")
  message(FATAL_ERROR "stderr does not match '${EXPECT}'")
endif()
if(NOT out STREQUAL "")
  message(FATAL_ERROR "unexpected output on stdout")
endif()
edm_expand(absent "${ABSENT}")
foreach(file IN LISTS absent)
  if(EXISTS "${file}")
    message(FATAL_ERROR "output file ${file} was written")
  endif()
endforeach()
edm_check_no_leftovers()
