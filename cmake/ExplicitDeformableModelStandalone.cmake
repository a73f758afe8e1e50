# Standalone build against an installed ITK, with plain CMake.
include(GNUInstallDirs)
include(CTest)

set(EDM_ITK_COMPONENTS
  ITKCommon ITKMesh ITKImageGradient ITKImageFilterBase ITKImageIntensity ITKSmoothing
  ITKIOImageBase ITKIOMeshBase ITKIOMeshVTK ITKIOMeshOBJ ITKIOMeshOFF ITKIOMeshGifti
  ITKIONIFTI ITKIONRRD ITKIOMeta ITKIOGDCM ITKIOPNG)
find_package(ITK 5.2 REQUIRED COMPONENTS ${EDM_ITK_COMPONENTS})
include(${ITK_USE_FILE})

# The core is header-only templates.
add_library(ExplicitDeformableModel INTERFACE)
add_library(ExplicitDeformableModel::ExplicitDeformableModel ALIAS ExplicitDeformableModel)
target_include_directories(ExplicitDeformableModel INTERFACE
  $<BUILD_INTERFACE:${PROJECT_SOURCE_DIR}/include>
  $<INSTALL_INTERFACE:${CMAKE_INSTALL_INCLUDEDIR}/ExplicitDeformableModel>)
target_link_libraries(ExplicitDeformableModel INTERFACE ${ITK_LIBRARIES})
install(DIRECTORY include/ DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/ExplicitDeformableModel)

set(CMAKE_RUNTIME_OUTPUT_DIRECTORY ${PROJECT_BINARY_DIR}/bin)

if(BUILD_TESTING)
  add_subdirectory(test)
endif()
option(EDM_BUILD_EXAMPLES "Build the examples" ON)
if(EDM_BUILD_EXAMPLES)
  add_subdirectory(examples)
endif()

# Optional VTK faces (vtk/): the VTK module, Python wrapping (import edmodel),
# rendering examples. AUTO builds them when find_package(VTK) succeeds.
set(EDM_USE_VTK AUTO CACHE STRING "Build the VTK module and Python wrapping: AUTO (when VTK is found), ON, OFF")
set_property(CACHE EDM_USE_VTK PROPERTY STRINGS AUTO ON OFF)
# The ParaView plugin (paraview/) builds the VTK module against ParaView's VTK.
option(BUILD_PARAVIEW_PLUGIN "Build the ParaView plugin (paraview/): VTK from ParaView, needs paraview-dev" OFF)
if(BUILD_PARAVIEW_PLUGIN)
  set(EDM_USE_VTK ON CACHE STRING "Build the VTK module and Python wrapping: AUTO (when VTK is found), ON, OFF" FORCE)
  set(EDM_VTK_FROM_PARAVIEW ON CACHE BOOL "Take VTK from an installed ParaView instead of a plain VTK" FORCE)
endif()
if(NOT EDM_USE_VTK STREQUAL "OFF")
  add_subdirectory(vtk)
endif()
# edmodel (src/) after vtk/: it uses the VTK module and edmRendering when built.
if(EXISTS ${PROJECT_SOURCE_DIR}/src/CMakeLists.txt)
  add_subdirectory(src)
endif()
if(BUILD_PARAVIEW_PLUGIN)
  add_subdirectory(paraview)
endif()

# Benchmarks (bench/, Google Benchmark): on by default when benchmark is found.
find_package(benchmark QUIET)
option(EDM_BUILD_BENCHMARKS "Build the benchmarks (bench/, needs Google Benchmark)" ${benchmark_FOUND})
if(EDM_BUILD_BENCHMARKS)
  add_subdirectory(bench)
endif()
