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
#ifndef itkDeformableMeshFilterImageTerms_hxx
#define itkDeformableMeshFilterImageTerms_hxx

// The image terms of DeformableMeshFilter (region force): their parameters'
// checks, the smoothed intensity image, the object's intensity model and the
// per-vertex outward speeds the step adds along the normals. Included by
// itkDeformableMeshFilter.hxx.

#include "itkSampledGaussianSmoothing.h"

#include <cstdint>
#include <cstring>

namespace itk
{

template <typename TMesh, typename TForceImage>
void
DeformableMeshFilter<TMesh, TForceImage>::VerifyImageTermParameters() const
{
  if (!(m_RegionWeight >= 0.0 && std::isfinite(m_RegionWeight)))
  {
    itkExceptionMacro("RegionWeight must be finite and non-negative; it is " << m_RegionWeight << ".");
  }
  if (!(m_RegionSigma >= 0.0 && std::isfinite(m_RegionSigma)))
  {
    itkExceptionMacro("RegionSigma must be finite and non-negative; it is " << m_RegionSigma << ".");
  }
  if (!(m_IntensityTolerance > 0.0 && std::isfinite(m_IntensityTolerance)))
  {
    itkExceptionMacro("IntensityTolerance must be finite and positive; it is " << m_IntensityTolerance << ".");
  }
  if (m_BackgroundUpdateInterval < 1)
  {
    itkExceptionMacro("BackgroundUpdateInterval must be at least 1; it is " << m_BackgroundUpdateInterval << ".");
  }
  if (!m_EstimateObjectIntensityRange && m_ObjectIntensityStatisticsGiven &&
      !(std::isfinite(m_ObjectIntensityMedian) && std::isfinite(m_ObjectIntensitySpread) &&
        m_ObjectIntensitySpread >= 0.0))
  {
    itkExceptionMacro("The object intensity statistics must be finite with a non-negative spread; they are median "
                      << m_ObjectIntensityMedian << ", spread " << m_ObjectIntensitySpread << ".");
  }
  if (!m_EstimateObjectIntensityRange && !m_ObjectIntensityStatisticsGiven &&
      !(std::isfinite(m_ObjectIntensityLower) && std::isfinite(m_ObjectIntensityUpper) &&
        m_ObjectIntensityLower <= m_ObjectIntensityUpper && m_ObjectIntensityWidth > 0.0 &&
        std::isfinite(m_ObjectIntensityWidth)))
  {
    itkExceptionMacro("The object intensity range must be finite with lower <= upper and a positive width; it is ["
                      << m_ObjectIntensityLower << ", " << m_ObjectIntensityUpper << "], width "
                      << m_ObjectIntensityWidth << ".");
  }
  if (!(m_EdgeSearchWeight >= 0.0 && std::isfinite(m_EdgeSearchWeight)))
  {
    itkExceptionMacro("EdgeSearchWeight must be finite and non-negative; it is " << m_EdgeSearchWeight << ".");
  }
  if (!(m_EdgeSearchDistance > 0.0 && std::isfinite(m_EdgeSearchDistance)))
  {
    itkExceptionMacro("EdgeSearchDistance must be finite and positive; it is " << m_EdgeSearchDistance << ".");
  }
  if (m_EdgeSearchWeight > 0.0 && this->GetIntensityImage() == nullptr)
  {
    itkExceptionMacro("EdgeSearchWeight is " << m_EdgeSearchWeight
                                             << " but there is no intensity image: call SetIntensityImage().");
  }
  if (m_RegionWeight > 0.0 && this->GetIntensityImage() == nullptr)
  {
    itkExceptionMacro("RegionWeight is " << m_RegionWeight
                                         << " but there is no intensity image: call SetIntensityImage().");
  }
}

template <typename TMesh, typename TForceImage>
void
DeformableMeshFilter<TMesh, TForceImage>::PrepareImageTerms()
{
  const IntensityImageType * image = this->GetIntensityImage();
  if (image->GetBufferedRegion().GetNumberOfPixels() == 0 || image->GetBufferPointer() == nullptr)
  {
    itkExceptionMacro("The intensity image has no buffered region (no pixel in memory): allocate it or update the "
                      "filter that produces it.");
  }
  if (m_SmoothedIntensity.IsNull() || m_SmoothedIntensitySource != image ||
      m_SmoothedIntensityTime != image->GetMTime() || m_SmoothedIntensitySigma != m_RegionSigma)
  {
    // Finite values only; intensities whose magnitude is outside 2^+-40 are
    // scaled by a power of two (exact) so that the smoothing and the
    // statistics neither overflow nor lose their precision in float.
    const float * buffer = image->GetBufferPointer();
    const size_t  count = image->GetBufferedRegion().GetNumberOfPixels();
    // The largest magnitude, as the largest of the values' bits without the
    // sign: for IEEE floats that order is the order of the magnitudes, with
    // the infinities and NaNs above every finite value. An integer maximum
    // without branches, which the compiler vectorises (a float comparison
    // that must see NaNs is not); a non-finite value is then looked for.
    uint32_t largestBits = 0;
    for (size_t i = 0; i < count; ++i)
    {
      uint32_t bits;
      std::memcpy(&bits, buffer + i, sizeof(bits));
      bits &= 0x7fffffffu;
      largestBits = bits > largestBits ? bits : largestBits;
    }
    float largest;
    std::memcpy(&largest, &largestBits, sizeof(largest));
    if (!std::isfinite(largest))
    {
      for (size_t i = 0; i < count; ++i)
      {
        if (!std::isfinite(buffer[i]))
        {
          itkExceptionMacro("The intensity image holds a non-finite value (" << buffer[i] << ") at offset " << i
                                                                             << " of its buffer.");
        }
      }
    }
    m_IntensityScale = 1.0;
    if (largest > 0.0f && (largest > std::ldexp(1.0f, 40) || largest < std::ldexp(1.0f, -40)))
    {
      m_IntensityScale = std::ldexp(1.0, -std::ilogb(largest));
    }
    // The image the samplers read: the intensity image itself in 3-D, the
    // slice z = 0 of a 3-D image for a 2-D one (spacing 1 and direction
    // identity along z: the samplers read it bilinearly at (x, y, 0)).
    const auto                                         region = image->GetBufferedRegion();
    typename SmoothedIntensityImageType::RegionType    region3;
    typename SmoothedIntensityImageType::PointType     origin3;
    typename SmoothedIntensityImageType::SpacingType   spacing3;
    typename SmoothedIntensityImageType::DirectionType direction3;
    direction3.SetIdentity();
    for (unsigned int r = 0; r < 3; ++r)
    {
      region3.SetIndex(r, r < PointDimension ? region.GetIndex()[r] : 0);
      region3.SetSize(r, r < PointDimension ? region.GetSize()[r] : 1);
      origin3[r] = r < PointDimension ? image->GetOrigin()[r] : 0.0;
      spacing3[r] = r < PointDimension ? image->GetSpacing()[r] : 1.0;
      for (unsigned int c = 0; c < PointDimension && r < PointDimension; ++c)
      {
        direction3(r, c) = image->GetDirection()(r, c);
      }
    }
    const auto makeTarget = [&]() {
      auto made = SmoothedIntensityImageType::New();
      made->SetRegions(region3);
      made->SetOrigin(origin3);
      made->SetSpacing(spacing3);
      made->SetDirection(direction3);
      made->Allocate();
      return made;
    };
    // The intensities (scaled) smoothed with the Gaussian of
    // ExternalForceImageFilter (itkSampledGaussianSmoothing.h), in the
    // image's own dimension; in double for the scaling: 2^133 (the scale of
    // a denormal maximum) is no float. Without smoothing they go straight
    // into the samplers' image.
    const auto copyScaled = [&](float * out) {
      if (m_IntensityScale != 1.0)
      {
        for (size_t i = 0; i < count; ++i)
        {
          out[i] = static_cast<float>(static_cast<double>(buffer[i]) * m_IntensityScale);
        }
      }
      else
      {
        std::copy(buffer, buffer + count, out);
      }
    };
    if (m_RegionSigma > 0.0)
    {
      const auto makeImage = [&]() {
        typename IntensityImageType::Pointer made = IntensityImageType::New();
        made->CopyInformation(image);
        made->SetRegions(region);
        made->Allocate();
        return made;
      };
      typename IntensityImageType::Pointer smoothed = makeImage();
      typename IntensityImageType::Pointer scratch = makeImage();
      copyScaled(smoothed->GetBufferPointer());
      MultiThreaderBase * threader = this->GetMultiThreader();
      threader->SetNumberOfWorkUnits(this->GetNumberOfWorkUnits());
      SmoothWithSampledGaussian<IntensityImageType>(smoothed, scratch, m_RegionSigma, threader);
      if constexpr (PointDimension == 3)
      {
        m_SmoothedIntensity = smoothed;
      }
      else
      {
        m_SmoothedIntensity = makeTarget();
        std::copy(
          smoothed->GetBufferPointer(), smoothed->GetBufferPointer() + count, m_SmoothedIntensity->GetBufferPointer());
      }
    }
    else
    {
      m_SmoothedIntensity = makeTarget();
      copyScaled(m_SmoothedIntensity->GetBufferPointer());
    }
    m_SmoothedIntensitySource = image;
    m_SmoothedIntensityTime = image->GetMTime();
    m_SmoothedIntensitySigma = m_RegionSigma;
    const std::vector<double> quantiles = RegionForceType::Quantiles(m_SmoothedIntensity, { 0.02, 0.98 });
    m_IntensityQuantiles[0] = quantiles[0];
    m_IntensityQuantiles[1] = quantiles[1];
    m_IntensityGradientQuantile = RegionForceType::GradientQuantile(m_SmoothedIntensity, 0.99);
    // The sampler's physical-to-index transform (a matrix inverse) with it:
    // the continuations of a run (one more step per update) keep both.
    m_IntensitySampler.SetImage(m_SmoothedIntensity);
  }
  const auto & spacing = image->GetSpacing();
  m_BackgroundStep = spacing[0];
  for (unsigned int d = 1; d < PointDimension; ++d)
  {
    m_BackgroundStep = std::min(m_BackgroundStep, spacing[d]);
  }
}

template <typename TMesh, typename TForceImage>
void
DeformableMeshFilter<TMesh, TForceImage>::EstimateImageTermModel()
{
  using namespace DeformableMeshFilterDetail;
  if (m_EstimateObjectIntensityRange)
  {
    const std::vector<double> samples =
      RegionForce::SampleInterior(m_IntensitySampler, this->GetCoordinates().data(), this->GetNumberOfCachedPoints());
    double median = 0.0;
    double spread = 0.0;
    if (!RegionForce::Statistics(samples, median, spread))
    {
      itkExceptionMacro("Cannot estimate the object's intensity range: "
                        << (samples.empty() ? "the interior of the initial surface lies outside the intensity image"
                                            : "the intensities inside the initial surface are not finite")
                        << "; give the range with SetObjectIntensityRange().");
    }
    // Reported in the image's units; the model works on the scaled ones.
    m_ObjectIntensityMedian = median / m_IntensityScale;
    m_ObjectIntensitySpread = spread / m_IntensityScale;
  }
  // Stability of the region term: its speed changes by at most RegionWeight
  // over the transition width; on an edge of the image's 99th percentile of
  // gradient that is at most one step's worth of intensity.
  m_RegionForce.SetMinimumWidth(m_RegionWeight * m_IntensityGradientQuantile);
  if (m_EstimateObjectIntensityRange || m_ObjectIntensityStatisticsGiven)
  {
    if (!m_RegionForce.SetModel(m_ObjectIntensityMedian * m_IntensityScale,
                                m_ObjectIntensitySpread * m_IntensityScale,
                                m_IntensityTolerance,
                                m_IntensityQuantiles[0],
                                m_IntensityQuantiles[1]))
    {
      itkExceptionMacro("The object's intensity model (median " << m_ObjectIntensityMedian << ", spread "
                                                                << m_ObjectIntensitySpread
                                                                << ") gives no finite intensity range.");
    }
    this->StoreObjectIntensityRange();
  }
  else
  {
    m_RegionForce.SetRange(m_ObjectIntensityLower * m_IntensityScale,
                           m_ObjectIntensityUpper * m_IntensityScale,
                           m_ObjectIntensityWidth * m_IntensityScale);
  }
}

template <typename TMesh, typename TForceImage>
void
DeformableMeshFilter<TMesh, TForceImage>::StoreObjectIntensityRange()
{
  m_ObjectIntensityLower = m_RegionForce.GetLower() / m_IntensityScale;
  m_ObjectIntensityUpper = m_RegionForce.GetUpper() / m_IntensityScale;
  m_ObjectIntensityWidth = m_RegionForce.GetWidth() / m_IntensityScale;
}

template <typename TMesh, typename TForceImage>
void
DeformableMeshFilter<TMesh, TForceImage>::EstimateBackground()
{
  // Samples 1 to 4 voxels outside each vertex along its outward unit normal
  // (stored by the geometry pass), in vertex order: the estimate does not
  // depend on the number of threads.
  const SizeValueType numberOfPoints = this->GetNumberOfCachedPoints();
  const double *      x = this->GetCoordinates().data();
  const float *       normals = m_Normals.data();
  std::vector<double> samples;
  samples.reserve(4 * numberOfPoints);
  for (SizeValueType i = 0; i < numberOfPoints; ++i)
  {
    for (unsigned int step = 1; step <= 4; ++step)
    {
      const double distance = step * m_BackgroundStep;
      double       p[3];
      for (unsigned int k = 0; k < 3; ++k)
      {
        p[k] = x[3 * i + k] + distance * static_cast<double>(normals[4 * i + k]);
      }
      const double value = m_IntensitySampler.Sample(p);
      if (std::isfinite(value))
      {
        samples.push_back(value);
      }
    }
  }
  m_RegionForce.AdaptToBackground(samples);
  this->StoreObjectIntensityRange();
}

template <typename TMesh, typename TForceImage>
void
DeformableMeshFilter<TMesh, TForceImage>::UpdateNormalSpeeds()
{
  const SizeValueType numberOfPoints = this->GetNumberOfCachedPoints();
  if (m_NormalSpeeds.size() != numberOfPoints)
  {
    m_NormalSpeeds.assign(numberOfPoints, 0.0f);
  }
  if (m_EstimateBackgroundIntensity && (m_EstimateObjectIntensityRange || m_ObjectIntensityStatisticsGiven) &&
      this->GetCurrentIteration() % m_BackgroundUpdateInterval == 0 && m_Normals.size() == 4 * numberOfPoints)
  {
    this->EstimateBackground();
  }
  const double *          x = this->GetCoordinates().data();
  float *                 speeds = m_NormalSpeeds.data();
  const double            weight = m_RegionWeight;
  constexpr SizeValueType blockSize = 4096;
  const SizeValueType     numberOfBlocks = (numberOfPoints + blockSize - 1) / blockSize;
  this->GetMultiThreader()->ParallelizeArray(
    0,
    numberOfBlocks,
    [this, x, speeds, weight, numberOfPoints](SizeValueType block) {
      const SizeValueType end = std::min(numberOfPoints, (block + 1) * blockSize);
      for (SizeValueType i = block * blockSize; i < end; ++i)
      {
        speeds[i] =
          weight > 0.0 ? static_cast<float>(weight * m_RegionForce.Speed(m_IntensitySampler.Sample(x + 3 * i))) : 0.0f;
      }
    },
    nullptr);
  if (m_EdgeSearchWeight > 0.0 && m_Normals.size() == 4 * numberOfPoints)
  {
    this->AddEdgeSearchSpeeds();
  }
  else
  {
    m_NumberOfEdgeHits = 0;
  }
}

template <typename TMesh, typename TForceImage>
void
DeformableMeshFilter<TMesh, TForceImage>::AddEdgeSearchSpeeds()
{
  using DeformableMeshFilterDetail::EdgeSearch;
  const SizeValueType numberOfPoints = this->GetNumberOfCachedPoints();
  const double *      x = this->GetCoordinates().data();
  const float *       normals = m_Normals.data();
  float *             speeds = m_NormalSpeeds.data();
  m_EdgeHits.resize(numberOfPoints);
  float * hits = m_EdgeHits.data();

  int polarity = m_EdgePolarity;
  if (polarity == 0)
  {
    if (m_EstimateObjectIntensityRange || m_ObjectIntensityStatisticsGiven)
    {
      polarity = m_RegionForce.Polarity(m_IntensityQuantiles[0], m_IntensityQuantiles[1]);
    }
    else
    {
      const double middle = 0.5 * (m_RegionForce.GetLower() + m_RegionForce.GetUpper());
      polarity = middle - m_IntensityQuantiles[0] >= m_IntensityQuantiles[1] - middle ? 1 : -1;
    }
  }
  // An edge must drop by at least the object's robust standard deviation
  // (the transition width for a given range): noise inside the object does
  // not make one. And by at least 1 % of the image's intensity range: the
  // object of a noise-free image has no spread, and the ripples of the
  // smoothing (a millionth of the range) inside it are no edges.
  const double contrast = std::max((m_EstimateObjectIntensityRange || m_ObjectIntensityStatisticsGiven)
                                     ? m_ObjectIntensitySpread * m_IntensityScale
                                     : m_RegionForce.GetWidth(),
                                   0.01 * (m_IntensityQuantiles[1] - m_IntensityQuantiles[0]));
  EdgeSearch search;
  search.Configure(m_EdgeSearchDistance, 0.5 * m_BackgroundStep, m_BackgroundStep, polarity, contrast);

  constexpr SizeValueType blockSize = 4096;
  const SizeValueType     numberOfBlocks = (numberOfPoints + blockSize - 1) / blockSize;
  MultiThreaderBase *     threader = this->GetMultiThreader();
  threader->ParallelizeArray(
    0,
    numberOfBlocks,
    [&](SizeValueType block) {
      const SizeValueType end = std::min(numberOfPoints, (block + 1) * blockSize);
      for (SizeValueType i = block * blockSize; i < end; ++i)
      {
        hits[i] = static_cast<float>(search.Find(m_IntensitySampler, x + 3 * i, normals + 4 * i));
      }
    },
    nullptr);

  // The median of the vertex's and its neighbours' hits, when more than half
  // of them found an edge: a single vertex's hit on noise or on a
  // neighbouring structure does not move it.
  const double          weight = m_EdgeSearchWeight;
  const double          inverseVoxel = 1.0 / m_BackgroundStep;
  std::vector<uint32_t> blockHits(numberOfBlocks, 0);
  threader->ParallelizeArray(
    0,
    numberOfBlocks,
    [&](SizeValueType block) {
      constexpr unsigned int capacity = 32;
      float                  values[capacity];
      uint32_t               count = 0;
      const SizeValueType    end = std::min(numberOfPoints, (block + 1) * blockSize);
      for (SizeValueType i = block * blockSize; i < end; ++i)
      {
        unsigned int found = 0;
        unsigned int total = 1;
        if (std::isfinite(hits[i]))
        {
          values[found++] = hits[i];
        }
        for (IndexType32 k = m_NeighbourOffsets[i]; k < m_NeighbourOffsets[i + 1] && total < capacity; ++k, ++total)
        {
          const float hit = hits[m_Neighbours[k]];
          if (std::isfinite(hit))
          {
            values[found++] = hit;
          }
        }
        if (2 * found <= total)
        {
          continue;
        }
        std::nth_element(values, values + found / 2, values + found);
        const double distance = values[found / 2];
        speeds[i] += static_cast<float>(weight * std::max(-1.0, std::min(1.0, distance * inverseVoxel)));
        ++count;
      }
      blockHits[block] = count;
    },
    nullptr);
  m_NumberOfEdgeHits = 0;
  for (const uint32_t count : blockHits)
  {
    m_NumberOfEdgeHits += count;
  }
}

} // end namespace itk

#endif
