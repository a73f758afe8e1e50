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
#ifndef itkDeformableMeshEdgeSearch_h
#define itkDeformableMeshEdgeSearch_h

#include "itkDeformableMeshRegionForce.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>

namespace itk
{
namespace DeformableMeshFilterDetail
{

/** \class EdgeSearch
 * \brief The edge search of DeformableMeshFilter: for a vertex, the signed
 * distance along its unit normal to the strongest edge of the expected
 * polarity within a search distance.
 *
 * The intensity profile I(t) = I(x + t n), t in [-D, D], is sampled every
 * half voxel on the smoothed intensity image (so the profile is smoothed
 * along the normal too); its derivative by central differences, times the
 * polarity p (+1: the object is brighter than its surroundings, the
 * intensity falls outward; -1: it rises), is the edge strength. The
 * strongest sample is refined by a parabola through it and its two
 * neighbours. An edge counts only when the intensity drops, across it, by
 * at least the minimum contrast (over one voxel on each side): flat or noisy
 * profiles give no hit (NaN), and the vertex feels no edge force.
 * \ingroup ExplicitDeformableModel
 */
class EdgeSearch
{
public:
  /** Largest number of samples of a profile (a search distance of 32
   * voxels). */
  static constexpr unsigned int MaximumNumberOfSamples = 129;

  /** \a distance: D, \a step: the sampling step along the normal (half the
   * smallest voxel spacing), \a voxel: the smallest spacing, all in mm;
   * \a polarity: +1 or -1; \a minimumContrast: intensity units. */
  void
  Configure(double distance, double step, double voxel, int polarity, double minimumContrast)
  {
    m_Step = step;
    m_Polarity = polarity >= 0 ? 1.0 : -1.0;
    m_MinimumContrast = minimumContrast;
    const double half = std::ceil(distance / step - 1e-9);
    m_HalfCount = static_cast<int>(std::min<double>(half, (MaximumNumberOfSamples - 1) / 2));
    m_Distance = m_HalfCount * step;
    m_Extra = 1 + static_cast<int>(std::min(63.0, std::ceil(voxel / step - 1e-9)));
  }

  /** Signed distance (mm, along n) from x to the strongest edge, NaN when
   * there is none. */
  double
  Find(const IntensitySampler & sampler, const double * x, const float * n) const
  {
    // Two more samples on each side than the search interval: the
    // derivative at its ends, and the contrast one voxel beyond the edge.
    const int extra = m_Extra;
    const int first = -m_HalfCount - extra;
    const int count = 2 * (m_HalfCount + extra) + 1;
    double    profile[MaximumNumberOfSamples + 2 * 64];
    for (int k = 0; k < count; ++k)
    {
      const double t = (first + k) * m_Step;
      const double p[3] = { x[0] + t * n[0], x[1] + t * n[1], x[2] + t * n[2] };
      profile[k] = sampler.Sample(p);
    }
    int    best = -1;
    double strongest = 0.0;
    for (int k = extra; k < count - extra; ++k)
    {
      const double strength = -m_Polarity * (profile[k + 1] - profile[k - 1]);
      if (strength > strongest) // false for NaN (outside the image)
      {
        strongest = strength;
        best = k;
      }
    }
    if (best < 0)
    {
      return std::numeric_limits<double>::quiet_NaN();
    }
    const int    reach = extra - 1;
    const double drop = m_Polarity * (profile[best - reach] - profile[best + reach]);
    if (!(drop >= m_MinimumContrast))
    {
      return std::numeric_limits<double>::quiet_NaN();
    }
    // Sub-sample position: the vertex of the parabola through the strengths
    // at best - 1, best, best + 1 (one-sided at the interval's ends).
    double offset = 0.0;
    if (best > extra && best < count - extra - 1)
    {
      const double before = -m_Polarity * (profile[best] - profile[best - 2]);
      const double after = -m_Polarity * (profile[best + 2] - profile[best]);
      const double curvature = before - 2.0 * strongest + after;
      if (curvature < 0.0)
      {
        offset = std::max(-0.5, std::min(0.5, 0.5 * (before - after) / curvature));
      }
    }
    return (first + best + offset) * m_Step;
  }

  /** The search distance actually used (a whole number of steps, mm). */
  double
  GetDistance() const
  {
    return m_Distance;
  }

private:
  double m_Step{ 0.5 };
  double m_Polarity{ 1.0 };
  double m_MinimumContrast{ 0.0 };
  double m_Distance{ 0.0 };
  int    m_HalfCount{ 0 };
  int    m_Extra{ 3 };
};

} // namespace DeformableMeshFilterDetail
} // namespace itk

#endif
