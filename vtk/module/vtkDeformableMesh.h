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
#ifndef vtkDeformableMesh_h
#define vtkDeformableMesh_h

#include "ExplicitDeformableModelVTKModule.h" // For export macro
#include "vtkIterativePolyDataAlgorithm.h"

class vtkAlgorithmOutput;
class vtkDeformableMeshInternals;
class vtkImageData;

/**
 * @class vtkDeformableMesh
 * @brief Explicit deformable surface: the points of a polydata move, iteration
 * after iteration, under a force field given as a vector image and internal
 * forces that keep the surface regular.
 *
 * The VTK face of itk::DeformableMeshFilter. Inputs:
 * - port 0: the initial mesh (vtkPolyData; triangles, polygons, strips, lines);
 * - port 1: a vtkImageData holding the external force field as a
 *   three-component point array in physical space (origin, spacing and
 *   direction honoured), chosen with SetInputArrayToProcess(0, 1, 0,
 *   vtkDataObject::FIELD_ASSOCIATION_POINTS, name); by default the active
 *   vectors of port 1.
 *
 * The parameters and their defaults are the ITK filter's (the constructor
 * reads the defaults from it).
 *
 * At each iteration every vertex x_i moves by
 *   s F(x_i) + a E_i + b R_i + beta n_i
 * with F the force field sampled by trilinear interpolation (ScaleFactor s),
 * E_i the elastic force toward the centroid of the neighbours (Elasticity a),
 * R_i the rigidity (bending) force (Rigidity b) and n_i the outward normal
 * (Balloon beta). With all internal weights 0 (the defaults) each point moves
 * independently, as in the seed paper's vtkDeformableMesh. See
 * itk::DeformableMeshFilter for the details; this class runs it.
 *
 * The force image is converted to ITK (single precision) when it or its array
 * changes; a new force image does not restart the iterations, a new mesh does.
 *
 * With ComputeDiagnostics on, the output carries three point arrays of the
 * last iteration, in physical units: DisplacementMagnitude,
 * ExternalForceMagnitude (s |F|) and InternalForceMagnitude (|a E + b R|);
 * they are zero before the first iteration.
 *
 * Errors (vtkErrorMacro and an empty output): no image on port 1, no array to
 * process, an array that does not have three components or does not match the
 * image's points, an empty mesh, an invalid parameter.
 *
 * @sa vtkIterativePolyDataAlgorithm itk::DeformableMeshFilter
 * itk::ExternalForceImageFilter
 */
class EXPLICITDEFORMABLEMODELVTK_EXPORT vtkDeformableMesh : public vtkIterativePolyDataAlgorithm
{
public:
  static vtkDeformableMesh *
  New();
  vtkTypeMacro(vtkDeformableMesh, vtkIterativePolyDataAlgorithm);
  void
  PrintSelf(ostream & os, vtkIndent indent) override;

  ///@{
  /**
   * The force image (port 1). Same as SetInputData(1, image) and
   * SetInputConnection(1, output).
   */
  void
  SetForceImageData(vtkImageData * image);
  void
  SetForceImageConnection(vtkAlgorithmOutput * output);
  ///@}

  ///@{
  /**
   * Weight s of the external force: a vertex moves by s times the sampled
   * force per iteration. With a force field normalised to a largest length of
   * 1 (itk::ExternalForceImageFilter's default), s is the largest external
   * displacement per iteration in physical units. Finite. Default: 1.0.
   */
  vtkSetMacro(ScaleFactor, double);
  vtkGetMacro(ScaleFactor, double);
  ///@}

  ///@{
  /**
   * Weight a of the elastic (membrane) force pulling each vertex toward the
   * centroid of its neighbours; dimensionless, in [0, 1]. Default: 0.
   */
  vtkSetClampMacro(Elasticity, double, 0.0, 1.0);
  vtkGetMacro(Elasticity, double);
  ///@}

  ///@{
  /**
   * When on (default), the elastic force keeps only its component tangent to
   * the surface (it spreads the vertices without shrinking the surface).
   */
  vtkSetMacro(TangentialElasticity, vtkTypeBool);
  vtkGetMacro(TangentialElasticity, vtkTypeBool);
  vtkBooleanMacro(TangentialElasticity, vtkTypeBool);
  ///@}

  ///@{
  /**
   * Weight b of the rigidity (bending) force; dimensionless, in [0, 1]
   * (a + 2b above 1 is scaled down to 1 by the ITK filter). Default: 0.
   */
  vtkSetClampMacro(Rigidity, double, 0.0, 1.0);
  vtkGetMacro(Rigidity, double);
  ///@}

  ///@{
  /**
   * Balloon force: displacement along the outward unit normal per iteration,
   * in physical units; positive inflates, negative deflates. The ITK filter
   * releases it for a vertex once the external force opposes it at least as
   * strongly, so that the vertex settles on the edge. Default: 0.
   */
  vtkSetMacro(Balloon, double);
  vtkGetMacro(Balloon, double);
  ///@}

  ///@{
  /**
   * Upper bound on a vertex's displacement per iteration, physical units;
   * 0 means no bound. Non-negative. Default: 0.
   */
  vtkSetClampMacro(MaximumStepLength, double, 0.0, VTK_DOUBLE_MAX);
  vtkGetMacro(MaximumStepLength, double);
  ///@}

  ///@{
  /**
   * Convergence threshold on the largest vertex displacement of an
   * iteration, physical units; 0 (default) disables convergence detection.
   */
  vtkSetClampMacro(ConvergenceTolerance, double, 0.0, VTK_DOUBLE_MAX);
  vtkGetMacro(ConvergenceTolerance, double);
  ///@}

  ///@{
  /**
   * Number of consecutive iterations below ConvergenceTolerance that declare
   * convergence. At least 1. Default: 3.
   */
  vtkSetClampMacro(ConvergenceWindow, int, 1, VTK_INT_MAX);
  vtkGetMacro(ConvergenceWindow, int);
  ///@}

  ///@{
  /**
   * Add the DisplacementMagnitude, ExternalForceMagnitude and
   * InternalForceMagnitude point arrays to the output. Default: On.
   */
  vtkSetMacro(ComputeDiagnostics, vtkTypeBool);
  vtkGetMacro(ComputeDiagnostics, vtkTypeBool);
  vtkBooleanMacro(ComputeDiagnostics, vtkTypeBool);
  ///@}

  /**
   * True (1) when the last update stopped because of convergence.
   */
  vtkGetMacro(Converged, vtkTypeBool);

  /**
   * Largest vertex displacement of the last iteration, physical units.
   */
  vtkGetMacro(LastMaximumDisplacement, double);

protected:
  vtkDeformableMesh();
  ~vtkDeformableMesh() override;

  int
  FillInputPortInformation(int port, vtkInformation * info) override;
  int
  PrepareFilter(vtkInformationVector ** inputVector) override;
  void
  AddOutputArrays(vtkPolyData * output) override;

  double      ScaleFactor = 1.0;
  double      Elasticity = 0.0;
  vtkTypeBool TangentialElasticity = 1;
  double      Rigidity = 0.0;
  double      Balloon = 0.0;
  double      MaximumStepLength = 0.0;
  double      ConvergenceTolerance = 0.0;
  int         ConvergenceWindow = 5;
  vtkTypeBool ComputeDiagnostics = 1;
  vtkTypeBool Converged = 0;
  double      LastMaximumDisplacement = 0.0;

  // The typed ITK filter and the converted force image.
  vtkDeformableMeshInternals * DeformableInternals;

private:
  vtkDeformableMesh(const vtkDeformableMesh &) = delete;
  void
  operator=(const vtkDeformableMesh &) = delete;
};

#endif
