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
#ifndef itkSampledGaussianSmoothing_h
#define itkSampledGaussianSmoothing_h

// The Gaussian smoothing of the module's image terms: ExternalForceImageFilter
// smooths the image of the force field with it, DeformableMeshFilter the
// intensity image of its region force and edge search. One implementation,
// so that both see the same smoothing for the same sigma.

#include "itkMath.h"
#include "itkMultiThreaderBase.h"

#include <algorithm>
#include <cmath>
#include <vector>

namespace itk
{

/** Sum of exp(-k^2 / (2 sigma^2)) for the integers k from \a first to
 * \a last: the taps of the Gaussian folded onto the border pixels. */
inline double
SampledGaussianTailSum(double first, double last, double sigma)
{
  if (!(first <= last))
  {
    return 0.0;
  }
  const auto gaussian = [sigma](double k) { return std::exp(-0.5 * (k / sigma) * (k / sigma)); };
  if (last - first < 1e6)
  {
    double sum = 0.0;
    for (double k = first; k <= last; k += 1.0)
    {
      sum += gaussian(k);
    }
    return sum;
  }
  // Euler-Maclaurin: the integral plus half the end terms; with sigma above
  // 1e5 pixels the neglected terms are far below float precision.
  const double scale = 1.0 / (sigma * std::sqrt(2.0));
  return sigma * std::sqrt(0.5 * Math::pi) * (std::erf(last * scale) - std::erf(first * scale)) +
         0.5 * (gaussian(first) + gaussian(last));
}

/** Smooths the float image \a current by a Gaussian of standard deviation
 * \a sigmaInPhysicalUnits along each axis (its spacing honoured): separable,
 * sampled and truncated at 4 sigma, normalised to a unit sum, border pixels
 * repeated (zero flux), threaded over lines and rows of pixels by
 * \a threader. \a other is a scratch image of the same buffered region;
 * on return \a current holds the result (the two pointers may have been
 * swapped). A sigma of 0 leaves the image as it is. */
template <typename TImage>
void
SmoothWithSampledGaussian(typename TImage::Pointer & current,
                          typename TImage::Pointer & other,
                          double                     sigmaInPhysicalUnits,
                          MultiThreaderBase *        threader)
{
  const auto          size = current->GetBufferedRegion().GetSize();
  const SizeValueType numberOfPixels = current->GetBufferedRegion().GetNumberOfPixels();
  // One axis after the other: the image seen as [outer][n][inner], inner the
  // pixels of the lower axes (contiguous), n the pixels along the axis.
  SizeValueType inner = 1;
  for (unsigned int d = 0; d < TImage::ImageDimension; ++d)
  {
    const SizeValueType n = size[d];
    const SizeValueType outer = numberOfPixels / (inner * n);
    const double        sigma = sigmaInPhysicalUnits / current->GetSpacing()[d]; // pixels
    if (n == 1 || !(sigma > 0.0))
    {
      inner *= n;
      continue;
    }
    // Sampled Gaussian truncated at 4 sigma, normalised to a unit sum. Taps
    // at n pixels or more fall beyond both ends of every line, where the
    // border pixels repeat: they are folded into one tail weight applied to
    // the two end pixels, so that the cost stays within n taps.
    const double        fullRadius = std::ceil(4.0 * sigma);
    const SizeValueType radius = fullRadius < static_cast<double>(n) ? static_cast<SizeValueType>(fullRadius) : n - 1;
    std::vector<float>  weights(radius + 1);
    double              sum = 0.0;
    for (SizeValueType k = 0; k <= radius; ++k)
    {
      const double w = std::exp(-0.5 * static_cast<double>(k) * static_cast<double>(k) / (sigma * sigma));
      weights[k] = static_cast<float>(w);
      sum += k == 0 ? w : 2.0 * w;
    }
    const double tailSum = SampledGaussianTailSum(static_cast<double>(radius) + 1.0, fullRadius, sigma);
    sum += 2.0 * tailSum;
    for (float & w : weights)
    {
      w = static_cast<float>(w / sum);
    }
    const auto    tail = static_cast<float>(tailSum / sum);
    const float * src = current->GetBufferPointer();
    float *       dst = other->GetBufferPointer();
    // Border pixels repeated beyond the image (zero flux).
    auto clamped = [n](SizeValueType p, SizeValueType k, bool up) -> SizeValueType {
      return up ? std::min(p + k, n - 1) : (p >= k ? p - k : 0);
    };
    if (inner == 1)
    {
      threader->ParallelizeArray(
        0,
        outer,
        [&](SizeValueType line) {
          const float * in = src + line * n;
          float *       out = dst + line * n;
          // Interior [first, last): no clamping, vectorisable loops.
          const SizeValueType first = n > 2 * radius ? radius : n;
          const SizeValueType last = n > 2 * radius ? n - radius : n;
          auto                border = [&](SizeValueType p) {
            float value = weights[0] * in[p];
            for (SizeValueType k = 1; k <= radius; ++k)
            {
              value += weights[k] * (in[clamped(p, k, false)] + in[clamped(p, k, true)]);
            }
            if (tail > 0.0f)
            {
              value += tail * (in[0] + in[n - 1]);
            }
            out[p] = value;
          };
          for (SizeValueType p = 0; p < first; ++p)
          {
            border(p);
          }
          for (SizeValueType p = last; p < n; ++p)
          {
            border(p);
          }
          for (SizeValueType p = first; p < last; ++p)
          {
            out[p] = weights[0] * in[p];
          }
          for (SizeValueType k = 1; k <= radius; ++k)
          {
            const float w = weights[k];
            for (SizeValueType p = first; p < last; ++p)
            {
              out[p] += w * (in[p - k] + in[p + k]);
            }
          }
        },
        nullptr);
    }
    else
    {
      threader->ParallelizeArray(
        0,
        outer * n,
        [&](SizeValueType row) {
          const SizeValueType o = row / n;
          const SizeValueType p = row % n;
          const float *       base = src + o * n * inner;
          float *             out = dst + row * inner;
          const float *       centre = base + p * inner;
          const float         w0 = weights[0];
          for (SizeValueType i = 0; i < inner; ++i)
          {
            out[i] = w0 * centre[i];
          }
          for (SizeValueType k = 1; k <= radius; ++k)
          {
            const float * below = base + clamped(p, k, false) * inner;
            const float * above = base + clamped(p, k, true) * inner;
            const float   w = weights[k];
            for (SizeValueType i = 0; i < inner; ++i)
            {
              out[i] += w * (below[i] + above[i]);
            }
          }
          if (tail > 0.0f)
          {
            const float * first = base;
            const float * last = base + (n - 1) * inner;
            for (SizeValueType i = 0; i < inner; ++i)
            {
              out[i] += tail * (first[i] + last[i]);
            }
          }
        },
        nullptr);
    }
    std::swap(current, other);
    inner *= n;
  }
}

} // end namespace itk

#endif
