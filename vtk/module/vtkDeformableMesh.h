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
 * The VTK face of itk::DeformableMeshFilter, in 3-D (surfaces) and in 2-D
 * (contours, snakes). Inputs:
 * - port 0: the initial mesh (vtkPolyData; triangles, polygons, strips, lines),
 *   or, over a 2-D image, the initial contours (lines and polylines only);
 * - port 1: a vtkImageData holding the external force field as a
 *   three-component point array in physical space (origin, spacing and
 *   direction honoured), chosen with SetInputArrayToProcess(0, 1, 0,
 *   vtkDataObject::FIELD_ASSOCIATION_POINTS, name); by default the active
 *   vectors of port 1. With RegionWeight > 0, the same image also holds the
 *   intensities of the region force as a one-component point array, chosen
 *   with SetInputArrayToProcess(1, 1, 0, ...); by default the active scalars
 *   (vtkExternalForceField's output carries its input's scalars).
 *
 * 2-D contours: when the image on port 1 is 2-D (a vtkImageData of nx x ny
 * x 1 points; origin, spacing and the in-plane part of the direction matrix
 * honoured) the input must be contours, lines and polylines, open or closed
 * (a polyline is closed when it ends on the point it starts from), several
 * per polydata; the 2-D itk::DeformableMeshFilter deforms them in the
 * image's plane. The input's z is ignored; the output has the input's cells
 * and its points in the image's plane (z of the image's points). The force
 * array then has 3 components (the third is ignored; vtkExternalForceField
 * gives 0) or 2. The balloon and the region force inflate closed contours
 * (each is oriented counter-clockwise, whatever the order of its points), and
 * need every contour closed: outward is undefined for an open one.
 * FixedBoundary keeps the ends of open contours where they are. Everything
 * else (parameters, diagnostics, the iteration contract) is as in 3-D;
 * remeshing works on surfaces only.
 *
 * The parameters and their defaults are the ITK filter's (the constructor
 * reads the defaults from it); itk::DeformableMeshFilter documents each one
 * in full, this header gives units, range and default.
 *
 * At each iteration every vertex x_i moves by
 *   s F(x_i) + a E_i + b R_i + beta n_i
 * with F the force field sampled by trilinear (2-D: bilinear) interpolation (ScaleFactor s),
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
 * process, an array that does not have three components (2-D: two or three)
 * or does not match the image's points, an empty mesh, an invalid parameter;
 * over a 2-D image: an input without lines, or with lines mixed with
 * polygons, triangle strips or vertices, an image flat along x or y, a
 * direction matrix that tilts the image's plane, the balloon or the region
 * force with an open contour; over a 3-D image: lines alone in one plane
 * z = const (a 2-D contour, which needs a 2-D image).
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
   * Weight s of the external force; with a normalised force field, the largest
   * external displacement per iteration. Millimetres; finite; default 1.0.
   * Meaning in full: itk::DeformableMeshFilter::SetScaleFactor().
   */
  vtkSetMacro(ScaleFactor, double);
  vtkGetMacro(ScaleFactor, double);
  ///@}

  ///@{
  /**
   * Weight a of the elastic (membrane) force toward the neighbours' centroid.
   * Dimensionless, [0, 1]; default 0.
   * Meaning in full: itk::DeformableMeshFilter::SetElasticity().
   */
  vtkSetClampMacro(Elasticity, double, 0.0, 1.0);
  vtkGetMacro(Elasticity, double);
  ///@}

  ///@{
  /**
   * Keep only the part of the elastic force tangent to the surface (no
   * shrinking). Default on.
   * Meaning in full: itk::DeformableMeshFilter::SetTangentialElasticity().
   */
  vtkSetMacro(TangentialElasticity, vtkTypeBool);
  vtkGetMacro(TangentialElasticity, vtkTypeBool);
  vtkBooleanMacro(TangentialElasticity, vtkTypeBool);
  ///@}

  ///@{
  /**
   * Weight b of the rigidity (bending) force. Dimensionless, [0, 1] (a + 2b
   * above 1 is scaled down to 1); default 0.
   * Meaning in full: itk::DeformableMeshFilter::SetRigidity().
   */
  vtkSetClampMacro(Rigidity, double, 0.0, 1.0);
  vtkGetMacro(Rigidity, double);
  ///@}

  ///@{
  /**
   * Inflation along the outward normal per iteration, released at a vertex
   * once the external force opposes it with at least half its strength;
   * negative deflates. Millimetres per iteration; finite; default 0.
   * Meaning in full: itk::DeformableMeshFilter::SetBalloon().
   */
  vtkSetMacro(Balloon, double);
  vtkGetMacro(Balloon, double);
  ///@}

  ///@{
  /**
   * Weight of the region force: the largest inflation (intensity inside the
   * object's range, estimated inside the initial surface) or deflation
   * (outside it) per iteration; 0: off. Millimetres per iteration, at least
   * 0; default 0. Meaning in full: itk::DeformableMeshFilter::SetRegionWeight().
   */
  vtkSetClampMacro(RegionWeight, double, 0.0, VTK_DOUBLE_MAX);
  vtkGetMacro(RegionWeight, double);
  ///@}

  ///@{
  /**
   * Gaussian smoothing of the intensities for the region force.
   * Millimetres, at least 0; default 1.
   * Meaning in full: itk::DeformableMeshFilter::SetRegionSigma().
   */
  vtkSetClampMacro(RegionSigma, double, 0.0, VTK_DOUBLE_MAX);
  vtkGetMacro(RegionSigma, double);
  ///@}

  ///@{
  /**
   * Edge search: the largest displacement per iteration toward the strongest
   * edge of the object's polarity found along the normal. Millimetres per
   * iteration, at least 0; default 0 (off).
   * Meaning in full: itk::DeformableMeshFilter::SetEdgeSearchWeight().
   */
  vtkSetClampMacro(EdgeSearchWeight, double, 0.0, VTK_DOUBLE_MAX);
  vtkGetMacro(EdgeSearchWeight, double);
  ///@}

  ///@{
  /**
   * How far the edge search looks on each side of the surface along the
   * normal. Millimetres, positive; default 2.
   * Meaning in full: itk::DeformableMeshFilter::SetEdgeSearchDistance().
   */
  vtkSetClampMacro(EdgeSearchDistance, double, 1e-6, VTK_DOUBLE_MAX);
  vtkGetMacro(EdgeSearchDistance, double);
  ///@}

  ///@{
  /**
   * Half-width of the estimated object intensity range, in robust standard
   * deviations. Positive; default 2.2.
   * Meaning in full: itk::DeformableMeshFilter::SetIntensityTolerance().
   */
  vtkSetClampMacro(IntensityTolerance, double, 1e-6, VTK_DOUBLE_MAX);
  vtkGetMacro(IntensityTolerance, double);
  ///@}

  ///@{
  /**
   * With the object's range estimated (EstimateObjectIntensityRange on), the
   * bounds of the range follow the background sampled just outside the
   * surface every BackgroundUpdateInterval iterations. Default: on.
   * Meaning in full: itk::DeformableMeshFilter::SetEstimateBackgroundIntensity().
   */
  vtkSetMacro(EstimateBackgroundIntensity, vtkTypeBool);
  vtkGetMacro(EstimateBackgroundIntensity, vtkTypeBool);
  vtkBooleanMacro(EstimateBackgroundIntensity, vtkTypeBool);
  ///@}

  ///@{
  /**
   * Iterations between two estimates of the background. At least 1;
   * default 10. Meaning in full:
   * itk::DeformableMeshFilter::SetBackgroundUpdateInterval().
   */
  vtkSetClampMacro(BackgroundUpdateInterval, int, 1, VTK_INT_MAX);
  vtkGetMacro(BackgroundUpdateInterval, int);
  ///@}

  ///@{
  /**
   * On (default): the object's intensity model is estimated inside the
   * initial surface at each reset. Off: ObjectIntensityRange is the object's
   * range, fixed (no background estimate), with a transition width of a
   * tenth of it. Meaning in full:
   * itk::DeformableMeshFilter::SetEstimateObjectIntensityRange() and
   * SetObjectIntensityRange().
   */
  vtkSetMacro(EstimateObjectIntensityRange, vtkTypeBool);
  vtkGetMacro(EstimateObjectIntensityRange, vtkTypeBool);
  vtkBooleanMacro(EstimateObjectIntensityRange, vtkTypeBool);
  ///@}

  ///@{
  /**
   * The object's intensity range [lower, upper], in the intensity array's
   * units, used when EstimateObjectIntensityRange is off (lower below
   * upper, or RequestData fails). Default: [0, 1].
   */
  vtkSetVector2Macro(ObjectIntensityRange, double);
  vtkGetVector2Macro(ObjectIntensityRange, double);
  ///@}

  ///@{
  /**
   * The edges the edge search looks for: +1 where the intensity falls
   * outward (bright object), -1 where it rises (dark object), 0 (default)
   * from the intensity model. Meaning in full:
   * itk::DeformableMeshFilter::SetEdgePolarity().
   */
  vtkSetClampMacro(EdgePolarity, int, -1, 1);
  vtkGetMacro(EdgePolarity, int);
  ///@}

  ///@{
  /**
   * Bound on a vertex's displacement per iteration; 0: no bound.
   * Millimetres, at least 0; default 0.
   * Meaning in full: itk::DeformableMeshFilter::SetMaximumStepLength().
   */
  vtkSetClampMacro(MaximumStepLength, double, 0.0, VTK_DOUBLE_MAX);
  vtkGetMacro(MaximumStepLength, double);
  ///@}

  ///@{
  /**
   * Target edge length of the adaptive remeshing: every RemeshingInterval
   * iterations the edges are brought into [2/3, 4/3] of it (splits,
   * collapses, flips, relaxation); the output then has the remeshed points
   * and triangles and no point or cell data of the input. 0: off.
   * Millimetres, at least 0; default 0.
   * Meaning in full: itk::DeformableMeshFilter::SetRemeshingEdgeLength().
   */
  vtkSetClampMacro(RemeshingEdgeLength, double, 0.0, VTK_DOUBLE_MAX);
  vtkGetMacro(RemeshingEdgeLength, double);
  ///@}

  ///@{
  /**
   * Iterations between two remeshings. At least 1; default 10.
   * Meaning in full: itk::DeformableMeshFilter::SetRemeshingInterval().
   */
  vtkSetClampMacro(RemeshingInterval, int, 1, VTK_INT_MAX);
  vtkGetMacro(RemeshingInterval, int);
  ///@}

  ///@{
  /**
   * What becomes of the external force's component tangent to the surface
   * where the surface has come to rest (external displacement below an
   * eighth of the mesh's root mean square edge length; whole beyond a
   * quarter of it). TANGENTIAL_DRIFT_KEEP (0): the force acts whole.
   * TANGENTIAL_DRIFT_SUPPRESS (1): dropped at rest, so the vertices of a
   * converged surface stop flowing along it and the remeshings stop
   * splitting and collapsing edges. TANGENTIAL_DRIFT_SUPPRESS_WHEN_REMESHING
   * (2, the default): suppressed when RemeshingEdgeLength > 0, kept
   * otherwise. SetSuppressTangentialDrift(), SuppressTangentialDriftOn() and
   * Off() are shorthands for 1 and 0.
   * Meaning in full: itk::DeformableMeshFilter::SetTangentialDrift().
   */
  enum TangentialDriftModes
  {
    TANGENTIAL_DRIFT_KEEP = 0,
    TANGENTIAL_DRIFT_SUPPRESS = 1,
    TANGENTIAL_DRIFT_SUPPRESS_WHEN_REMESHING = 2
  };
  vtkSetClampMacro(TangentialDrift, int, TANGENTIAL_DRIFT_KEEP, TANGENTIAL_DRIFT_SUPPRESS_WHEN_REMESHING);
  vtkGetMacro(TangentialDrift, int);
  void
  SetTangentialDriftToKeep()
  {
    this->SetTangentialDrift(TANGENTIAL_DRIFT_KEEP);
  }
  void
  SetTangentialDriftToSuppress()
  {
    this->SetTangentialDrift(TANGENTIAL_DRIFT_SUPPRESS);
  }
  void
  SetTangentialDriftToSuppressWhenRemeshing()
  {
    this->SetTangentialDrift(TANGENTIAL_DRIFT_SUPPRESS_WHEN_REMESHING);
  }
  void
  SetSuppressTangentialDrift(vtkTypeBool suppress)
  {
    this->SetTangentialDrift(suppress ? TANGENTIAL_DRIFT_SUPPRESS : TANGENTIAL_DRIFT_KEEP);
  }
  void
  SuppressTangentialDriftOn()
  {
    this->SetSuppressTangentialDrift(1);
  }
  void
  SuppressTangentialDriftOff()
  {
    this->SetSuppressTangentialDrift(0);
  }
  ///@}

  ///@{
  /**
   * Reference edge length L: the edge length at which Elasticity and
   * Rigidity have their nominal weight; when positive the internal forces
   * are scaled by (L/h)^2 and (L/h)^4 (h the mesh's root mean square edge
   * length), so the same parameters give the same surface at any resolution
   * (with remeshing, typically RemeshingEdgeLength). 0: weights relative to
   * the mesh's own edges. Millimetres, at least 0; default 0.
   * Meaning in full: itk::DeformableMeshFilter::SetReferenceEdgeLength().
   */
  vtkSetClampMacro(ReferenceEdgeLength, double, 0.0, VTK_DOUBLE_MAX);
  vtkGetMacro(ReferenceEdgeLength, double);
  ///@}

  ///@{
  /**
   * No step lets the surface intersect itself: the displacements of the
   * vertices of triangles that would intersect, or come closer than
   * MinimumDistance, are halved, halved again, then zeroed; a remeshing that
   * would make contact leaves the contact's neighbourhood as it was. An
   * input that already intersects itself is an error (the first pair named).
   * Surfaces only (an error on 2-D contours). Default off.
   * Meaning in full: itk::DeformableMeshFilter::SetPreventSelfIntersections().
   */
  vtkSetMacro(PreventSelfIntersections, vtkTypeBool);
  vtkGetMacro(PreventSelfIntersections, vtkTypeBool);
  vtkBooleanMacro(PreventSelfIntersections, vtkTypeBool);
  ///@}

  ///@{
  /**
   * With PreventSelfIntersections: the smallest distance a step may leave
   * between two triangles sharing no vertex (0: intersection and contact
   * only); keep it below half the shortest edge. Millimetres, at least 0;
   * default 0.
   * Meaning in full: itk::DeformableMeshFilter::SetMinimumDistance().
   */
  vtkSetClampMacro(MinimumDistance, double, 0.0, VTK_DOUBLE_MAX);
  vtkGetMacro(MinimumDistance, double);
  ///@}

  ///@{
  /**
   * Keep the boundary of an open mesh at its input position, exactly: the
   * ends of open contours (2-D), the boundary of open surfaces and the ends
   * of lines (3-D). Off (default): they move like the other vertices, their
   * internal forces from their neighbours on one side only (a free open
   * contour shrinks along itself unless the image holds it). Closed contours
   * and surfaces have no boundary.
   * Meaning in full: itk::DeformableMeshFilter::SetFixedBoundary().
   */
  vtkSetMacro(FixedBoundary, vtkTypeBool);
  vtkGetMacro(FixedBoundary, vtkTypeBool);
  vtkBooleanMacro(FixedBoundary, vtkTypeBool);
  ///@}

  ///@{
  /**
   * Stop when the largest displacement stays below it for ConvergenceWindow
   * iterations; 0: never. Millimetres, at least 0; default 0.
   * Meaning in full: itk::DeformableMeshFilter::SetConvergenceTolerance().
   */
  vtkSetClampMacro(ConvergenceTolerance, double, 0.0, VTK_DOUBLE_MAX);
  vtkGetMacro(ConvergenceTolerance, double);
  ///@}

  ///@{
  /**
   * Consecutive iterations below ConvergenceTolerance that declare
   * convergence. At least 1; default 3.
   * Meaning in full: itk::DeformableMeshFilter::SetConvergenceWindow().
   */
  vtkSetClampMacro(ConvergenceWindow, int, 1, VTK_INT_MAX);
  vtkGetMacro(ConvergenceWindow, int);
  ///@}

  ///@{
  /**
   * With f > 0, an iteration is quiet when at most f x (number of points)
   * vertices move by ConvergenceTolerance or more (0: when none does). In
   * [0, 1]; default 0 (edmodel: 0.005).
   * Meaning in full: itk::DeformableMeshFilter::SetConvergenceFraction().
   */
  vtkSetClampMacro(ConvergenceFraction, double, 0.0, 1.0);
  vtkGetMacro(ConvergenceFraction, double);
  ///@}

  ///@{
  /**
   * The convergence test (tolerance, window, fraction) measures each
   * vertex's displacement along its normal: vertices that only slide along
   * the surface do not keep the model running. Default off.
   * Meaning in full: itk::DeformableMeshFilter::SetConvergenceAlongNormals().
   */
  vtkSetMacro(ConvergenceAlongNormals, vtkTypeBool);
  vtkGetMacro(ConvergenceAlongNormals, vtkTypeBool);
  vtkBooleanMacro(ConvergenceAlongNormals, vtkTypeBool);
  ///@}

  ///@{
  /**
   * Halve the step of a vertex whose displacement reverses its previous one
   * (x1.25 back toward the full step otherwise), so that vertices jumping
   * across a thin gap or a sharp crest of the force settle. Default off
   * (edmodel: on).
   * Meaning in full: itk::DeformableMeshFilter::SetDampOscillations().
   */
  vtkSetMacro(DampOscillations, vtkTypeBool);
  vtkGetMacro(DampOscillations, vtkTypeBool);
  vtkBooleanMacro(DampOscillations, vtkTypeBool);
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

  /**
   * With PreventSelfIntersections: the near-collisions handled since the
   * last restart (pairs of triangles found violating the constraint, summed
   * over the iterations).
   * Meaning in full: itk::DeformableMeshFilter::GetTotalNumberOfCollisionsPrevented().
   */
  vtkGetMacro(NumberOfCollisionsPrevented, vtkIdType);

  ///@{
  /**
   * 2-D: the closed and open contours found in the input at the last
   * restart (0 in 3-D).
   */
  vtkGetMacro(NumberOfClosedContours, int);
  vtkGetMacro(NumberOfOpenContours, int);
  ///@}

protected:
  vtkDeformableMesh();
  ~vtkDeformableMesh() override;

  int
  FillInputPortInformation(int port, vtkInformation * info) override;
  int
  RequestMeshDimension(vtkPolyData * input, vtkInformationVector ** inputVector) override;
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
  double      RemeshingEdgeLength = 0.0;
  int         RemeshingInterval = 10;
  int         TangentialDrift = TANGENTIAL_DRIFT_SUPPRESS_WHEN_REMESHING;
  double      RegionWeight = 0.0;
  double      RegionSigma = 1.0;
  double      EdgeSearchWeight = 0.0;
  double      EdgeSearchDistance = 2.0;
  double      IntensityTolerance = 2.2;
  vtkTypeBool EstimateBackgroundIntensity = 1;
  int         BackgroundUpdateInterval = 10;
  vtkTypeBool EstimateObjectIntensityRange = 1;
  double      ObjectIntensityRange[2] = { 0.0, 1.0 };
  int         EdgePolarity = 0;
  double      ReferenceEdgeLength = 0.0;
  vtkTypeBool ConvergenceAlongNormals = 0;
  vtkTypeBool PreventSelfIntersections = 0;
  double      MinimumDistance = 0.0;
  vtkTypeBool FixedBoundary = 0;
  double      ConvergenceTolerance = 0.0;
  int         ConvergenceWindow = 3;
  double      ConvergenceFraction = 0.0;
  vtkTypeBool DampOscillations = 0;
  vtkTypeBool ComputeDiagnostics = 1;
  vtkTypeBool Converged = 0;
  double      LastMaximumDisplacement = 0.0;
  vtkIdType   NumberOfCollisionsPrevented = 0;
  int         NumberOfClosedContours = 0;
  int         NumberOfOpenContours = 0;

  // The typed ITK filter and the converted force image.
  vtkDeformableMeshInternals * DeformableInternals;

private:
  vtkDeformableMesh(const vtkDeformableMesh &) = delete;
  void
  operator=(const vtkDeformableMesh &) = delete;
};

#endif
