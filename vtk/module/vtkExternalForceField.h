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
#ifndef vtkExternalForceField_h
#define vtkExternalForceField_h

#include "ExplicitDeformableModelVTKModule.h" // For export macro
#include "vtkImageAlgorithm.h"

/**
 * @class vtkExternalForceField
 * @brief External force field of a deformable model, computed from a scalar
 * volume: the gradient of the edge map, grad |grad (G_sigma * I)|, optionally
 * diffused by gradient vector flow.
 *
 * The VTK face of itk::ExternalForceImageFilter: the scalar point array of the
 * input vtkImageData (chosen with SetInputArrayToProcess(0, 0, 0,
 * vtkDataObject::FIELD_ASSOCIATION_POINTS, name); by default the active
 * scalars) is converted to an itk::Image<float, 3> with the image's origin,
 * spacing and direction, the ITK filter runs, and its vector image comes back
 * as the three-component float point array "Force" (the active vectors of the
 * output). The input's point arrays are passed along, so the output can be
 * given as it is to vtkDeformableMesh's port 1 and still be coloured by
 * intensity.
 *
 * The input is a three-dimensional image (at least 4 points along each axis
 * for the Gaussian smoothing), or a two-dimensional one of nx x ny x 1 points
 * (a plane z = const; the direction matrix must not mix z with x and y): the
 * 2-D ITK filter then computes the in-plane force, and the "Force" array
 * still has three components, the third 0, as vtkDeformableMesh and
 * ParaView's glyphs expect. The whole input extent is requested and
 * the whole extent is produced.
 *
 * Errors (vtkErrorMacro and an empty output): no input array, an array with
 * more than one component, an image that is neither 3-D nor nx x ny x 1, an invalid
 * parameter (a non-positive regularisation; SetSigma() clamps a negative
 * Sigma to 0), any exception of
 * the ITK filter (a Sigma beyond the image's largest extent, NaN or infinite
 * intensities), a failed memory allocation. No parameter value crashes.
 *
 * @sa vtkDeformableMesh itk::ExternalForceImageFilter
 */
class EXPLICITDEFORMABLEMODELVTK_EXPORT vtkExternalForceField : public vtkImageAlgorithm
{
public:
  static vtkExternalForceField *
  New();
  vtkTypeMacro(vtkExternalForceField, vtkImageAlgorithm);
  void
  PrintSelf(ostream & os, vtkIndent indent) override;

  ///@{
  /**
   * Standard deviation of the Gaussian smoothing, in physical units. It sets
   * the capture range of the plain gradient force (about 2 to 3 Sigma on
   * each side of an edge); 0 disables smoothing. Non-negative, at most the
   * largest physical extent of the input. Default: 1.0.
   */
  vtkSetClampMacro(Sigma, double, 0.0, VTK_DOUBLE_MAX);
  vtkGetMacro(Sigma, double);
  ///@}

  ///@{
  /**
   * Divide the field by its largest vector length, so that forces are at
   * most 1 (dimensionless) whatever the intensity range; a deformable mesh's
   * ScaleFactor is then its largest external displacement per iteration.
   * Default: On.
   */
  vtkSetMacro(NormalizeForces, vtkTypeBool);
  vtkGetMacro(NormalizeForces, vtkTypeBool);
  vtkBooleanMacro(NormalizeForces, vtkTypeBool);
  ///@}

  ///@{
  /**
   * Diffuse the force by gradient vector flow (Xu and Prince, 1998) so that
   * it reaches far from the edges. Default: Off.
   */
  vtkSetMacro(UseGradientVectorFlow, vtkTypeBool);
  vtkGetMacro(UseGradientVectorFlow, vtkTypeBool);
  vtkBooleanMacro(UseGradientVectorFlow, vtkTypeBool);
  ///@}

  ///@{
  /**
   * Regularisation weight mu of gradient vector flow (dimensionless, the edge
   * map being normalised to [0, 1]): larger values give smoother fields that
   * reach farther. Positive. Default: 0.1.
   */
  vtkSetMacro(GradientVectorFlowRegularization, double);
  vtkGetMacro(GradientVectorFlowRegularization, double);
  ///@}

  ///@{
  /**
   * Number of explicit diffusion iterations of gradient vector flow; the
   * distance the field spreads grows as the square root of this number.
   * Default: 400.
   */
  vtkSetClampMacro(GradientVectorFlowIterations, int, 0, VTK_INT_MAX);
  vtkGetMacro(GradientVectorFlowIterations, int);
  ///@}

protected:
  vtkExternalForceField();
  ~vtkExternalForceField() override = default;

  int
  FillInputPortInformation(int port, vtkInformation * info) override;
  int
  RequestUpdateExtent(vtkInformation *, vtkInformationVector **, vtkInformationVector *) override;
  int
  RequestData(vtkInformation *, vtkInformationVector **, vtkInformationVector *) override;

  double      Sigma = 1.0;
  vtkTypeBool NormalizeForces = 1;
  vtkTypeBool UseGradientVectorFlow = 0;
  double      GradientVectorFlowRegularization = 0.1;
  int         GradientVectorFlowIterations = 400;

private:
  vtkExternalForceField(const vtkExternalForceField &) = delete;
  void
  operator=(const vtkExternalForceField &) = delete;
};

#endif
