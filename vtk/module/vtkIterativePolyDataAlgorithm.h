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
#ifndef vtkIterativePolyDataAlgorithm_h
#define vtkIterativePolyDataAlgorithm_h

#include "ExplicitDeformableModelVTKModule.h" // For export macro
#include "vtkPolyDataAlgorithm.h"

class vtkIterativePolyDataAlgorithmInternals;

/**
 * @class vtkIterativePolyDataAlgorithm
 * @brief Base class of polydata algorithms that move the points of their input
 * step by step and can resume where the previous update stopped.
 *
 * The VTK face of itk::IterativeMeshFilter: each subclass keeps one ITK filter
 * alive and this class drives it from RequestData(), so the iteration contract
 * is the ITK filter's own:
 *
 * - On the first update, when IterateFromZero is on, when NumberOfIterations
 *   is 0 or below CurrentIteration, or when the input polydata has changed
 *   (another object, or a larger modification time), the input is cached and
 *   CurrentIteration returns to 0.
 * - While CurrentIteration < NumberOfIterations one step runs. With
 *   IterateFromZero off, raising NumberOfIterations by one and updating runs
 *   exactly one more step: this is what makes animation cheap (a render loop,
 *   ParaView's animation view).
 * - NumberOfIterations == 0 gives the input points back unchanged.
 *
 * The input is never modified. The output has the input's cells, point data,
 * cell data and field data (shallow copies) and new points of the input's
 * point data type. Progress is forwarded from the ITK filter, and
 * SetAbortExecute(1) stops the iterations between two steps.
 *
 * Two dimensions: a subclass with a 2-D ITK filter (vtkDeformableMesh)
 * deforms contours, the lines and polylines of the input over a 2-D image,
 * in the plane z = ContourPlaneZ (RequestMeshDimension() decides, at each
 * update; the input's z is ignored and the output points have that z). The
 * iteration contract is the same in both; a change of dimension restarts.
 *
 * An empty input (no points) is an error: vtkErrorMacro and an empty output.
 * So is any exception thrown by the ITK filter.
 *
 * @sa vtkPolyDataIterativeWarp vtkDeformableMesh itk::IterativeMeshFilter
 */
class EXPLICITDEFORMABLEMODELVTK_EXPORT vtkIterativePolyDataAlgorithm : public vtkPolyDataAlgorithm
{
public:
  vtkTypeMacro(vtkIterativePolyDataAlgorithm, vtkPolyDataAlgorithm);
  void
  PrintSelf(ostream & os, vtkIndent indent) override;

  ///@{
  /**
   * Number of iterations the output should have undergone after the update.
   * Default: 0 (the output points are the input points). With IterateFromZero
   * off, only the iterations between CurrentIteration and NumberOfIterations
   * are computed.
   */
  vtkSetClampMacro(NumberOfIterations, int, 0, VTK_INT_MAX);
  vtkGetMacro(NumberOfIterations, int);
  ///@}

  /**
   * Number of iterations the current output has undergone: NumberOfIterations
   * after a complete update, less when the update was aborted or the
   * algorithm converged (vtkDeformableMesh).
   */
  vtkGetMacro(CurrentIteration, int);

  ///@{
  /**
   * When on (default), every update restarts from the input and runs all
   * NumberOfIterations iterations. When off, an update continues from the
   * previous output: raising NumberOfIterations by one runs one step.
   */
  vtkSetMacro(IterateFromZero, vtkTypeBool);
  vtkGetMacro(IterateFromZero, vtkTypeBool);
  vtkBooleanMacro(IterateFromZero, vtkTypeBool);
  ///@}

  /**
   * Dimension of the model at the last update: 3 (surfaces, and curves in
   * space) or 2 (contours in a plane z = const over a 2-D image); 0 before
   * the first update or after an input was refused.
   */
  vtkGetMacro(MeshDimension, int);

protected:
  vtkIterativePolyDataAlgorithm();
  ~vtkIterativePolyDataAlgorithm() override;

  int
  RequestData(vtkInformation *, vtkInformationVector **, vtkInformationVector *) override;

  /**
   * Subclass hook, called before the ITK filter updates: pass the parameters
   * and the other inputs to the filter. Return 0 after a vtkErrorMacro to
   * abort the update (the output is then empty).
   */
  virtual int
  PrepareFilter(vtkInformationVector ** inputVector) = 0;

  /**
   * Subclass hook, called first at each update: the dimension of the model
   * for this input, 3 (the default) or 2 (contours; set ContourPlaneZ, the z
   * of the output points, and create Internals->ContourFilter). Return 0
   * after a vtkErrorMacro to refuse the input (the output is then empty).
   * MeshDimension holds the value for PrepareFilter() and AddOutputArrays().
   */
  virtual int
  RequestMeshDimension(vtkPolyData * input, vtkInformationVector ** inputVector);

  /**
   * Subclass hook, called after a successful update: add arrays (diagnostics)
   * to the output. Default: nothing.
   */
  virtual void
  AddOutputArrays(vtkPolyData * output);

  int         NumberOfIterations = 0;
  int         CurrentIteration = 0;
  vtkTypeBool IterateFromZero = 1;
  int         MeshDimension = 0;
  double      ContourPlaneZ = 0.0;

  // The ITK filter, the cached ITK input mesh and what it was made from.
  vtkIterativePolyDataAlgorithmInternals * Internals;

private:
  vtkIterativePolyDataAlgorithm(const vtkIterativePolyDataAlgorithm &) = delete;
  void
  operator=(const vtkIterativePolyDataAlgorithm &) = delete;
};

#endif
