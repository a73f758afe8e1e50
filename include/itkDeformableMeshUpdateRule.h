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
#ifndef itkDeformableMeshUpdateRule_h
#define itkDeformableMeshUpdateRule_h

#include "itkVector.h"

#include <cmath>

namespace itk
{

/** \class DeformableMeshUpdateRule
 * \brief The per-vertex update rule of DeformableMeshFilter, in scalar form:
 * the reference that the filter's vectorised kernels implement.
 *
 * Given what the step knows of a vertex (VertexTerms: the sampled force,
 * the umbrella vector, the outward unit normal, the mean of the neighbours'
 * umbrella vectors, the image terms' normal speed) and whether its balloon
 * has been released, Displacement() returns the vertex's displacement for
 * one iteration:
 * \f[
 *   \Delta x = s\,F + a\,E + b\,R + (\beta + v)\,n ,
 *   \qquad E = u \;\mbox{or}\; u - (u \cdot n)\,n, \qquad R = u - \bar u ,
 * \f]
 * bounded in length by MaximumStepLength when it is positive. The balloon
 * \f$ \beta \f$ is released, for good, once the external force opposes it
 * with at least half its strength: \f$ \beta\,(sF \cdot n) \le -\beta^2/2 \f$.
 *
 * A new force term goes here as one more member and one more line in
 * Displacement(), in the kernels' StepBlock()
 * (itkDeformableMeshFilterKernelBody.inc) where its input is sampled, as a
 * parameter of DeformableMeshFilter, and in the scalar reference test
 * (test/itkDeformableMeshFilterKernelsGTest.cxx), which holds the kernels against
 * this rule on irregular meshes with and without each term. A term that
 * moves vertices along the normal (region force, edge search) can instead
 * fill the filter's normal speeds (VertexTerms::normalSpeed).
 *
 * \sa DeformableMeshFilter
 * \ingroup ExplicitDeformableModel
 */
struct DeformableMeshUpdateRule
{
  using VectorType = Vector<double, 3>;

  /** What the step knows of one vertex. */
  struct VertexTerms
  {
    VectorType force{ 0.0 };        // F: the force image at the vertex (0 outside it)
    VectorType umbrella{ 0.0 };     // u: centroid of the neighbours minus the vertex
    VectorType normal{ 0.0 };       // n: outward unit normal, 0 where it is undefined
    VectorType umbrellaMean{ 0.0 }; // mean of the neighbours' umbrella vectors (0 without neighbours)
    double     normalSpeed{ 0.0 };  // v: outward speed of the image terms, mm per iteration
  };

  double scaleFactor{ 1.0 };       // s, mm per unit of force
  double elasticity{ 0.0 };        // a, after the a + 2b <= 1 scaling
  double rigidity{ 0.0 };          // b, after the a + 2b <= 1 scaling
  bool   tangential{ true };       // E keeps its tangent part only
  double balloon{ 0.0 };           // beta, mm per iteration
  double maximumStepLength{ 0.0 }; // mm; 0: no bound

  /** The rule of a filter's parameters: Elasticity and Rigidity scaled down
   * so that a + 2b <= 1, the stability bound of the explicit update. */
  static DeformableMeshUpdateRule
  FromParameters(double scaleFactor,
                 double elasticity,
                 double rigidity,
                 bool   tangentialElasticity,
                 double balloon,
                 double maximumStepLength)
  {
    const double             internalSum = elasticity + 2.0 * rigidity;
    const double             internalScale = internalSum > 1.0 ? 1.0 / internalSum : 1.0;
    DeformableMeshUpdateRule rule;
    rule.scaleFactor = scaleFactor;
    rule.elasticity = elasticity * internalScale;
    rule.rigidity = rigidity * internalScale;
    rule.tangential = tangentialElasticity;
    rule.balloon = balloon;
    rule.maximumStepLength = maximumStepLength;
    return rule;
  }

  /** The displacement of one vertex; sets balloonReleased when the balloon
   * is released at this iteration. */
  VectorType
  Displacement(const VertexTerms & v, bool & balloonReleased) const
  {
    const VectorType external = scaleFactor * v.force;

    VectorType elastic = v.umbrella;
    if (tangential)
    {
      elastic -= (v.umbrella * v.normal) * v.normal;
    }
    const VectorType bending = v.umbrella - v.umbrellaMean;

    double speed = 0.0;
    if (balloon != 0.0 && !balloonReleased)
    {
      if (balloon * (external * v.normal) <= -0.5 * balloon * balloon)
      {
        balloonReleased = true;
      }
      else
      {
        speed = balloon;
      }
    }
    speed += v.normalSpeed;

    VectorType   delta = external + elasticity * elastic + rigidity * bending + speed * v.normal;
    const double length = delta.GetNorm();
    if (maximumStepLength > 0.0 && length > maximumStepLength)
    {
      delta *= maximumStepLength / length;
    }
    return delta;
  }
};

} // end namespace itk

#endif
