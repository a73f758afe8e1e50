# Shared by the edmodel test drivers (cmake -P). Lists arrive with "|" between
# items (ctest would split ";"), and "@WORK@" stands for the test's directory.

function(edm_expand out text)
  string(REPLACE "|" ";" list "${text}")
  string(REPLACE "@WORK@" "${WORK}" list "${list}")
  set(${out} "${list}" PARENT_SCOPE)
endfunction()

# Runs a helper command that must succeed.
function(edm_run_helper text)
  edm_expand(command "${text}")
  execute_process(COMMAND ${command} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "helper failed (${rc}): ${command}\n${out}${err}")
  endif()
  message(STATUS "${out}")
endfunction()

# A fresh, empty working directory.
function(edm_fresh_work)
  file(REMOVE_RECURSE "${WORK}")
  file(MAKE_DIRECTORY "${WORK}")
endfunction()

# Fails when a temporary output of edmodel is left in the working directory.
function(edm_check_no_leftovers)
  file(GLOB leftovers LIST_DIRECTORIES true "${WORK}/.edmodel-*")
  if(leftovers)
    message(FATAL_ERROR "temporary output left behind: ${leftovers}")
  endif()
endfunction()

# EDM_WITH_VTK: whether this edmodel writes .vtp, .stl and .pvd.
execute_process(COMMAND ${EDMODEL} --version OUTPUT_VARIABLE _edm_version RESULT_VARIABLE _edm_rc)
if(_edm_version MATCHES "with VTK")
  set(EDM_WITH_VTK ON)
else()
  set(EDM_WITH_VTK OFF)
endif()
