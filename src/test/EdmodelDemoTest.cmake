# edmodel demo: exit code 0 (accuracy good), the files it promises, and the
# accuracy figures on stdout.
cmake_minimum_required(VERSION 3.16)
file(REMOVE_RECURSE "${WORK}")
execute_process(COMMAND ${EDMODEL} demo --output-dir ${WORK}/out RESULT_VARIABLE rc OUTPUT_VARIABLE out
  ERROR_VARIABLE err)
message(STATUS "${out}")
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "edmodel demo exited with ${rc}\n${err}")
endif()
foreach(file demo-image.nii.gz demo-force.mha demo-sphere.vtk demo-mesh.vtk)
  if(NOT EXISTS ${WORK}/out/${file})
    message(FATAL_ERROR "edmodel demo did not write ${file}")
  endif()
endforeach()
if(NOT out MATCHES "final mesh: +mean [0-9.e-]+ voxel, max [0-9.e-]+ voxel" OR NOT out MATCHES "accuracy good")
  message(FATAL_ERROR "edmodel demo did not report its accuracy")
endif()
