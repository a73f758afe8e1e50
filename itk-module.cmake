set(DOCUMENTATION "Explicit deformable models: a triangulated surface mesh moves, iteration after \
iteration, under external forces sampled from an image (the gradient of its smoothed gradient \
magnitude, optionally diffused by gradient vector flow) and internal forces (elasticity, rigidity, \
balloon) until it sits on the boundary of an object. Everything is in physical space, the step runs \
multithreaded on flat arrays, and the iteration resumes one step at a time, which makes animation \
cheap. Filters: IterativeMeshFilter, BrownianMeshFilter, DeformableMeshFilter, ExternalForceImageFilter.")

# DEPENDS: what the headers of include/ include. PRIVATE_DEPENDS: the image
# and mesh IO of the edmodel application (src/) and the examples, which the
# module's users do not need. TEST_DEPENDS: what test/ includes.
itk_module(ExplicitDeformableModel
  DEPENDS
    ITKCommon
    ITKImageGradient
    ITKMesh
    ITKSmoothing
  PRIVATE_DEPENDS
    ITKIOGDCM
    ITKIOImageBase
    ITKIOMeshBase
    ITKIOMeshGifti
    ITKIOMeshOBJ
    ITKIOMeshOFF
    ITKIOMeshVTK
    ITKIOMeta
    ITKIONIFTI
    ITKIONRRD
    ITKIOPNG
  TEST_DEPENDS
    ITKGoogleTest
    ITKImageNoise
    ITKTestKernel
  DESCRIPTION
    "${DOCUMENTATION}"
  EXCLUDE_FROM_DEFAULT
)
