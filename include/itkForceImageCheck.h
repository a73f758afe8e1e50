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
#ifndef itkForceImageCheck_h
#define itkForceImageCheck_h

#include "itkMacro.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <sstream>
#include <type_traits>

namespace itk
{

/** \class ForceImageCheck
 * \brief Checks the force image of a deformable model before it moves a
 * vertex: every value finite, and the largest step a vertex can take in one
 * iteration within the image.
 *
 * A NaN or infinite force, or a step of 1e200 mm, turns the whole mesh into
 * NaN within an iteration or two; the check makes it an ExceptionObject with
 * a message naming the cause instead. The scan of the image (its values and
 * largest vector length) is kept until the image or its buffer changes, so an
 * update that runs one more iteration (animation) does not pay for it again.
 *
 * \sa DeformableMeshFilter
 * \ingroup ExplicitDeformableModel
 */
template <typename TForceImage>
class ForceImageCheck
{
public:
  using ForceImageType = TForceImage;
  static constexpr unsigned int ImageDimension = ForceImageType::ImageDimension;

  /** Throws an ExceptionObject when the force image holds a non-finite value,
   * or when the largest step of one iteration, |scaleFactor| times the
   * largest force plus \a otherSpeeds (balloon and image terms, physical
   * units per iteration), bounded by \a maximumStepLength when positive,
   * exceeds the physical diagonal of the force image. */
  void
  Verify(const ForceImageType * image, double scaleFactor, double otherSpeeds, double maximumStepLength)
  {
    this->Scan(image);
    if (m_NonFinite)
    {
      std::ostringstream message;
      message << "The force image has a non-finite value (" << m_NonFiniteValue << ") at index " << m_NonFiniteIndex
              << ": the mesh would become NaN. Check the image the forces were computed from.";
      throw ExceptionObject(__FILE__, __LINE__, message.str(), ITK_LOCATION);
    }
    double step = std::abs(scaleFactor) * m_LargestForce + std::abs(otherSpeeds);
    if (maximumStepLength > 0.0)
    {
      step = std::min(step, maximumStepLength);
    }
    if (!(step <= m_Diagonal))
    {
      std::ostringstream message;
      message << "A vertex could move by up to " << step << " (ScaleFactor " << scaleFactor
              << " times the largest force " << m_LargestForce << ", plus " << std::abs(otherSpeeds)
              << " of balloon and image terms) in one iteration, more than the diagonal of the force image ("
              << m_Diagonal
              << "): the mesh would leave the image at the first step. Reduce ScaleFactor or Balloon, or bound the "
                 "step with MaximumStepLength.";
      throw ExceptionObject(__FILE__, __LINE__, message.str(), ITK_LOCATION);
    }
  }

  /** Largest vector length of the last image scanned. */
  double
  GetLargestForce() const
  {
    return m_LargestForce;
  }

private:
  void
  Scan(const ForceImageType * image)
  {
    const auto region = image->GetBufferedRegion();
    if (image == m_Image && image->GetBufferPointer() == m_Buffer && image->GetMTime() == m_Time &&
        image->GetPixelContainer()->GetMTime() == m_BufferTime && region == m_Region)
    {
      return;
    }
    m_Image = image;
    m_Buffer = image->GetBufferPointer();
    m_Time = image->GetMTime();
    m_BufferTime = image->GetPixelContainer()->GetMTime();
    m_Region = region;
    m_NonFinite = false;
    m_LargestForce = 0.0;

    const auto *        pixels = image->GetBufferPointer();
    const SizeValueType n = region.GetNumberOfPixels();
    using ComponentType = typename ForceImageType::PixelType::ValueType;
    constexpr unsigned int components = ForceImageType::PixelType::Dimension;
    if constexpr (std::is_same_v<ComponentType, float> &&
                  sizeof(typename ForceImageType::PixelType) == components * sizeof(float))
    {
      // Float vectors: squared lengths in float, their largest as the
      // largest of their bits (non-negative floats order as their bits,
      // infinities and NaNs above every finite value): integer maxima, a
      // loop the compiler vectorises. Only the check's bound needs the
      // length (float precision is plenty); a squared length that is not
      // finite (a non-finite component, or an overflow of float) is left to
      // the exact scan below.
      const float * c = n > 0 ? pixels[0].GetDataPointer() : nullptr;
      uint32_t      largestBits = 0;
      for (SizeValueType i = 0; i < n; ++i)
      {
        float squared = 0.0f;
        for (unsigned int k = 0; k < components; ++k)
        {
          squared += c[components * i + k] * c[components * i + k];
        }
        uint32_t bits;
        std::memcpy(&bits, &squared, sizeof(bits));
        largestBits = bits > largestBits ? bits : largestBits;
      }
      float largestSquared;
      std::memcpy(&largestSquared, &largestBits, sizeof(largestSquared));
      if (std::isfinite(largestSquared))
      {
        m_LargestForce = std::sqrt(static_cast<double>(largestSquared));
        m_Diagonal = PhysicalDiagonal(image);
        return;
      }
    }
    // The largest squared length, without branches: four running maxima
    // (a maximum of non-negative numbers does not depend on their order) of
    // squared lengths whose NaN or infinity, from a non-finite component,
    // propagates; only then is the first such pixel looked for.
    double largest[4] = { 0.0, 0.0, 0.0, 0.0 };
    for (SizeValueType i = 0; i < n; ++i)
    {
      double squared = 0.0;
      for (unsigned int k = 0; k < ForceImageType::PixelType::Dimension; ++k)
      {
        const double v = static_cast<double>(pixels[i][k]);
        squared += v * v;
      }
      double & m = largest[i & 3];
      m = squared > m || squared != squared ? squared : m;
    }
    double largestSquared = 0.0;
    for (const double m : largest)
    {
      largestSquared = m > largestSquared || m != m ? m : largestSquared;
    }
    if (std::isfinite(largestSquared))
    {
      m_LargestForce = std::sqrt(largestSquared);
      m_Diagonal = PhysicalDiagonal(image);
      return;
    }
    largestSquared = 0.0;
    for (SizeValueType i = 0; i < n && !m_NonFinite; ++i)
    {
      double squared = 0.0;
      for (unsigned int k = 0; k < ForceImageType::PixelType::Dimension; ++k)
      {
        const double v = static_cast<double>(pixels[i][k]);
        if (!std::isfinite(v))
        {
          m_NonFinite = true;
          m_NonFiniteValue = v;
          m_NonFiniteIndex = image->ComputeIndex(static_cast<OffsetValueType>(i));
        }
        squared += v * v;
      }
      largestSquared = std::max(largestSquared, squared);
    }
    m_LargestForce = std::sqrt(largestSquared);
    m_Diagonal = PhysicalDiagonal(image);
  }

  /** The physical diagonal of the image's voxels. */
  static double
  PhysicalDiagonal(const ForceImageType * image)
  {
    double squaredDiagonal = 0.0;
    for (unsigned int d = 0; d < ImageDimension; ++d)
    {
      const double extent =
        static_cast<double>(image->GetLargestPossibleRegion().GetSize()[d]) * image->GetSpacing()[d];
      squaredDiagonal += extent * extent;
    }
    return std::sqrt(squaredDiagonal);
  }

  const ForceImageType *              m_Image{ nullptr };
  const void *                        m_Buffer{ nullptr };
  ModifiedTimeType                    m_Time{ 0 };
  ModifiedTimeType                    m_BufferTime{ 0 };
  typename ForceImageType::RegionType m_Region;
  bool                                m_NonFinite{ false };
  double                              m_NonFiniteValue{ 0.0 };
  typename ForceImageType::IndexType  m_NonFiniteIndex;
  double                              m_LargestForce{ 0.0 };
  double                              m_Diagonal{ 0.0 };
};

} // end namespace itk

#endif
