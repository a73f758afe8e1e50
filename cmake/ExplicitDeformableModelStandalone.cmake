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

if(BUILD_TESTING)
  add_subdirectory(test)
endif()
