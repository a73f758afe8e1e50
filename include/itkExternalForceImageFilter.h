/*=========================================================================
 *
 *  Copyright NumFOCUS
 *
 *  Licensed under the Apache License, Version 2.0 (the "License");
 *  you may not use this file except in compliance with the License.
 *  You may obtain a copy of the License at
 *
 *         http://www.apache.org/licenses/LICENSE-2.0.txt
 *
 *  Unless required by applicable law or agreed to in writing, software
 *  distributed under the License is distributed on an "AS IS" BASIS,
 *  WITHOUT WARRANTIES OR CONDITIONS OF ANY KIND, either express or implied.
 *  See the License for the specific language governing permissions and
 *  limitations under the License.
 *
 *=========================================================================*/
#ifndef itkExternalForceImageFilter_h
#define itkExternalForceImageFilter_h

#include "itkGradientImageFilter.h"
#include "itkExplicitDeformableModelCompatibility.h"

namespace itk
{

/** \class ExternalForceImageFilter
 * \brief Computes the external force field of a deformable model from a scalar
 * image: the gradient of the edge map, \f$ \nabla |\nabla (G_\sigma * I)| \f$,
 * optionally diffused by gradient vector flow.
 *
 * The force at a point points toward the nearest ridge of the gradient
 * magnitude, that is toward the object boundary, so a DeformableMeshFilter
 * sampling this field pulls its vertices onto the boundary.
 *
 * Steps, all in physical space (origin, spacing and direction honoured):
 * -# Gaussian smoothing of standard deviation Sigma (physical units; 0 skips
 *    it): separable, the Gaussian sampled and truncated at 4 Sigma along each
 *    axis and normalised, border pixels repeated beyond the image;
 * -# edge map \f$ e = |\nabla (G_\sigma * I)| \f$;
 * -# force \f$ F = \nabla e \f$.
 *
 * Both derivatives are central differences with a zero-flux boundary, as
 * GradientImageFilter computes them, honouring the inherited UseImageSpacing
 * and UseImageDirection (both On by default). Smoothing and derivatives run
 * on the raw buffers, threaded over rows of pixels: the whole filter is
 * faster per voxel than two GradientImageFilter passes (OverrideBoundaryCondition
 * does not apply).
 * Then:
 * -# with UseGradientVectorFlow, the gradient vector flow of Xu and Prince:
 *    \f$ \partial_t v = \mu \nabla^2 v - |\nabla e|^2 (v - \nabla e) \f$ iterated
 *    GradientVectorFlowIterations times from \f$ v = \nabla e \f$, with the
 *    Laplacian in physical units (anisotropic spacing honoured), the edge map
 *    normalised to [0, 1] first, a stable time step chosen from the spacing,
 *    multithreaded. It extends the capture range of the force far from edges
 *    and into concavities;
 * -# with NormalizeForces (default On), the field is divided by its largest
 *    length, so that the largest force has length 1 whatever the intensity
 *    range of the image. DeformableMeshFilter's ScaleFactor is then the largest
 *    external displacement per iteration in physical units.
 *
 * Without normalisation the output is in intensity units per squared physical
 * unit.
 *
 * Bad input is an ExceptionObject, never a non-finite output: an input pixel
 * that is NaN or infinite, a Sigma beyond the image's extent, a raw field that
 * does not fit the output pixel type, and a failed memory allocation (the
 * message gives the size needed). Intensities of any finite magnitude (up to
 * the largest float or double, down to denormals) give the same normalised
 * field: they are scaled by a power of two before the derivatives.
 *
 * \sa DeformableMeshFilter, GradientImageFilter
 * \ingroup ExplicitDeformableModel
 */
template <typename TInputImage,
          typename TOutputImage =
            Image<CovariantVector<float, TInputImage::ImageDimension>, TInputImage::ImageDimension>>
class ITK_TEMPLATE_EXPORT ExternalForceImageFilter
  : public GradientImageFilter<TInputImage,
                               typename TOutputImage::PixelType::ValueType,
                               typename TOutputImage::PixelType::ValueType,
                               TOutputImage>
{
public:
  ITK_DISALLOW_COPY_AND_MOVE(ExternalForceImageFilter);

  /** Standard class type aliases. */
  using Self = ExternalForceImageFilter;
  using Superclass = GradientImageFilter<TInputImage,
                                         typename TOutputImage::PixelType::ValueType,
                                         typename TOutputImage::PixelType::ValueType,
                                         TOutputImage>;
  using Pointer = SmartPointer<Self>;
  using ConstPointer = SmartPointer<const Self>;

  /** Method for creation through the object factory. */
  itkNewMacro(Self);

  /** Run-time type information (and related methods). */
  itkOverrideGetNameOfClassMacro(ExternalForceImageFilter);

  static constexpr unsigned int ImageDimension = TInputImage::ImageDimension;

  using InputImageType = TInputImage;
  using OutputImageType = TOutputImage;
  using OutputPixelType = typename OutputImageType::PixelType;
  using OutputValueType = typename OutputPixelType::ValueType;
  using RealImageType = Image<float, ImageDimension>;

  /** Standard deviation of the Gaussian smoothing, in physical units (mm for
   * medical images). It sets the capture range of the plain gradient force
   * (about 2 to 3 Sigma on each side of an edge). 0 disables smoothing.
   * Must be finite, non-negative and at most the largest physical extent of
   * the input image (beyond it the smoothed image has no edge left); the
   * update throws an ExceptionObject otherwise. Default: 1.0. */
  itkSetMacro(Sigma, double);
  itkGetConstMacro(Sigma, double);

  /** Divide the field by its largest vector length, so that forces are at
   * most 1 (dimensionless) whatever the intensity range. Default: On. */
  itkSetMacro(NormalizeForces, bool);
  itkGetConstMacro(NormalizeForces, bool);
  itkBooleanMacro(NormalizeForces);

  /** Diffuse the force by gradient vector flow (Xu and Prince, 1998) to reach
   * far from edges. Default: Off. */
  itkSetMacro(UseGradientVectorFlow, bool);
  itkGetConstMacro(UseGradientVectorFlow, bool);
  itkBooleanMacro(UseGradientVectorFlow);

  /** Regularisation weight mu of gradient vector flow (dimensionless, with the
   * edge map normalised to [0, 1]): larger values give smoother fields that
   * reach farther. Must be positive and finite. Default: 0.1. */
  itkSetMacro(GradientVectorFlowRegularization, double);
  itkGetConstMacro(GradientVectorFlowRegularization, double);

  /** Number of explicit diffusion iterations of gradient vector flow. The
   * distance the field spreads grows as the square root of this number.
   * Default: 400. */
  itkSetMacro(GradientVectorFlowIterations, unsigned int);
  itkGetConstMacro(GradientVectorFlowIterations, unsigned int);

  /** The whole input is needed (Gaussian smoothing and diffusion are global). */
  void
  GenerateInputRequestedRegion() override;

protected:
  ExternalForceImageFilter() = default;
  ~ExternalForceImageFilter() override = default;

  void
  PrintSelf(std::ostream & os, Indent indent) const override;

  void
  VerifyPreconditions() const override;

  void
  EnlargeOutputRequestedRegion(DataObject * output) override;

  void
  GenerateData() override;

private:
  /** GenerateData() without the checks and the conversion of std::bad_alloc. */
  void
  ComputeForceField(const InputImageType * input);

  /** The input as floats, smoothed by a Gaussian of standard deviation Sigma
   * (physical units): separable, sampled and truncated at 4 Sigma along each
   * axis, border pixels repeated, threaded over lines and rows of pixels. */
  typename RealImageType::Pointer
  Smooth(const InputImageType * input);

  using SizeType = typename RealImageType::SizeType;

  /** Start (buffer offset) of line number \a line of pixels along x, and the
   * offsets from a pixel of that line to its lower and upper neighbours along
   * the other axes: 0 at the border, so that a missing neighbour is the pixel
   * itself (zero-flux boundary). lower[0] and upper[0] are left to the caller.
   * The three arrays have ImageDimension elements (pointers, not references
   * to arrays: ITK 5.2's wrapping writes those in a form SWIG cannot parse). */
  static OffsetValueType
  LocateLine(SizeValueType           line,
             const SizeType &        size,
             const OffsetValueType * stride,
             OffsetValueType *       lower,
             OffsetValueType *       upper);

  /** Pixels per block of ForEachCentralDifference(). */
  static constexpr SizeValueType CentralDifferenceBlockLength = 256;

  /** Central differences of \a image on its buffer, threaded over lines of
   * pixels along x, each line in blocks of up to
   * CentralDifferenceBlockLength pixels: calls function(line, offset, count,
   * derivative) for each block, the block being the \a count pixels from
   * buffer offset \a offset on line number \a line, and
   * derivative[d * CentralDifferenceBlockLength + k] the derivative along
   * axis d at its pixel k: (v[+1] - v[-1]) / (2 h_d), h_d the spacing when
   * UseImageSpacing is on (else 1), with a zero-flux boundary, as
   * GradientImageFilter computes it, without its neighbourhood iterators.
   * The blocks of a line are visited in order by one thread; the loops over
   * a block's pixels vectorise. */
  template <typename TFunction>
  void
  ForEachCentralDifference(const RealImageType * image, const TFunction & function);

  /** In-place gradient vector flow diffusion of the field. */
  void
  DiffuseGradientVectorFlow(OutputImageType * field);

  double       m_Sigma{ 1.0 };
  bool         m_NormalizeForces{ true };
  bool         m_UseGradientVectorFlow{ false };
  double       m_GradientVectorFlowRegularization{ 0.1 };
  unsigned int m_GradientVectorFlowIterations{ 400 };
  /** The intensities are divided by 2^m_IntensityExponent on conversion to
   * float (0 for magnitudes between 2^-40 and 2^40). */
  int m_IntensityExponent{ 0 };
};
} // end namespace itk

#ifndef ITK_MANUAL_INSTANTIATION
#  include "itkExternalForceImageFilter.hxx"
#endif

#endif
