# Standalone build against an installed ITK (no ITKModuleExternal.cmake, as
# Debian's ITK 5.2.1), with plain CMake.
include(CTest)

# The modules of itk-module.cmake: DEPENDS (the headers), PRIVATE_DEPENDS
# (the IO of edmodel and the examples) and, for the tests, TEST_DEPENDS.
set(EDM_ITK_COMPONENTS
  ITKCommon ITKMesh ITKImageGradient ITKSmoothing ITKDistanceMap ITKThresholding
  ITKIOImageBase ITKIOMeshBase ITKIOMeshVTK ITKIOMeshOBJ ITKIOMeshOFF ITKIOMeshGifti
  ITKIONIFTI ITKIONRRD ITKIOMeta ITKIOGDCM ITKIOPNG)
if(BUILD_TESTING)
  list(APPEND EDM_ITK_COMPONENTS ITKImageNoise)
endif()
find_package(ITK 5.2 REQUIRED COMPONENTS ${EDM_ITK_COMPONENTS})
include(${ITK_USE_FILE})

include(cmake/ExplicitDeformableModelParts.cmake)

# The core's GoogleTests and their kernel-path reruns depend on neither VTK
# nor ParaView: a second configuration of the same sources against another
# VTK (CI's ParaView stage) may leave them to the first.
option(EDM_BUILD_CORE_TESTS "Build and register the core's GoogleTests (test/)" ON)
mark_as_advanced(EDM_BUILD_CORE_TESTS)
if(BUILD_TESTING AND EDM_BUILD_CORE_TESTS)
  add_subdirectory(test)
endif()

# --- Installed, it is usable: a CMake package configuration ----------------
# find_package(ExplicitDeformableModel [COMPONENTS VTK]) in
# <prefix>/lib/cmake/ExplicitDeformableModel, with the targets
# ExplicitDeformableModel::ExplicitDeformableModel and, when the VTK module was
# built, EDM::ExplicitDeformableModelVTK (test/downstream uses both).
include(CMakePackageConfigHelpers)
set(EDM_CMAKE_DESTINATION "${CMAKE_INSTALL_LIBDIR}/cmake/ExplicitDeformableModel")
install(TARGETS ExplicitDeformableModel EXPORT ExplicitDeformableModelTargets)
install(EXPORT ExplicitDeformableModelTargets NAMESPACE ExplicitDeformableModel::
  DESTINATION "${EDM_CMAKE_DESTINATION}" COMPONENT Development)
set(EDM_CONFIG_VTK_FIND_ARGS "")
if(TARGET EDM::ExplicitDeformableModelVTK)
  set(EDM_CONFIG_VTK_FIND_ARGS "COMPONENTS CommonCore CommonDataModel CommonExecutionModel IOXML HINTS \"${VTK_DIR}\"")
endif()
if(NOT EDM_PYTHON_DESTINATION)
  set(EDM_PYTHON_DESTINATION "lib/python3/dist-packages")
endif()
configure_package_config_file(cmake/ExplicitDeformableModelConfig.cmake.in
  "${PROJECT_BINARY_DIR}/ExplicitDeformableModelConfig.cmake"
  INSTALL_DESTINATION "${EDM_CMAKE_DESTINATION}")
write_basic_package_version_file("${PROJECT_BINARY_DIR}/ExplicitDeformableModelConfigVersion.cmake"
  COMPATIBILITY SameMinorVersion)
install(FILES "${PROJECT_BINARY_DIR}/ExplicitDeformableModelConfig.cmake"
  "${PROJECT_BINARY_DIR}/ExplicitDeformableModelConfigVersion.cmake"
  DESTINATION "${EDM_CMAKE_DESTINATION}" COMPONENT Development)

# The CI test of the installed package: install into a fresh prefix, build
# test/downstream against it (core and VTK module) and run it; import the
# installed Python package.
if(BUILD_TESTING)
  set(_edm_downstream_options "")
  if(TARGET EDM::ExplicitDeformableModelVTK)
    list(APPEND _edm_downstream_options -DVTK=ON)
  endif()
  if(EDM_PYTHON_ENABLED)
    list(APPEND _edm_downstream_options "-DPYTHON=${Python3_EXECUTABLE}" "-DPYTHON_DESTINATION=${EDM_PYTHON_DESTINATION}")
  endif()
  add_test(NAME ExplicitDeformableModel.InstallDownstream
    COMMAND ${CMAKE_COMMAND} "-DBUILD_DIR=${PROJECT_BINARY_DIR}" "-DWORK=${PROJECT_BINARY_DIR}/test/downstream"
      "-DSOURCE=${PROJECT_SOURCE_DIR}/test/downstream" ${_edm_downstream_options}
      -P "${PROJECT_SOURCE_DIR}/test/downstream/InstallAndBuild.cmake")
  set_tests_properties(ExplicitDeformableModel.InstallDownstream PROPERTIES TIMEOUT 900)
endif()
