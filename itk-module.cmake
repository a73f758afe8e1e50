# The module's description is the README's text.
get_filename_component(MY_CURRENT_DIR "${CMAKE_CURRENT_LIST_FILE}" PATH)
file(READ "${MY_CURRENT_DIR}/README.md" DOCUMENTATION)

itk_module(ExplicitDeformableModel
  DEPENDS
    ITKCommon
    ITKMesh
    ITKImageGradient
  COMPILE_DEPENDS
    ITKImageFilterBase
    ITKImageIntensity
    ITKSmoothing
  TEST_DEPENDS
    ITKTestKernel
    ITKGoogleTest
  DESCRIPTION
    "${DOCUMENTATION}"
  EXCLUDE_FROM_DEFAULT
)
