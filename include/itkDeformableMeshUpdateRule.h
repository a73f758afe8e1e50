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

#include <algorithm>
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
 * The weights a and b of a filter's parameters (FromParameters()): without a
 * reference edge length, Elasticity and Rigidity scaled down so that
 * a + 2b <= 1, the stability bound of the explicit update. With a reference
 * edge length L (DeformableMeshFilter's ReferenceEdgeLength, mm), the terms
 * are made independent of the mesh's resolution by the edge weight
 * \f$ w = L^2 / \langle h^2 \rangle \f$ (EdgeWeight(); \f$ \langle h^2 \rangle
 * \f$ the mesh's mean squared edge length): on edges of length h the umbrella
 * vector is about \f$ (h^2/4)\,\Delta x \f$ (\f$ \Delta x = -2Hn \f$, the mean
 * curvature vector) and R about \f$ -(h^4/16)\,\Delta^2 x \f$, so the
 * elasticity weighted by \f$ a\,w \f$ is \f$ a\,(L^2/4)\,\Delta x \f$ and the
 * rigidity weighted by \f$ b\,w^2 \f$ is \f$ -b\,(L^4/16)\,\Delta^2 x \f$ whatever
 * h. The explicit update of those is stable when \f$ a w + 2 b w^2 \le 1 \f$:
 * an iteration is then split into subSteps sub-steps of the internal forces,
 * each with \f$ a w \f$ and \f$ b w^2 \f$ divided by their number, the
 * external force and the balloon applied once per iteration, in the last one.
 * Displacement() is the displacement of one sub-step; the external force and
 * balloon are 0 in all but the last (InternalOnly()).
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
  double elasticity{ 0.0 };        // a, after the a + 2b <= 1 scaling, or a w / subSteps
  double rigidity{ 0.0 };          // b, after the a + 2b <= 1 scaling, or b w^2 / subSteps
  bool   tangential{ true };       // E keeps its tangent part only
  double balloon{ 0.0 };           // beta, mm per iteration
  double maximumStepLength{ 0.0 }; // mm; 0: no bound
  double subSteps{ 1.0 };          // sub-steps of the internal forces per iteration

  /** The edge weight of a reference edge length \a referenceEdgeLength (mm)
   * on a mesh whose mean squared edge length is \a meanSquaredEdgeLength
   * (mm^2): (L / h)^2; 0 when either is 0 (no scaling). */
  static double
  EdgeWeight(double referenceEdgeLength, double meanSquaredEdgeLength)
  {
    return referenceEdgeLength > 0.0 && meanSquaredEdgeLength > 0.0
             ? referenceEdgeLength * referenceEdgeLength / meanSquaredEdgeLength
             : 0.0;
  }

  /** The rule of a filter's parameters. \a edgeWeight 0 (no reference edge
   * length): Elasticity and Rigidity scaled down so that a + 2b <= 1, the
   * stability bound of the explicit update, one step per iteration.
   * \a edgeWeight w > 0 (EdgeWeight()): a w and b w^2, in as many sub-steps
   * as the bound needs, ceil(a w + 2 b w^2) (at least 1). */
  static DeformableMeshUpdateRule
  FromParameters(double scaleFactor,
                 double elasticity,
                 double rigidity,
                 bool   tangentialElasticity,
                 double balloon,
                 double maximumStepLength,
                 double edgeWeight = 0.0)
  {
    DeformableMeshUpdateRule rule;
    if (edgeWeight > 0.0)
    {
      const double weightedElasticity = elasticity * edgeWeight;
      const double weightedRigidity = rigidity * edgeWeight * edgeWeight;
      rule.subSteps = std::max(1.0, std::ceil(weightedElasticity + 2.0 * weightedRigidity));
      rule.elasticity = weightedElasticity / rule.subSteps;
      rule.rigidity = weightedRigidity / rule.subSteps;
    }
    else
    {
      const double internalSum = elasticity + 2.0 * rigidity;
      const double internalScale = internalSum > 1.0 ? 1.0 / internalSum : 1.0;
      rule.elasticity = elasticity * internalScale;
      rule.rigidity = rigidity * internalScale;
    }
    rule.scaleFactor = scaleFactor;
    rule.tangential = tangentialElasticity;
    rule.balloon = balloon;
    rule.maximumStepLength = maximumStepLength;
    return rule;
  }

  /** The rule of the sub-steps before the last one of an iteration: the
   * internal forces alone. */
  DeformableMeshUpdateRule
  InternalOnly() const
  {
    DeformableMeshUpdateRule rule = *this;
    rule.scaleFactor = 0.0;
    rule.balloon = 0.0;
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
