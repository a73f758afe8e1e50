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
#ifndef itkBrownianMeshFilter_hxx
#define itkBrownianMeshFilter_hxx

#include "itkBrownianMeshFilter.h"
#include "itkMultiThreaderBase.h"

#include <cmath>

namespace itk
{
namespace BrownianMeshFilterDetail
{
/** SplitMix64 finaliser: a bijective 64-bit mix used as a counter-based
 * generator, so that each (seed, iteration, point) has its own stream. */
inline uint64_t
Mix(uint64_t z)
{
  z += 0x9e3779b97f4a7c15ULL;
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  return z ^ (z >> 31);
}

/** Uniform double in (0, 1] from the 53 high bits. */
inline double
ToUnitInterval(uint64_t z)
{
  return (static_cast<double>(z >> 11) + 1.0) * (1.0 / 9007199254740992.0);
}
} // namespace BrownianMeshFilterDetail

template <typename TMesh>
void
BrownianMeshFilter<TMesh>::VerifyPreconditions() const
{
  Superclass::VerifyPreconditions();
  if (!std::isfinite(m_StepLength) || m_StepLength < 0.0)
  {
    itkExceptionMacro("StepLength must be finite and non-negative; it is " << m_StepLength << ".");
  }
}

template <typename TMesh>
void
BrownianMeshFilter<TMesh>::Iterate()
{
  using namespace BrownianMeshFilterDetail;
  std::vector<double> & coordinates = this->GetCoordinates();
  const SizeValueType   numberOfPoints = this->GetNumberOfCachedPoints();
  const double          sigma = m_StepLength / std::sqrt(static_cast<double>(PointDimension));
  const uint64_t        stream = Mix(m_Seed ^ Mix(static_cast<uint64_t>(this->GetCurrentIteration())));
  constexpr double      twoPi = 6.283185307179586476925;

  constexpr SizeValueType blockSize = 4096;
  const SizeValueType     numberOfBlocks = (numberOfPoints + blockSize - 1) / blockSize;
  auto                    moveBlock = [&](SizeValueType block) {
    const SizeValueType end = std::min(numberOfPoints, (block + 1) * blockSize);
    for (SizeValueType i = block * blockSize; i < end; ++i)
    {
      uint64_t counter = Mix(stream ^ (static_cast<uint64_t>(i) * 0xd1b54a32d192ed03ULL));
      double * x = coordinates.data() + i * PointDimension;
      for (unsigned int d = 0; d < PointDimension; d += 2)
      {
        // Box-Muller: two independent normal deviates from two uniforms.
        const double u1 = ToUnitInterval(counter = Mix(counter));
        const double u2 = ToUnitInterval(counter = Mix(counter));
        const double radius = sigma * std::sqrt(-2.0 * std::log(u1));
        x[d] += radius * std::cos(twoPi * u2);
        if (d + 1 < PointDimension)
        {
          x[d + 1] += radius * std::sin(twoPi * u2);
        }
      }
    }
  };
  this->GetMultiThreader()->SetNumberOfWorkUnits(this->GetNumberOfWorkUnits());
  this->GetMultiThreader()->ParallelizeArray(0, numberOfBlocks, moveBlock, nullptr);
}

template <typename TMesh>
void
BrownianMeshFilter<TMesh>::PrintSelf(std::ostream & os, Indent indent) const
{
  Superclass::PrintSelf(os, indent);
  os << indent << "StepLength: " << m_StepLength << std::endl;
  os << indent << "Seed: " << m_Seed << std::endl;
}

} // end namespace itk

#endif
