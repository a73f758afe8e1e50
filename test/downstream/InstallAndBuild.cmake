# ctest driver (ExplicitDeformableModel.InstallDownstream): installs the
# project's build tree into a fresh prefix, builds the downstream project of
# this directory against it and runs it; with the VTK module, also through the
# module and the installed Python package (import edmodel with PYTHONPATH the
# prefix's package directory, no LD_LIBRARY_PATH).
#
# -DBUILD_DIR=<project build tree> -DWORK=<scratch directory> -DSOURCE=<this directory>
# [-DVTK=ON] [-DPYTHON=<interpreter> -DPYTHON_DESTINATION=<relative package directory>]
# (no semicolons in the commands below: run() passes them on as a list)
set(prefix "${WORK}/prefix")
file(REMOVE_RECURSE "${WORK}")
file(MAKE_DIRECTORY "${WORK}")

function(run what)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "${what} failed (${rc}):\n${out}\n${err}")
  endif()
  set(run_output "${out}" PARENT_SCOPE)
endfunction()

run("install" "${CMAKE_COMMAND}" --install "${BUILD_DIR}" --prefix "${prefix}")
if(NOT EXISTS "${prefix}/lib/cmake/ExplicitDeformableModel/ExplicitDeformableModelConfig.cmake")
  message(FATAL_ERROR "no package configuration installed in ${prefix}/lib/cmake/ExplicitDeformableModel")
endif()

set(vtk_option -DEDM_DOWNSTREAM_VTK=OFF)
if(VTK)
  set(vtk_option -DEDM_DOWNSTREAM_VTK=ON)
endif()
run("configure the downstream project" "${CMAKE_COMMAND}" -S "${SOURCE}" -B "${WORK}/build"
  -DCMAKE_BUILD_TYPE=Release "-DCMAKE_PREFIX_PATH=${prefix}" ${vtk_option})
run("build the downstream project" "${CMAKE_COMMAND}" --build "${WORK}/build")
run("run the downstream program" "${WORK}/build/edmDownstream")
message(STATUS "${run_output}")

if(PYTHON)
  set(package "${prefix}/${PYTHON_DESTINATION}")
  if(NOT EXISTS "${package}/edmodel/__init__.py")
    message(FATAL_ERROR "the edmodel package is not in ${package}")
  endif()
  run("import the installed edmodel" "${CMAKE_COMMAND}" -E env --unset=LD_LIBRARY_PATH "PYTHONPATH=${package}"
    "${PYTHON}" -c "import edmodel\nm = edmodel.vtkDeformableMesh()\nprint('edmodel from', edmodel.__file__, m.GetClassName())")
  message(STATUS "${run_output}")
  if(NOT run_output MATCHES "${package}")
    message(FATAL_ERROR "python imported another edmodel: ${run_output}")
  endif()
endif()
