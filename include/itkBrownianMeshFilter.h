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
#ifndef itkBrownianMeshFilter_h
#define itkBrownianMeshFilter_h

#include "itkIterativeMeshFilter.h"

namespace itk
{

/** \class BrownianMeshFilter
 * \brief Moves every point of a mesh by an isotropic Gaussian random vector at
 * each iteration (a Brownian random walk).
 *
 * Each component of the displacement of a point at one iteration is drawn from
 * a normal distribution of zero mean and standard deviation
 * StepLength / sqrt(PointDimension), so that the root mean square length of the
 * displacement per iteration is StepLength. After n iterations a point has
 * moved by a Gaussian vector of covariance n * StepLength^2 / PointDimension * I.
 *
 * The random numbers are a function of (Seed, iteration, point index) only:
 * the output is the same whatever the number of threads, and running 2n
 * iterations at once or n then n more with IterateFromZero off gives the same
 * mesh.
 *
 * \sa IterativeMeshFilter
 * \ingroup ExplicitDeformableModel
 */
template <typename TMesh>
class ITK_TEMPLATE_EXPORT BrownianMeshFilter : public IterativeMeshFilter<TMesh, TMesh>
{
public:
  ITK_DISALLOW_COPY_AND_MOVE(BrownianMeshFilter);

  /** Standard class type aliases. */
  using Self = BrownianMeshFilter;
  using Superclass = IterativeMeshFilter<TMesh, TMesh>;
  using Pointer = SmartPointer<Self>;
  using ConstPointer = SmartPointer<const Self>;

  /** Method for creation through the object factory. */
  itkNewMacro(Self);

  /** Run-time type information (and related methods). */
  itkOverrideGetNameOfClassMacro(BrownianMeshFilter);

  using MeshType = TMesh;
  static constexpr unsigned int PointDimension = Superclass::PointDimension;

  /** Root mean square length of the displacement of a point per iteration, in
   * physical units (the mesh's coordinate units, mm for medical images).
   * Must be finite and non-negative. Default: 1.0. */
  itkSetMacro(StepLength, double);
  itkGetConstMacro(StepLength, double);

  /** Seed of the random walk: the same seed gives the same output.
   * Default: 0. */
  itkSetMacro(Seed, uint64_t);
  itkGetConstMacro(Seed, uint64_t);

protected:
  BrownianMeshFilter() = default;
  ~BrownianMeshFilter() override = default;

  void
  PrintSelf(std::ostream & os, Indent indent) const override;

  void
  VerifyPreconditions() const override;

  void
  Iterate() override;

private:
  double   m_StepLength{ 1.0 };
  uint64_t m_Seed{ 0 };
};
} // end namespace itk

#ifndef ITK_MANUAL_INSTANTIATION
#  include "itkBrownianMeshFilter.hxx"
#endif

#endif
