# The parts of the project around the ITK module, shared by the three builds
# (CMakeLists.txt): the core's CMake target, the examples, the VTK module and
# its Python package, the edmodel application (src/), the ParaView plugin,
# the benchmarks and the package configuration.
#
# EDM_ITK_MODULE_SYSTEM is ON inside ITK's module machinery (ITK's tree, or
# ITKModuleExternal), where ITK declared the module and adds test/ itself.

# edm_use_itk_io(): in the current directory, registers the image and mesh IO
# factories of the module's dependencies (ITK's UseITK.cmake) for programs
# that read or write files. The standalone build did it for the whole project.
macro(edm_use_itk_io)
  if(EDM_ITK_MODULE_SYSTEM)
    if(ITK_SOURCE_DIR)
      # ITK's own stand-in for ITKConfig.cmake during its configuration (what
      # itk_module_examples() uses).
      set(ITK_DIR "${ITK_BINARY_DIR}/CMakeTmp")
    endif()
    find_package(ITK REQUIRED COMPONENTS ${ITK_MODULE_ExplicitDeformableModel_DEPENDS})
    if(DEFINED ITK_INTERFACE_LIBRARIES AND COMMAND itk_generate_factory_registration)
      # ITK 6 deprecates UseITK.cmake: the registration headers are generated
      # here and the factory meta-modules (ITK::ITKImageIO, ITK::ITKMeshIO)
      # carry them.
      itk_generate_factory_registration()
      list(APPEND ITK_LIBRARIES ${ITK_INTERFACE_LIBRARIES})
      foreach(_edm_factory IN ITEMS ITK::ITKImageIO ITK::ITKMeshIO)
        if(TARGET ${_edm_factory})
          list(APPEND ITK_LIBRARIES ${_edm_factory})
        endif()
      endforeach()
    else()
      include(${ITK_USE_FILE})
    endif()
  endif()
endmacro()

if(EDM_ITK_MODULE_SYSTEM)
  # What the standalone build asks find_package(ITK) for.
  set(EDM_ITK_COMPONENTS ${ITK_MODULE_ExplicitDeformableModel_DEPENDS})
endif()

# --- The core: header-only templates ----------------------------------------
add_library(ExplicitDeformableModel INTERFACE)
add_library(ExplicitDeformableModel::ExplicitDeformableModel ALIAS ExplicitDeformableModel)
target_include_directories(ExplicitDeformableModel INTERFACE
  $<BUILD_INTERFACE:${PROJECT_SOURCE_DIR}/include>
  $<INSTALL_INTERFACE:${CMAKE_INSTALL_INCLUDEDIR}/ExplicitDeformableModel>)
target_compile_features(ExplicitDeformableModel INTERFACE cxx_std_17)
if(EDM_ITK_MODULE_SYSTEM)
  # The libraries of the modules the headers include.
  foreach(_edm_dep IN LISTS ITK_MODULE_ExplicitDeformableModel_PUBLIC_DEPENDS)
    target_link_libraries(ExplicitDeformableModel INTERFACE ${${_edm_dep}_LIBRARIES})
    target_include_directories(ExplicitDeformableModel INTERFACE
      "$<BUILD_INTERFACE:${${_edm_dep}_INCLUDE_DIRS}>")
  endforeach()
else()
  target_link_libraries(ExplicitDeformableModel INTERFACE ${ITK_LIBRARIES})
  install(DIRECTORY include/ DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/ExplicitDeformableModel
    COMPONENT Development)
endif()

if(NOT CMAKE_RUNTIME_OUTPUT_DIRECTORY)
  set(CMAKE_RUNTIME_OUTPUT_DIRECTORY ${PROJECT_BINARY_DIR}/bin)
endif()

option(EDM_BUILD_EXAMPLES "Build the examples" ON)
if(EDM_BUILD_EXAMPLES)
  add_subdirectory(examples)
endif()

# Inside ITK's tree only the module and its applications are built: ITK's
# configuration is not the place for VTK, ParaView or Google Benchmark.
if(ITK_SOURCE_DIR)
  message(STATUS "ExplicitDeformableModel: inside ITK's tree: building the module, edmodel and the examples; "
    "the VTK module, the ParaView plugin and the benchmarks build standalone or through ITKModuleExternal.")
else()
  # Optional VTK faces (vtk/): the VTK module, Python wrapping (import
  # edmodel), rendering examples. AUTO builds them when find_package(VTK)
  # succeeds.
  set(EDM_USE_VTK AUTO CACHE STRING "Build the VTK module and Python wrapping: AUTO (when VTK is found), ON, OFF")
  set_property(CACHE EDM_USE_VTK PROPERTY STRINGS AUTO ON OFF)
  # The ParaView plugin (paraview/) builds the VTK module against ParaView's VTK.
  option(BUILD_PARAVIEW_PLUGIN "Build the ParaView plugin (paraview/): VTK from ParaView, needs paraview-dev" OFF)
  if(BUILD_PARAVIEW_PLUGIN)
    set(EDM_USE_VTK ON CACHE STRING "Build the VTK module and Python wrapping: AUTO (when VTK is found), ON, OFF"
      FORCE)
    set(EDM_VTK_FROM_PARAVIEW ON CACHE BOOL "Take VTK from an installed ParaView instead of a plain VTK" FORCE)
  endif()
  if(NOT EDM_USE_VTK STREQUAL "OFF")
    add_subdirectory(vtk)
  else()
    message(STATUS "ExplicitDeformableModel: EDM_USE_VTK=OFF, the VTK module is not built.")
  endif()
endif()
# edmodel (src/) after vtk/: it uses the VTK module and edmRendering when built.
if(EXISTS ${PROJECT_SOURCE_DIR}/src/CMakeLists.txt)
  add_subdirectory(src)
endif()
if(BUILD_PARAVIEW_PLUGIN AND NOT ITK_SOURCE_DIR)
  add_subdirectory(paraview)
endif()
# Validation on real scans (validation/): the standalone build, whose ITK
# components include the scoring tool's ITKDistanceMap and ITKThresholding.
if(NOT EDM_ITK_MODULE_SYSTEM)
  add_subdirectory(validation)
else()
  message(STATUS "ExplicitDeformableModel: the real-image validation (validation/) builds standalone only.")
endif()

# Benchmarks (bench/, Google Benchmark): on by default when benchmark is found
# and the ITK has ITKDeformableMesh, the reference of the comparison.
if(NOT ITK_SOURCE_DIR)
  find_package(benchmark QUIET)
  list(FIND ITK_MODULES_ENABLED ITKDeformableMesh _edm_has_simplex)
  set(_edm_bench_default OFF)
  if(benchmark_FOUND AND (_edm_has_simplex GREATER -1 OR NOT EDM_ITK_MODULE_SYSTEM))
    set(_edm_bench_default ON)
  elseif(NOT benchmark_FOUND)
    message(STATUS "ExplicitDeformableModel: Google Benchmark not found (Debian: libbenchmark-dev), "
      "the benchmarks are not built.")
  else()
    message(STATUS "ExplicitDeformableModel: this ITK has no ITKDeformableMesh, the benchmarks are not built.")
  endif()
  option(EDM_BUILD_BENCHMARKS "Build the benchmarks (bench/, needs Google Benchmark)" ${_edm_bench_default})
  if(EDM_BUILD_BENCHMARKS)
    add_subdirectory(bench)
  endif()
endif()
