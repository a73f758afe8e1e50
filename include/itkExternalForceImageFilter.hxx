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
#ifndef itkExternalForceImageFilter_hxx
#define itkExternalForceImageFilter_hxx

#include "itkExternalForceImageFilter.h"
#include "itkMultiThreaderBase.h"
#include "itkSampledGaussianSmoothing.h"

#include <cstdint>
#include <cstring>
#include <type_traits>

#include "itkMath.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <new>
#include <vector>

#if defined(__SSE2__)
#  include <emmintrin.h>
#endif

namespace itk
{
namespace ExternalForceImageFilterDetail
{
/** out[k] = static_cast<float>(std::sqrt(in[k])) for k < count, with SSE2
 * two at a time (the same values: sqrtpd and cvtpd2ps round as sqrtsd and
 * cvtsd2ss do). */
inline void
SquareRootsToFloat(const double * in, SizeValueType count, float * out)
{
  SizeValueType k = 0;
#if defined(__SSE2__)
  for (; k + 2 <= count; k += 2)
  {
    const __m128 roots = _mm_cvtpd_ps(_mm_sqrt_pd(_mm_loadu_pd(in + k)));
    _mm_storel_epi64(reinterpret_cast<__m128i *>(out + k), _mm_castps_si128(roots));
  }
#endif
  for (; k < count; ++k)
  {
    out[k] = static_cast<float>(std::sqrt(in[k]));
  }
}
} // namespace ExternalForceImageFilterDetail

template <typename TInputImage, typename TOutputImage>
void
ExternalForceImageFilter<TInputImage, TOutputImage>::VerifyPreconditions() const
{
  Superclass::VerifyPreconditions();
  if (!(m_Sigma >= 0.0 && std::isfinite(m_Sigma)))
  {
    itkExceptionMacro("Sigma must be finite and non-negative; it is " << m_Sigma << ".");
  }
  if (m_UseGradientVectorFlow &&
      !(m_GradientVectorFlowRegularization > 0.0 && std::isfinite(m_GradientVectorFlowRegularization)))
  {
    itkExceptionMacro("GradientVectorFlowRegularization must be positive and finite; it is "
                      << m_GradientVectorFlowRegularization << ".");
  }
}

template <typename TInputImage, typename TOutputImage>
void
ExternalForceImageFilter<TInputImage, TOutputImage>::GenerateInputRequestedRegion()
{
  auto * input = const_cast<InputImageType *>(this->GetInput());
  if (input != nullptr)
  {
    input->SetRequestedRegionToLargestPossibleRegion();
  }
}

template <typename TInputImage, typename TOutputImage>
void
ExternalForceImageFilter<TInputImage, TOutputImage>::EnlargeOutputRequestedRegion(DataObject * output)
{
  output->SetRequestedRegionToLargestPossibleRegion();
}

template <typename TInputImage, typename TOutputImage>
void
ExternalForceImageFilter<TInputImage, TOutputImage>::GenerateData()
{
  const InputImageType * input = this->GetInput();
  if (input->GetBufferedRegion().GetNumberOfPixels() == 0)
  {
    itkExceptionMacro("The input image has no pixel in its buffered region.");
  }
  double largestExtent = 0.0;
  for (unsigned int d = 0; d < ImageDimension; ++d)
  {
    if (input->GetLargestPossibleRegion().GetSize()[d] < 4)
    {
      itkExceptionMacro("The input image must have at least 4 pixels along each axis; its size is "
                        << input->GetLargestPossibleRegion().GetSize() << ".");
    }
    largestExtent = std::max(
      largestExtent, static_cast<double>(input->GetLargestPossibleRegion().GetSize()[d]) * input->GetSpacing()[d]);
  }
  // Beyond the image's extent the smoothed image is flat: no edge is left to
  // pull a mesh, and the kernel's size would be unbounded.
  if (!(m_Sigma <= largestExtent))
  {
    itkExceptionMacro("Sigma (" << m_Sigma << ") exceeds the largest physical extent of the input image ("
                                << largestExtent << "): the smoothed image would have no edge.");
  }
  const SizeValueType numberOfPixels = input->GetBufferedRegion().GetNumberOfPixels();
  try
  {
    this->ComputeForceField(input);
  }
  catch (const std::bad_alloc &)
  {
    // The float images of the smoothing, edge map and field, and the arrays
    // of the diffusion.
    const double bytesPerPixel = 3.0 * sizeof(float) + sizeof(OutputPixelType) +
                                 (m_UseGradientVectorFlow ? sizeof(float) + 3.0 * sizeof(OutputPixelType) : 0.0);
    itkExceptionMacro("Out of memory: the force field of an image of "
                      << numberOfPixels << " pixels needs about " << bytesPerPixel * numberOfPixels / 1e6 << " MB.");
  }
}

template <typename TInputImage, typename TOutputImage>
void
ExternalForceImageFilter<TInputImage, TOutputImage>::ComputeForceField(const InputImageType * input)
{
  typename RealImageType::Pointer smoothed = this->Smooth(input);
  this->UpdateProgress(0.3f);

  // Edge map |grad (G * I)|: the squared norms in double, their roots taken
  // two at a time (SquareRootsToFloat: the values of std::sqrt, whose errno
  // path keeps compilers from vectorising it).
  auto edgeMap = RealImageType::New();
  edgeMap->CopyInformation(smoothed);
  edgeMap->SetRegions(smoothed->GetBufferedRegion());
  edgeMap->Allocate();
  float *                 edges = edgeMap->GetBufferPointer();
  constexpr SizeValueType blockLength = CentralDifferenceBlockLength;
  this->ForEachCentralDifference(
    smoothed, [edges](SizeValueType, OffsetValueType first, SizeValueType count, const double * derivative) {
      double squared[blockLength];
      for (SizeValueType k = 0; k < count; ++k)
      {
        double squaredNorm = 0.0;
        for (unsigned int d = 0; d < ImageDimension; ++d)
        {
          const double g = derivative[d * blockLength + k];
          squaredNorm += g * g;
        }
        squared[k] = squaredNorm;
      }
      ExternalForceImageFilterDetail::SquareRootsToFloat(squared, count, edges + first);
    });
  smoothed = nullptr;

  if (m_UseGradientVectorFlow)
  {
    // A [0, 1] edge map makes the GVF weights independent of the intensity range.
    float *             e = edgeMap->GetBufferPointer();
    const SizeValueType n = edgeMap->GetBufferedRegion().GetNumberOfPixels();
    const float         largest = *std::max_element(e, e + n);
    if (largest > 0.0f)
    {
      std::transform(e, e + n, e, [largest](float v) { return v / largest; });
    }
  }

  // Force grad |grad (G * I)|, in physical axes when UseImageDirection is on.
  // Without the diffusion, the largest squared norm of the normalisation is
  // taken on the way, line by line (the same maximum: the order does not
  // change a maximum, and a NaN, as in std::max, is never taken).
  auto field = OutputImageType::New();
  field->CopyInformation(edgeMap);
  field->SetRegions(edgeMap->GetBufferedRegion());
  field->Allocate();
  OutputPixelType *   forces = field->GetBufferPointer();
  const bool          useDirection = this->GetUseImageDirection();
  const auto          direction = edgeMap->GetDirection();
  const bool          largestOnTheWay = m_NormalizeForces && !m_UseGradientVectorFlow;
  const SizeValueType numberOfLines =
    edgeMap->GetBufferedRegion().GetNumberOfPixels() / edgeMap->GetBufferedRegion().GetSize()[0];
  std::vector<double> lineLargest(largestOnTheWay ? numberOfLines : 0, 0.0);
  this->ForEachCentralDifference(
    edgeMap,
    [=, &lineLargest](SizeValueType line, OffsetValueType first, SizeValueType count, const double * derivative) {
      OutputPixelType * out = forces + first;
      for (SizeValueType k = 0; k < count; ++k)
      {
        for (unsigned int r = 0; r < ImageDimension; ++r)
        {
          double component = useDirection ? 0.0 : derivative[r * blockLength + k];
          if (useDirection)
          {
            for (unsigned int c = 0; c < ImageDimension; ++c)
            {
              component += direction(r, c) * derivative[c * blockLength + k];
            }
          }
          out[k][r] = static_cast<OutputValueType>(component);
        }
      }
      if (largestOnTheWay)
      {
        double largest = lineLargest[line];
        for (SizeValueType k = 0; k < count; ++k)
        {
          largest = std::max(largest, static_cast<double>(out[k].GetSquaredNorm()));
        }
        lineLargest[line] = largest;
      }
    });

  if (m_UseGradientVectorFlow)
  {
    this->DiffuseGradientVectorFlow(field);
  }

  OutputPixelType *   f = field->GetBufferPointer();
  const SizeValueType n = field->GetBufferedRegion().GetNumberOfPixels();
  using ComponentType = typename OutputPixelType::ValueType;
  // The largest magnitude of the components, as the largest of their IEEE
  // bits without the sign (infinities and NaNs above every finite value): a
  // loop without branches; the non-finite component is looked for only when
  // there is one. With the normalisation, in the same pass as the scaling.
  constexpr bool ieeeComponents = std::is_same_v<ComponentType, float> || std::is_same_v<ComponentType, double>;
  using Bits = std::conditional_t<std::is_same_v<ComponentType, double>, uint64_t, uint32_t>;
  constexpr Bits      magnitudeMask = ~(Bits{ 1 } << (8 * sizeof(Bits) - 1));
  Bits                largestBits = 0;
  ComponentType *     components = n > 0 ? f[0].GetDataPointer() : nullptr;
  const SizeValueType numberOfComponents = n * OutputPixelType::Dimension;
  const auto          scanComponents = [&]() {
    if constexpr (ieeeComponents)
    {
      for (SizeValueType i = 0; i < numberOfComponents; ++i)
      {
        Bits bits;
        std::memcpy(&bits, components + i, sizeof(bits));
        bits &= magnitudeMask;
        largestBits = bits > largestBits ? bits : largestBits;
      }
    }
  };
  bool scanned = false;
  if (m_NormalizeForces)
  {
    double largest = 0.0;
    if (largestOnTheWay)
    {
      for (const double value : lineLargest)
      {
        largest = std::max(largest, value);
      }
    }
    else
    {
      for (SizeValueType i = 0; i < n; ++i)
      {
        largest = std::max(largest, static_cast<double>(f[i].GetSquaredNorm()));
      }
    }
    if (largest > 0.0)
    {
      const auto scale = static_cast<OutputValueType>(1.0 / std::sqrt(largest));
      if constexpr (ieeeComponents)
      {
        for (SizeValueType i = 0; i < numberOfComponents; ++i)
        {
          const ComponentType scaled = components[i] * scale;
          components[i] = scaled;
          Bits bits;
          std::memcpy(&bits, &scaled, sizeof(bits));
          bits &= magnitudeMask;
          largestBits = bits > largestBits ? bits : largestBits;
        }
        scanned = true;
      }
      else
      {
        for (SizeValueType i = 0; i < n; ++i)
        {
          f[i] *= scale;
        }
      }
    }
  }
  else if (m_IntensityExponent != 0 && !m_UseGradientVectorFlow)
  {
    // Raw forces are linear in the intensities: undo the scaling of Smooth().
    for (SizeValueType i = 0; i < n; ++i)
    {
      for (unsigned int k = 0; k < OutputPixelType::Dimension; ++k)
      {
        f[i][k] = static_cast<OutputValueType>(std::ldexp(static_cast<double>(f[i][k]), m_IntensityExponent));
      }
    }
  }
  bool allFinite = false;
  if constexpr (ieeeComponents)
  {
    if (!scanned)
    {
      scanComponents();
    }
    ComponentType largestMagnitude;
    std::memcpy(&largestMagnitude, &largestBits, sizeof(largestMagnitude));
    allFinite = std::isfinite(largestMagnitude);
  }
  for (SizeValueType i = 0; i < n && !allFinite; ++i)
  {
    for (unsigned int k = 0; k < OutputPixelType::Dimension; ++k)
    {
      if (!std::isfinite(static_cast<double>(f[i][k])))
      {
        itkExceptionMacro("The force at index " << field->ComputeIndex(static_cast<OffsetValueType>(i))
                                                << " is not finite (" << f[i][k]
                                                << "): the raw forces exceed the range of the output pixel type; "
                                                   "turn NormalizeForces on.");
      }
    }
  }
  this->GraftOutput(field);
}

template <typename TInputImage, typename TOutputImage>
auto
ExternalForceImageFilter<TInputImage, TOutputImage>::Smooth(const InputImageType * input) ->
  typename RealImageType::Pointer
{
  const auto          region = input->GetBufferedRegion();
  const SizeValueType numberOfPixels = region.GetNumberOfPixels();
  auto                makeImage = [&]() {
    auto image = RealImageType::New();
    image->CopyInformation(input);
    image->SetRegions(region);
    image->Allocate();
    return image;
  };
  MultiThreaderBase * threader = this->GetMultiThreader();
  threader->SetNumberOfWorkUnits(this->GetNumberOfWorkUnits());
  constexpr SizeValueType chunk = 4096;
  const SizeValueType     numberOfChunks = (numberOfPixels + chunk - 1) / chunk;

  typename RealImageType::Pointer current;
  {
    // The largest |intensity| and the first non-finite pixel, chunk by chunk:
    // the largest magnitude without branches (a loop the compiler
    // vectorises), the non-finite pixel looked for only when the largest is
    // not finite (infinities and NaNs propagate through the comparisons
    // written so).
    const auto *        in = input->GetBufferPointer();
    std::vector<double> largest(numberOfChunks, 0.0);
    std::vector<double> firstNonFinite(numberOfChunks, -1.0);
    threader->ParallelizeArray(
      0,
      numberOfChunks,
      [&](SizeValueType c) {
        const SizeValueType end = std::min(numberOfPixels, (c + 1) * chunk);
        double              m = 0.0;
        using InputValueType = typename InputImageType::PixelType;
        if constexpr (std::is_same_v<InputValueType, float> || std::is_same_v<InputValueType, double>)
        {
          // The largest of the values' bits without the sign: for IEEE
          // numbers the order of their magnitudes, infinities and NaNs above
          // every finite value (an integer maximum, which vectorises).
          using Bits = std::conditional_t<std::is_same_v<InputValueType, float>, uint32_t, uint64_t>;
          constexpr Bits magnitudeMask = ~(Bits{ 1 } << (8 * sizeof(Bits) - 1));
          Bits           largestBits = 0;
          for (SizeValueType i = c * chunk; i < end; ++i)
          {
            Bits bits;
            std::memcpy(&bits, in + i, sizeof(bits));
            bits &= magnitudeMask;
            largestBits = bits > largestBits ? bits : largestBits;
          }
          InputValueType largestValue;
          std::memcpy(&largestValue, &largestBits, sizeof(largestValue));
          m = static_cast<double>(largestValue);
        }
        else
        {
          for (SizeValueType i = c * chunk; i < end; ++i)
          {
            const double v = std::abs(static_cast<double>(in[i]));
            m = v > m || v != v ? v : m;
          }
        }
        if (!(m <= std::numeric_limits<double>::max()))
        {
          for (SizeValueType i = c * chunk; i < end; ++i)
          {
            if (!(std::abs(static_cast<double>(in[i])) <= std::numeric_limits<double>::max()))
            {
              firstNonFinite[c] = static_cast<double>(i);
              break;
            }
          }
        }
        largest[c] = m;
      },
      nullptr);
    for (SizeValueType c = 0; c < numberOfChunks; ++c)
    {
      if (firstNonFinite[c] >= 0.0)
      {
        const auto offset = static_cast<OffsetValueType>(firstNonFinite[c]);
        itkExceptionMacro("The input image has a non-finite value (" << static_cast<double>(in[offset]) << ") at index "
                                                                     << input->ComputeIndex(offset) << ".");
      }
    }
    // Intensities far from 1 are scaled by a power of two (exact in floating
    // point) so that the squared derivatives neither overflow nor underflow in
    // float; the normalised field is the same, raw forces are scaled back.
    const double largestIntensity = *std::max_element(largest.begin(), largest.end());
    m_IntensityExponent = 0;
    if (largestIntensity > 0.0 && (largestIntensity > 0x1p40 || largestIntensity < 0x1p-40))
    {
      m_IntensityExponent = std::ilogb(largestIntensity);
    }
    const int exponent = m_IntensityExponent;
    if constexpr (std::is_same_v<InputImageType, RealImageType>)
    {
      // A float image neither scaled nor smoothed is its own smoothed image:
      // the force field only reads it (no copy).
      if (exponent == 0 && m_Sigma == 0.0)
      {
        return const_cast<RealImageType *>(input);
      }
    }
    current = makeImage();
    float * out = current->GetBufferPointer();
    threader->ParallelizeArray(
      0,
      numberOfChunks,
      [&](SizeValueType c) {
        const SizeValueType end = std::min(numberOfPixels, (c + 1) * chunk);
        if (exponent == 0)
        {
          for (SizeValueType i = c * chunk; i < end; ++i)
          {
            out[i] = static_cast<float>(static_cast<double>(in[i]));
          }
        }
        else
        {
          for (SizeValueType i = c * chunk; i < end; ++i)
          {
            out[i] = static_cast<float>(std::ldexp(static_cast<double>(in[i]), -exponent));
          }
        }
      },
      nullptr);
  }
  if (m_Sigma == 0.0)
  {
    return current;
  }

  typename RealImageType::Pointer other = makeImage();
  SmoothWithSampledGaussian<RealImageType>(current, other, m_Sigma, threader);
  return current;
}

template <typename TInputImage, typename TOutputImage>
OffsetValueType
ExternalForceImageFilter<TInputImage, TOutputImage>::LocateLine(SizeValueType           line,
                                                                const SizeType &        size,
                                                                const OffsetValueType * stride,
                                                                OffsetValueType *       lower,
                                                                OffsetValueType *       upper)
{
  OffsetValueType start = 0;
  for (unsigned int d = 1; d < ImageDimension; ++d)
  {
    const SizeValueType coordinate = line % size[d];
    line /= size[d];
    start += static_cast<OffsetValueType>(coordinate) * stride[d];
    lower[d] = coordinate > 0 ? -stride[d] : 0;
    upper[d] = coordinate + 1 < size[d] ? stride[d] : 0;
  }
  return start;
}

template <typename TInputImage, typename TOutputImage>
template <typename TFunction>
void
ExternalForceImageFilter<TInputImage, TOutputImage>::ForEachCentralDifference(const RealImageType * image,
                                                                              const TFunction &     function)
{
  const auto          region = image->GetBufferedRegion();
  const auto          size = region.GetSize();
  const float *       v = image->GetBufferPointer();
  const SizeValueType lineLength = size[0];
  const SizeValueType numberOfLines = region.GetNumberOfPixels() / lineLength;

  OffsetValueType stride[ImageDimension];
  double          scale[ImageDimension];
  stride[0] = 1;
  for (unsigned int d = 0; d < ImageDimension; ++d)
  {
    if (d > 0)
    {
      stride[d] = stride[d - 1] * static_cast<OffsetValueType>(size[d - 1]);
    }
    scale[d] = 0.5 / (this->GetUseImageSpacing() ? image->GetSpacing()[d] : 1.0);
  }

  MultiThreaderBase * threader = this->GetMultiThreader();
  threader->SetNumberOfWorkUnits(this->GetNumberOfWorkUnits());
  threader->ParallelizeArray(
    0,
    numberOfLines,
    [&](SizeValueType line) {
      // Zero-flux (Neumann) border, as GradientImageFilter's default.
      OffsetValueType         lower[ImageDimension];
      OffsetValueType         upper[ImageDimension];
      const OffsetValueType   lineStart = LocateLine(line, size, stride, lower, upper);
      constexpr SizeValueType blockLength = CentralDifferenceBlockLength;
      double                  derivative[ImageDimension * blockLength];
      for (SizeValueType x0 = 0; x0 < lineLength; x0 += blockLength)
      {
        const SizeValueType count = std::min(blockLength, lineLength - x0);
        const float *       p = v + lineStart + static_cast<OffsetValueType>(x0);
        // Along the line: the inner pixels in a loop of constant offsets,
        // then the line's ends (a missing neighbour is the pixel itself).
        const bool          firstBlock = x0 == 0;
        const bool          lastBlock = x0 + count == lineLength;
        const SizeValueType innerBegin = firstBlock ? 1 : 0;
        const SizeValueType innerEnd = lastBlock ? count - 1 : count;
        for (SizeValueType k = innerBegin; k < innerEnd; ++k)
        {
          derivative[k] = (static_cast<double>(p[k + 1]) - p[k - 1]) * scale[0];
        }
        if (firstBlock)
        {
          derivative[0] = (static_cast<double>(p[lineLength > 1 ? 1 : 0]) - p[0]) * scale[0];
        }
        if (lastBlock && lineLength > 1)
        {
          derivative[count - 1] = (static_cast<double>(p[count - 1]) - p[count - 2]) * scale[0];
        }
        for (unsigned int d = 1; d < ImageDimension; ++d)
        {
          const float * below = p + lower[d];
          const float * above = p + upper[d];
          double *      out = derivative + d * blockLength;
          const double  s = scale[d];
          for (SizeValueType k = 0; k < count; ++k)
          {
            out[k] = (static_cast<double>(above[k]) - below[k]) * s;
          }
        }
        function(line, lineStart + static_cast<OffsetValueType>(x0), count, static_cast<const double *>(derivative));
      }
    },
    nullptr);
}

template <typename TInputImage, typename TOutputImage>
void
ExternalForceImageFilter<TInputImage, TOutputImage>::DiffuseGradientVectorFlow(OutputImageType * field)
{
  constexpr unsigned int Components = OutputPixelType::Dimension;
  const auto             region = field->GetBufferedRegion();
  const auto             size = region.GetSize();
  const SizeValueType    numberOfPixels = region.GetNumberOfPixels();
  const SizeValueType    lineLength = size[0];
  const SizeValueType    numberOfLines = numberOfPixels / lineLength;

  OffsetValueType stride[ImageDimension];
  double          inverseSquaredSpacing[ImageDimension];
  double          sumInverseSquaredSpacing = 0.0;
  stride[0] = 1;
  for (unsigned int d = 0; d < ImageDimension; ++d)
  {
    if (d > 0)
    {
      stride[d] = stride[d - 1] * static_cast<OffsetValueType>(size[d - 1]);
    }
    const double h = this->GetUseImageSpacing() ? field->GetSpacing()[d] : 1.0;
    inverseSquaredSpacing[d] = 1.0 / (h * h);
    sumInverseSquaredSpacing += inverseSquaredSpacing[d];
  }

  // Data term: b = |grad e|^2 and c = b * grad e, from the initial field.
  const OutputPixelType *      f = field->GetBufferPointer();
  std::vector<float>           b(numberOfPixels);
  std::vector<OutputPixelType> c(numberOfPixels);
  float                        largestB = 0.0f;
  for (SizeValueType i = 0; i < numberOfPixels; ++i)
  {
    b[i] = static_cast<float>(f[i].GetSquaredNorm());
    c[i] = f[i] * static_cast<OutputValueType>(b[i]);
    largestB = std::max(largestB, b[i]);
  }

  // Forward Euler is stable for dt * (4 mu sum(1/h^2) + max b) <= 2.
  const double mu = m_GradientVectorFlowRegularization;
  const double timeStep = 0.9 * 2.0 / (4.0 * mu * sumInverseSquaredSpacing + largestB);

  std::vector<OutputPixelType> current(f, f + numberOfPixels);
  std::vector<OutputPixelType> next(numberOfPixels);
  MultiThreaderBase *          threader = this->GetMultiThreader();
  threader->SetNumberOfWorkUnits(this->GetNumberOfWorkUnits());

  for (unsigned int iteration = 0; iteration < m_GradientVectorFlowIterations; ++iteration)
  {
    const OutputPixelType * v = current.data();
    OutputPixelType *       w = next.data();
    threader->ParallelizeArray(
      0,
      numberOfLines,
      [&](SizeValueType line) {
        // Zero-flux (Neumann) boundary: a missing neighbour equals the centre.
        OffsetValueType       lower[ImageDimension];
        OffsetValueType       upper[ImageDimension];
        const OffsetValueType lineStart = LocateLine(line, size, stride, lower, upper);
        for (SizeValueType x = 0; x < lineLength; ++x)
        {
          const OffsetValueType   i = lineStart + static_cast<OffsetValueType>(x);
          const OutputPixelType & center = v[i];
          lower[0] = x > 0 ? -1 : 0;
          upper[0] = x + 1 < lineLength ? 1 : 0;
          double laplacian[Components] = {};
          for (unsigned int d = 0; d < ImageDimension; ++d)
          {
            const OutputPixelType & below = v[i + lower[d]];
            const OutputPixelType & above = v[i + upper[d]];
            for (unsigned int k = 0; k < Components; ++k)
            {
              laplacian[k] += (static_cast<double>(below[k]) + above[k] - 2.0 * center[k]) * inverseSquaredSpacing[d];
            }
          }
          for (unsigned int k = 0; k < Components; ++k)
          {
            w[i][k] =
              static_cast<OutputValueType>(center[k] + timeStep * (mu * laplacian[k] - b[i] * center[k] + c[i][k]));
          }
        }
      },
      nullptr);
    current.swap(next);
    // The diffusion is the last 70 % of the work, after the smoothing.
    this->UpdateProgress(0.3f + 0.7f * static_cast<float>(iteration + 1) / m_GradientVectorFlowIterations);
  }
  std::copy(current.begin(), current.end(), field->GetBufferPointer());
}

template <typename TInputImage, typename TOutputImage>
void
ExternalForceImageFilter<TInputImage, TOutputImage>::PrintSelf(std::ostream & os, Indent indent) const
{
  Superclass::PrintSelf(os, indent);
  os << indent << "Sigma: " << m_Sigma << std::endl;
  os << indent << "NormalizeForces: " << (m_NormalizeForces ? "On" : "Off") << std::endl;
  os << indent << "UseGradientVectorFlow: " << (m_UseGradientVectorFlow ? "On" : "Off") << std::endl;
  os << indent << "GradientVectorFlowRegularization: " << m_GradientVectorFlowRegularization << std::endl;
  os << indent << "GradientVectorFlowIterations: " << m_GradientVectorFlowIterations << std::endl;
  os << indent << "IntensityExponent: " << m_IntensityExponent << std::endl;
}

} // end namespace itk

#endif
