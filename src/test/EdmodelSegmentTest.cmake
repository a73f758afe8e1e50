# End-to-end run of 'edmodel segment' on a generated ellipsoid image; the
# output mesh is read back and measured against the exact ellipsoid.
#
# EDMODEL, TOOL, WORK: the programs and the test's directory.
# PHANTOM: edmodelTestTool arguments that write the image (phantom or dicom).
# SETUP: optional extra helper command (edmodelTestTool arguments).
# SEGMENT: edmodel arguments.
# OUTPUT: the mesh edmodel writes, measured with MEASURE (edmodelTestTool
# measure arguments after the path).
# CONVERT: optional edmodel arguments run after the segmentation that turn
# OUTPUT into MEASURED (a format the measuring tool reads), then measured.
# PRESENT: optional files that must exist afterwards.
# MEASURE_COMMAND: the edmodelTestTool command that measures (default
# measure: a mesh against an ellipsoid; measure-contour: a 2-D contour
# against an ellipse; check-ends: the ends of an open contour). CHECK: optional edmodelTestTool arguments of a further
# check that must succeed (e.g. check-overlay).
# REQUIRES_VTK: skip (message "test skipped") when edmodel is built without VTK.
cmake_minimum_required(VERSION 3.16)
include(${CMAKE_CURRENT_LIST_DIR}/EdmodelTestCommon.cmake)

if(REQUIRES_VTK AND NOT EDM_WITH_VTK)
  message(STATUS "edmodel test skipped: edmodel is built without VTK")
  return()
endif()
edm_fresh_work()
edm_run_helper("${TOOL}|${PHANTOM}")
if(SETUP)
  edm_run_helper("${TOOL}|${SETUP}")
endif()

edm_expand(arguments "${SEGMENT}")
edm_expand(output "${OUTPUT}")
execute_process(COMMAND ${EDMODEL} ${arguments} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
message(STATUS "edmodel ${arguments}\n${err}${out}")
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "edmodel exited with ${rc}")
endif()
if("--quiet" IN_LIST arguments)
  if(NOT err STREQUAL "" OR NOT out STREQUAL "")
    message(FATAL_ERROR "--quiet, yet edmodel printed something")
  endif()
elseif(NOT err MATCHES "edmodel: deforming: [0-9]+ iterations" OR NOT out MATCHES "^edmodel: wrote ")
  message(FATAL_ERROR "no progress on stderr or no summary on stdout")
endif()
if(NOT EXISTS "${output}")
  message(FATAL_ERROR "no output mesh ${output}")
endif()
# With the collision test (on by default for surfaces, off with
# --allow-self-intersections) the surface never intersects itself.
if(out MATCHES "surface quality: ([0-9]+) intersecting pairs" AND NOT "--allow-self-intersections" IN_LIST arguments
   AND NOT CMAKE_MATCH_1 EQUAL 0)
  message(FATAL_ERROR "the surface intersects itself: ${CMAKE_MATCH_1} pairs of triangles")
endif()
edm_check_no_leftovers()

edm_expand(present "${PRESENT}")
foreach(file IN LISTS present)
  if(NOT EXISTS "${file}")
    message(FATAL_ERROR "edmodel did not write ${file}")
  endif()
endforeach()

if(CONVERT)
  edm_expand(convert "${CONVERT}")
  execute_process(COMMAND ${EDMODEL} ${convert} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "edmodel ${convert} exited with ${rc}\n${err}")
  endif()
  edm_expand(output "${MEASURED}")
endif()

if(CHECK)
  edm_run_helper("${TOOL}|${CHECK}")
endif()

if(NOT MEASURE_COMMAND)
  set(MEASURE_COMMAND measure)
endif()
edm_expand(measure "${MEASURE}")
execute_process(COMMAND ${TOOL} ${MEASURE_COMMAND} ${output} ${measure} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
message(STATUS "${out}${err}")
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "the output is not on the known boundary")
endif()
