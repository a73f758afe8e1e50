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
#ifndef vtkPolyDataIterativeWarp_h
#define vtkPolyDataIterativeWarp_h

#include "ExplicitDeformableModelVTKModule.h" // For export macro
#include "vtkIterativePolyDataAlgorithm.h"

/**
 * @class vtkPolyDataIterativeWarp
 * @brief Brownian random walk of the points of a polydata, one step per
 * iteration.
 *
 * The VTK face of itk::BrownianMeshFilter: at each iteration every point moves
 * by an isotropic Gaussian vector whose root mean square length is StepLength,
 * so that after n iterations a point has moved by a Gaussian vector of
 * covariance n * StepLength^2 / 3 * I. The random numbers depend on Seed, the
 * iteration and the point index only: the output does not depend on the
 * number of threads, and n iterations followed by n more with IterateFromZero
 * off give the same points as 2n at once.
 *
 * @sa vtkIterativePolyDataAlgorithm itk::BrownianMeshFilter
 */
class EXPLICITDEFORMABLEMODELVTK_EXPORT vtkPolyDataIterativeWarp : public vtkIterativePolyDataAlgorithm
{
public:
  static vtkPolyDataIterativeWarp *
  New();
  vtkTypeMacro(vtkPolyDataIterativeWarp, vtkIterativePolyDataAlgorithm);
  void
  PrintSelf(ostream & os, vtkIndent indent) override;

  ///@{
  /**
   * Root mean square length of a point's displacement per iteration, in the
   * units of the point coordinates (mm for medical images). Non-negative.
   * Default: 1.0.
   */
  vtkSetClampMacro(StepLength, double, 0.0, VTK_DOUBLE_MAX);
  vtkGetMacro(StepLength, double);
  ///@}

  ///@{
  /**
   * Seed of the random walk: the same seed gives the same output.
   * Non-negative. Default: 0.
   */
  vtkSetClampMacro(Seed, int, 0, VTK_INT_MAX);
  vtkGetMacro(Seed, int);
  ///@}

protected:
  vtkPolyDataIterativeWarp();
  ~vtkPolyDataIterativeWarp() override = default;

  int
  PrepareFilter(vtkInformationVector ** inputVector) override;

  double StepLength = 1.0;
  int    Seed = 0;

private:
  vtkPolyDataIterativeWarp(const vtkPolyDataIterativeWarp &) = delete;
  void
  operator=(const vtkPolyDataIterativeWarp &) = delete;
};

#endif
