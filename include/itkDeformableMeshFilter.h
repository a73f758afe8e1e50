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
#ifndef itkDeformableMeshFilter_h
#define itkDeformableMeshFilter_h

#include "itkIterativeMeshFilter.h"
#include "itkImage.h"
#include "itkDeformableMeshFilterDetail.h"
#include "itkDeformableMeshFilterEnums.h"
#include "itkDeformableMeshEdgeSearch.h"
#include "itkDeformableMeshRegionForce.h"
#include "itkDeformableMeshRemesher.h"
#include "itkForceImageCheck.h"
#include "itkSurfaceCollision.h"

#include <array>
#include <cstdint>
#include <vector>

namespace itk
{

/** \class DeformableMeshFilter
 * \brief Explicit deformable surface (3-D) or contour (2-D): the points of a
 * mesh move, iteration after iteration, under an external force field sampled
 * from an image and internal forces that keep the surface regular.
 *
 * At each iteration every vertex \f$ x_i \f$ moves by
 * \f[
 *   \Delta x_i = s\,F(x_i) + a\,E_i + b\,R_i + \beta\,n_i
 * \f]
 * where
 * - \f$ F \f$ is the force image sampled by trilinear (2-D: bilinear) interpolation at the
 *   physical position of the vertex (origin, spacing and direction of the
 *   image honoured; a vertex outside the image gets no external force),
 *   \f$ s \f$ the ScaleFactor;
 * - \f$ E_i = \bar{x}_{N(i)} - x_i \f$ is the elastic (membrane) force toward the
 *   centroid of the vertex's neighbours, projected on the tangent plane when
 *   TangentialElasticity is on, \f$ a \f$ the Elasticity;
 * - \f$ R_i = -(\overline{E}_{N(i)} - E_i) \f$ is the rigidity (bending) force,
 *   the negated umbrella operator applied twice, \f$ b \f$ the Rigidity;
 * - \f$ n_i \f$ is the outward unit vertex normal and \f$ \beta \f$ the Balloon
 *   (Cohen's inflation force).
 *
 * The neighbours come from the mesh's cells (edges of triangles, polygons, lines
 * and polylines); normals from its triangles and polygons (2-D: from the
 * contours' segments, see below). The explicit update
 * of the internal terms is stable when \f$ a + 2b \le 1 \f$; larger sums are
 * scaled down to 1 so that every valid parameter set gives a stable iteration.
 * MaximumStepLength, when positive, bounds the length of each vertex's
 * displacement per iteration.
 *
 * Resolution: \f$ E_i \f$ and \f$ R_i \f$ are umbrella operators of the mesh's
 * edges, about \f$ (h^2/4)\,\Delta x \f$ and \f$ -(h^4/16)\,\Delta^2 x \f$ on
 * edges of length \f$ h \f$ (\f$ \Delta x = -2Hn \f$, the mean curvature
 * vector): with the same Elasticity and Rigidity a finer mesh is much less
 * regularised. With ReferenceEdgeLength \f$ L > 0 \f$ (mm) they are weighted
 * by \f$ w = L^2 / \langle h^2 \rangle \f$ and \f$ w^2 \f$, \f$ \langle h^2
 * \rangle \f$ the mesh's mean squared edge length at the start of each
 * iteration (GetEdgeWeight()): curvature terms in physical units,
 * \f$ a (L^2/4) \Delta x \f$ and \f$ -b (L^4/16) \Delta^2 x \f$ mm per
 * iteration, which produce the same surface at any resolution, Elasticity
 * and Rigidity being the weights the terms have on a mesh of edge length L.
 * The explicit update then needs \f$ a w + 2 b w^2 \le 1 \f$: on edges
 * shorter than L an iteration is split into sub-steps of the internal forces
 * (about \f$ 2b(L/h)^4 \f$ of them; GetNumberOfSubSteps()), which costs time
 * but not accuracy; the external force and the balloon act once per
 * iteration, so the surface moves toward the object at the same speed at any
 * resolution. The weight is one for the whole mesh, not per vertex: the
 * umbrella operators are averages, so the bound then does not depend on the
 * shortest edges, which a deformation without remeshing shrinks to a
 * fraction of the mean (per-vertex weights would make the number of
 * sub-steps follow them); on a mesh of very uneven edge lengths the regions
 * of short edges are regularised less than the others. The balloon, ScaleFactor (with a normalised force field),
 * MaximumStepLength and ConvergenceTolerance are in mm per iteration and
 * mean the same at any resolution in both modes.
 *
 * With the output of ExternalForceImageFilter (normalised so that the largest
 * force has length 1), ScaleFactor is the largest external displacement per
 * iteration in physical units, whatever the intensity range of the image.
 *
 * Convergence: with ConvergenceTolerance > 0, the iteration stops when the
 * largest vertex displacement stays below the tolerance during
 * ConvergenceWindow consecutive iterations; GetConverged() then returns true
 * and CurrentIteration tells where it stopped. NumberOfIterations remains the
 * cap.
 *
 * Oscillation damping (DampOscillations, off by default): an explicit step
 * overshoots where a force changes direction within less than a step (a thin
 * gap between two structures, a sharp crest of the force field, a vertex
 * whose normal flips as it crosses the plane of its neighbours); such a
 * vertex then jumps back and forth by the step bound for ever, and the
 * largest displacement never falls below ConvergenceTolerance. With the
 * damping on, each vertex keeps a step factor in [1/1024, 1]: a displacement
 * that reverses the vertex's previous one (an angle above 120 degrees)
 * halves it, any other displacement multiplies it by 1.25, and the vertex
 * moves by the factor times its displacement. A vertex that moves steadily
 * keeps the factor 1 (its motion is unchanged); an oscillating one settles
 * where the force changes sign. GetNumberOfDampedVertices() gives the
 * reversals of the last iteration.
 *
 * The step runs on flat arrays unpacked once in Reset(): coordinates and a CSR
 * vertex-neighbour table in which the neighbours of a vertex whose triangles
 * form one fan are stored in fan order, so that the same loads give its
 * umbrella vector and its normal (sum of (x_j - x_i) x (x_j+1 - x_i)); other
 * vertices (polygons, lines, non-manifold fans) keep their triangles in a side
 * table. The force image is read through its buffer with the
 * physical-to-index transform precomputed. The arithmetic works on 3-D vectors
 * held in 4 lanes. The kernels (itkDeformableMeshFilterKernels.h) are compiled
 * for AVX2 with FMA, for SSE2 and in plain C++ in one binary, whatever the
 * compile flags; the fastest one the processor runs is chosen at run time
 * (the environment variable EDM_KERNEL_PATH, avx2, sse2 or portable, forces
 * one). With rigidity, a first pass stores the umbrella vectors and normals
 * in single precision, the second computes the displacements. Vertices are
 * processed in fixed blocks over threads, so the output is bit-for-bit
 * identical whatever the number of threads.
 *
 * Per-vertex diagnostics of the last iteration of an update (displacement
 * length, external and internal force lengths, physical units) are available
 * with GetDisplacementMagnitudes(), GetExternalForceMagnitudes() and
 * GetInternalForceMagnitudes().
 *
 * Adaptive remeshing (RemeshingEdgeLength > 0): after the step of every
 * RemeshingInterval-th iteration, DeformableMeshRemesher brings the edge
 * lengths into [4/5, 4/3] x RemeshingEdgeLength (splits, collapses, flips
 * toward valence 6, tangential relaxation) on the step's flat arrays, and
 * the step's tables are rebuilt. The output then has the remeshed points and
 * one TriangleCell per triangle, no point or cell data (see
 * IterativeMeshFilter); the iteration contract holds as before
 * (CurrentIteration, continuation with IterateFromZero off, abort, restart,
 * IterationEvent with the current mesh, diagnostics sized to the current
 * mesh). Remeshing needs a mesh of triangles only (an input with other cells
 * is refused with an ExceptionObject at the first update); boundary edges are
 * split but kept, non-manifold parts left alone (DeformableMeshRemesher).
 * The balloon's per-vertex release and the diagnostics of a new vertex are
 * those of its parent vertex. Once the surface rests on the object, the
 * force's tangential part keeps its vertices flowing along it, and every
 * remeshing splits and collapses edges where they leave and gather: with
 * remeshing the filter suppresses that flow by default (TangentialDrift).
 *
 * Renumbering: at each reset, an input whose numbering is not local (more
 * than a tenth of its edges join points numbered more than 2048 apart, as in
 * itk::RegularSphereMeshSource's subdivisions) is renumbered internally
 * along a Morton curve of its positions, so that the step's speed does not
 * depend on the input's numbering; the output keeps the input's numbering
 * and the diagnostics are indexed by the input's point identifiers. A
 * remeshing keeps the numbering of the points it keeps and numbers each new
 * point after the one it comes from (DeformableMeshRemesher); after many
 * operations (a surface that travelled far from its start, a tenth of the
 * points split or collapsed since the last renumbering), at a remeshing that
 * changed at most a twentieth of the points (one that replaces a third of
 * them, as while a sphere travels to the object, would scramble a new
 * numbering at once) or once the operations exceed twice the points, the
 * remeshed mesh is renumbered breadth-first along its edges
 * (DeformableMeshRemesher::OutputBreadthFirstOrder()), and its triangles
 * reordered by their smallest point
 * (DeformableMeshRemesher::RenumberOutput()): the step's neighbour
 * reads, and the scans of the triangles by the collision test and the next
 * remeshing, stay in the caches (measured: 20 steps on the 1M-point
 * benchmark surface at rest, remeshed from a sphere, 342 to 493 ms as the
 * remeshings left it, 274 to 337 ms renumbered, 240 to 322 ms on the
 * sphere). The output is the renumbered mesh;
 * GetNumberOfLocalityRenumberings() counts them.
 *
 * 2-D contours (snakes): with an itk::Mesh of 2-D points and a 2-D force
 * image (vectors of 2 components, e.g. ExternalForceImageFilter on a 2-D
 * image), the filter deforms contours by the same step: the points are held
 * as (x, y, 0), the force image is sampled bilinearly in physical space
 * (origin, spacing and direction honoured), and the umbrella vector of a
 * point is the mean of its two neighbours minus the point. A contour is made
 * of LineCell cells (one segment each, chained into open or closed contours)
 * or of PolygonCell cells (one closed contour each, its points in order; ITK
 * 5.2 has no polyline cell); a mesh may hold several. The normal of a point
 * is the perpendicular of its tangent: for the segments p -> x -> q,
 * (q - p) x z, normalised, on the right of the direction of travel.
 * Orientation convention: each closed contour is oriented at reset so that
 * it runs counter-clockwise (positive signed area, with x to the right and y
 * up), whatever the order of its points in the input, so its normals point
 * away from the region it encloses: the balloon inflates every closed
 * contour, and the region force takes its inside as the object. An open
 * contour keeps the direction of its points (chained from the end whose
 * segment leaves it); its normals are on the right of that direction, and
 * since an open contour encloses nothing, Balloon and RegionWeight raise an
 * ExceptionObject with an open contour in the mesh. Where contours branch (a
 * point of more than two segments) the segments keep the input's direction
 * and the normal is the sum of theirs. Everything else is as in 3-D:
 * elasticity (tangential or not), rigidity, ReferenceEdgeLength (on a
 * contour the umbrella vector is about (h^2/2) times the curvature vector,
 * so the weights mean the same at any resolution, but with h^2/2 and
 * h^4/4 in place of the surface's h^2/4 and h^4/16), balloon, region force
 * and edge search (IntensityImageType is then a 2-D image, smoothed in 2-D),
 * MaximumStepLength, convergence, diagnostics, FixedBoundary and the
 * iteration contract. PreventSelfIntersections and RemeshingEdgeLength work
 * on the triangles of 3-D surfaces: turned on with a 2-D mesh, the update
 * raises an ExceptionObject naming the parameter. So do a triangle or
 * quadrilateral cell in a 2-D mesh, a contour of fewer than 2 distinct
 * points (a vertex cell, a line from a point to itself) and a polygon cell
 * of fewer than 3. A force image whose dimension is not the mesh's does not
 * compile.
 *
 * Open meshes: the ends of an open contour and the boundary of an open
 * surface (edges of one triangle) move like the other vertices by default,
 * their umbrella vectors taken over their one-sided neighbourhoods (so the
 * elastic force pulls them inward and a free open surface shrinks along its
 * rim), or keep their input position exactly with FixedBoundary on.
 *
 * \sa ExternalForceImageFilter, IterativeMeshFilter
 * \ingroup ExplicitDeformableModel
 */
template <typename TMesh, typename TForceImage>
class ITK_TEMPLATE_EXPORT DeformableMeshFilter : public IterativeMeshFilter<TMesh, TMesh>
{
public:
  ITK_DISALLOW_COPY_AND_MOVE(DeformableMeshFilter);

  /** Standard class type aliases. */
  using Self = DeformableMeshFilter;
  using Superclass = IterativeMeshFilter<TMesh, TMesh>;
  using Pointer = SmartPointer<Self>;
  using ConstPointer = SmartPointer<const Self>;

  /** Method for creation through the object factory. */
  itkNewMacro(Self);

  /** Run-time type information (and related methods). */
  itkOverrideGetNameOfClassMacro(DeformableMeshFilter);

  using MeshType = TMesh;
  using ForceImageType = TForceImage;
  using ForcePixelType = typename ForceImageType::PixelType;

  static constexpr unsigned int PointDimension = Superclass::PointDimension;
  static_assert(PointDimension == 2 || PointDimension == 3,
                "DeformableMeshFilter deforms 3-D surfaces and 2-D contours.");
  static_assert(ForceImageType::ImageDimension == PointDimension,
                "The force image must have the dimension of the mesh's points.");
  static_assert(ForcePixelType::Dimension == PointDimension,
                "The force image pixels must have as many components as the mesh's points.");

  /** The external force field: an image of vectors of the mesh's dimension
   * (itk::Vector or itk::CovariantVector, float or double; 3-D for a
   * surface, 2-D for contours) expressed in physical space, for example the
   * output of ExternalForceImageFilter. Required. */
  itkSetInputMacro(ForceImage, ForceImageType);
  itkGetInputMacro(ForceImage, ForceImageType);

  /** Weight s of the external force: a vertex moves by s times the sampled
   * force per iteration. With a force field normalised to a largest length of 1
   * (ExternalForceImageFilter's default), s is the largest external
   * displacement per iteration in physical units; keep it below the smoothing
   * scale of the force field for a smooth approach (about half of it).
   * Must be finite. Default: 1.0. */
  itkSetMacro(ScaleFactor, double);
  itkGetConstMacro(ScaleFactor, double);

  /** Weight a of the elastic (membrane, first order) internal force, pulling
   * each vertex toward the centroid of its neighbours. Dimensionless, in
   * [0, 1]: 1 moves a vertex onto the centroid in one iteration. Default: 0
   * (vertices move independently, as in the seed's deformable mesh). */
  itkSetMacro(Elasticity, double);
  itkGetConstMacro(Elasticity, double);

  /** When on (default), the elastic force keeps only its component tangent to
   * the surface: it regularises the distribution of the vertices without
   * shrinking the surface. When off, the full umbrella operator is used
   * (Laplacian smoothing, which also shrinks convex surfaces). */
  itkSetMacro(TangentialElasticity, bool);
  itkGetConstMacro(TangentialElasticity, bool);
  itkBooleanMacro(TangentialElasticity);

  using TangentialDriftEnum = DeformableMeshFilterEnums::TangentialDrift;

  /** What becomes of the external force's component tangent to the surface
   * where the surface has come to rest. Suppressed, it is dropped where the
   * external displacement (ScaleFactor times the force) is shorter than an
   * eighth of the mesh's root mean square edge length h: the vertex moves
   * along its normal only; between h/8 and h/4 the tangential component is
   * blended back in (its weight rises linearly from 0 to 1); beyond h/4 the
   * force acts whole. Kept, the force acts whole everywhere.
   * Default: TangentialDriftEnum::SuppressWhenRemeshing, suppressed when the
   * filter remeshes (RemeshingEdgeLength > 0), kept otherwise.
   *
   * Why suppress: a force field's tangential component moves vertices along
   * the surface without changing its shape. Where the surface has converged
   * it does not vanish (the surface rests where the force's normal part
   * balances the internal forces, off the force field's zero set), so the
   * vertices flow along the surface for ever, toward where the field's
   * tangential part converges; with remeshing this flow is cut into splits
   * and collapses at every remeshing. On the benchmarks' ellipsoid at rest,
   * with remeshing every 10 iterations, 2 to 7 % of the points went through
   * the remesher at every remeshing (the share grows as the edges shrink:
   * the flow is in mm per iteration); suppressed, 0.1 to 0.6 %, and the
   * surface is the same (docs/performance.md). Far from the object the
   * step is long against the edges and the field moves neighbouring vertices
   * together; there the normal alone would not (neighbouring normals differ,
   * and long steps along them fold a fine mesh: with the bounds at h/4 and
   * h/2 the benchmark's 1M sphere came close to itself while it travelled),
   * hence the whole force beyond h/4.
   *
   * Why not without remeshing by default: a mesh that cannot gain vertices
   * needs that flow to bring them where the surface bends most. On the seed
   * paper's anisotropic ellipsoid without remeshing, suppressing it raised
   * the largest distance to the surface from 0.52 to 0.70 voxel (balloon)
   * and from 0.59 to 0.77 voxel (gradient vector flow); with remeshing the
   * elongated ellipsoid's surface is the same either way (mean distance
   * 0.118 voxel). GetExternalForceMagnitudes() gives the external force as
   * applied, its tangential part dropped or weighted. */
  itkSetEnumMacro(TangentialDrift, TangentialDriftEnum);
  itkGetEnumMacro(TangentialDrift, TangentialDriftEnum);

  /** Shorthand for TangentialDrift: on sets Suppress, off sets Keep. */
  virtual void
  SetSuppressTangentialDrift(bool suppress)
  {
    this->SetTangentialDrift(suppress ? TangentialDriftEnum::Suppress : TangentialDriftEnum::Keep);
  }
  virtual void
  SuppressTangentialDriftOn()
  {
    this->SetSuppressTangentialDrift(true);
  }
  virtual void
  SuppressTangentialDriftOff()
  {
    this->SetSuppressTangentialDrift(false);
  }

  /** Whether the tangential drift is suppressed with the current parameters:
   * TangentialDrift is Suppress, or SuppressWhenRemeshing with
   * RemeshingEdgeLength > 0. */
  bool
  GetSuppressTangentialDrift() const
  {
    return m_TangentialDrift == TangentialDriftEnum::Suppress ||
           (m_TangentialDrift == TangentialDriftEnum::SuppressWhenRemeshing && m_RemeshingEdgeLength > 0.0);
  }

  /** Weight b of the rigidity (bending, second order) internal force, the
   * umbrella operator applied twice: it penalises changes of curvature and
   * leaves a sphere unchanged. Dimensionless, in [0, 0.5] for stability on its
   * own; a + 2b above 1 is scaled down to 1. Default: 0. */
  itkSetMacro(Rigidity, double);
  itkGetConstMacro(Rigidity, double);

  /** Balloon (inflation) force: displacement along the outward unit vertex
   * normal per iteration, in physical units. Positive inflates, negative
   * deflates. "Outward" is decided from the signed volume of the mesh, so an
   * inward-oriented closed mesh behaves the same as an outward-oriented one.
   * The balloon carries each vertex to an edge: once the external force
   * opposes it with at least half its strength (the vertex has reached the
   * edge's capture range), it is released for that vertex until the next
   * reset, so that the vertex settles on the edge rather than where the two
   * forces balance. Half, not any opposing force, so that noise far from the
   * edge does not stop the inflation.
   * Must be finite. Default: 0. */
  itkSetMacro(Balloon, double);
  itkGetConstMacro(Balloon, double);

  /** The intensity image of the region force: a scalar image of the mesh's
   * dimension in the same physical space as the force image (typically the
   * image the force field was computed from). Optional; needed when
   * RegionWeight > 0. */
  using IntensityImageType = Image<float, PointDimension>;
  itkSetInputMacro(IntensityImage, IntensityImageType);
  itkGetInputMacro(IntensityImage, IntensityImageType);

  /** Weight of the region force, the largest outward (inflation) or inward
   * (deflation) displacement per iteration it gives, in physical units (mm).
   * Each vertex inflates where the intensity at its position (the intensity
   * image smoothed by RegionSigma) lies inside the object's intensity range
   * and deflates where it lies outside, in proportion to its margin from the
   * range's bounds (DeformableMeshFilterDetail::RegionForce), so that the
   * surface settles on the iso-surface of the bound that separates the object
   * from its surroundings and stays there whatever the number of iterations:
   * unlike the balloon, it needs no edge to stop it. A vertex outside the
   * image deflates. The transition width is at least RegionWeight times the
   * 99th percentile of the smoothed intensity's gradient magnitude (per mm),
   * so that a vertex on a steep edge does not step past the bound: the
   * region term converges for any weight, and near the boundary it behaves
   * the same for weights above that (RegionForce::SetMinimumWidth()).
   * Non-negative; 0 turns the region force off. Default: 0. */
  itkSetMacro(RegionWeight, double);
  itkGetConstMacro(RegionWeight, double);

  /** Standard deviation of the Gaussian smoothing of the intensity image for
   * the region force, physical units (mm): thin dark or bright structures
   * narrower than about 2 sigma (sulci, vessels, noise) no longer stop the
   * surface. The Gaussian is that of ExternalForceImageFilter (sampled,
   * truncated at 4 sigma, border pixels repeated:
   * itkSampledGaussianSmoothing.h). The smoothed image and its statistics are
   * kept until the intensity image or RegionSigma changes, also from one
   * input mesh to the next (a coarse-to-fine schedule can reuse one filter).
   * 0: no smoothing. Non-negative. Default: 1. */
  itkSetMacro(RegionSigma, double);
  itkGetConstMacro(RegionSigma, double);

  /** Half-width of the object's intensity class in robust standard
   * deviations of the object's intensities, when the object's model is
   * estimated (EstimateObjectIntensityRange on) or given by
   * SetObjectIntensityStatistics(): the class is median +- IntensityTolerance
   * x 1.4826 x MAD, or, for a piecewise constant object (that half-width
   * below a fifth of the image's intensity range), halfway to the image's
   * other extreme (RegionForce::SetModel()). The class is the range until
   * the surface reaches the background (EstimateBackgroundIntensity); it also
   * separates the background's samples from the object's. Positive. Default:
   * 2.2. */
  itkSetMacro(IntensityTolerance, double);
  itkGetConstMacro(IntensityTolerance, double);

  /** When on (default), the object's model is estimated at each reset from
   * the interior of the input (initial) surface: the median and robust
   * spread of intensities sampled between 10 % and 60 % of the way from each
   * vertex toward the vertices' centroid, so a surface that is star-shaped
   * around its centroid and lies inside the object samples the object only.
   * When off, the model given by SetObjectIntensityStatistics() or the range
   * given by SetObjectIntensityRange() is used. */
  itkSetMacro(EstimateObjectIntensityRange, bool);
  itkGetConstMacro(EstimateObjectIntensityRange, bool);
  itkBooleanMacro(EstimateObjectIntensityRange);

  /** When on (default), with an estimated or given object model (not with a
   * given range), the bounds of the range follow the background: every
   * BackgroundUpdateInterval iterations, intensities are sampled 1 to 4
   * voxels (of the intensity image's smallest spacing) outside each vertex
   * along its normal; those below the object's class form the dark
   * background, those above it the bright one, and a background holding at
   * least 5 % of the samples moves its bound to halfway between the object's
   * median and its own (RegionForce::AdaptToBackground()): the boundary of
   * the two classes, where a blurred edge between them is steepest. Until
   * the surface reaches a background, its bound stays at the class's. */
  itkSetMacro(EstimateBackgroundIntensity, bool);
  itkGetConstMacro(EstimateBackgroundIntensity, bool);
  itkBooleanMacro(EstimateBackgroundIntensity);

  /** Iterations between two estimates of the background (>= 1). Default: 10. */
  itkSetMacro(BackgroundUpdateInterval, unsigned int);
  itkGetConstMacro(BackgroundUpdateInterval, unsigned int);

  /** The object's intensity range [lower, upper] for the region force, in the
   * intensity image's units, and the transition width (intensity units, > 0)
   * over which the speed goes from full deflation to full inflation, fixed
   * (no background estimate). Turns EstimateObjectIntensityRange off. For a
   * bright object on a dark background give an upper bound above the image's
   * maximum. */
  void
  SetObjectIntensityRange(double lower, double upper, double width)
  {
    m_ObjectIntensityLower = lower;
    m_ObjectIntensityUpper = upper;
    m_ObjectIntensityWidth = width;
    m_EstimateObjectIntensityRange = false;
    m_ObjectIntensityStatisticsGiven = false;
    this->Modified();
  }
  /** The object's model as the median and robust spread (standard deviation
   * units, >= 0) of its intensities, in the intensity image's units, for
   * instance those estimated by an earlier run (GetObjectIntensityMedian(),
   * GetObjectIntensitySpread()): the range follows from them as when they are
   * estimated (IntensityTolerance, EstimateBackgroundIntensity). Turns
   * EstimateObjectIntensityRange off. */
  void
  SetObjectIntensityStatistics(double median, double spread)
  {
    m_ObjectIntensityMedian = median;
    m_ObjectIntensitySpread = spread;
    m_EstimateObjectIntensityRange = false;
    m_ObjectIntensityStatisticsGiven = true;
    this->Modified();
  }
  /** The range in use: as set, or as estimated (at the last reset, and from
   * the background at the last iteration). */
  itkGetConstMacro(ObjectIntensityLower, double);
  itkGetConstMacro(ObjectIntensityUpper, double);
  itkGetConstMacro(ObjectIntensityWidth, double);
  /** The object's model: as set, or as estimated at the last reset. */
  itkGetConstMacro(ObjectIntensityMedian, double);
  itkGetConstMacro(ObjectIntensitySpread, double);

  /** Weight of the edge search, the largest displacement per iteration
   * (mm) it gives along the normal. For each vertex, the intensity profile
   * along its unit normal (the intensity image smoothed by RegionSigma,
   * sampled every half voxel from -EdgeSearchDistance to
   * +EdgeSearchDistance) is searched for the strongest edge of the expected
   * polarity (EdgePolarity) whose contrast, one voxel on each side, is at
   * least the object's robust standard deviation (DeformableMeshFilterDetail::
   * EdgeSearch); the hit is the median of the vertex's and its neighbours'
   * hits (more than half of them must have found an edge), and the vertex
   * moves toward it by EdgeSearchWeight x clamp(hit / voxel, -1, 1): at full
   * weight beyond one voxel (the smallest spacing of the intensity image),
   * in proportion closer, so that it settles on the edge. It adds to the
   * region force, which brings the surface within the search distance; on
   * its own (RegionWeight 0) the object's model is still estimated for the
   * polarity and the contrast. Keep it below one voxel per iteration.
   * Non-negative; 0 turns the edge search off. Default: 0. */
  itkSetMacro(EdgeSearchWeight, double);
  itkGetConstMacro(EdgeSearchWeight, double);

  /** Half-length of the edge search's profile along the normal, physical
   * units (mm): the capture range of the edge search on each side of the
   * surface (at most 64 half-voxel steps are taken). Positive. Default: 2. */
  itkSetMacro(EdgeSearchDistance, double);
  itkGetConstMacro(EdgeSearchDistance, double);

  /** The edges the edge search looks for: +1 where the intensity falls
   * outward (an object brighter than its surroundings), -1 where it rises (a
   * darker object), 0 (default) from the intensity model: the side of the
   * object's class where the background's samples lie
   * (EstimateBackgroundIntensity), or before any background estimate the
   * side of the image's intensity range farther from the object's median. */
  itkSetClampMacro(EdgePolarity, int, -1, 1);
  itkGetConstMacro(EdgePolarity, int);

  /** Vertices that felt the edge search's force at the last iteration. */
  itkGetConstMacro(NumberOfEdgeHits, SizeValueType);

  /** Reference edge length L, physical units (mm): the edge length at which
   * Elasticity and Rigidity have their nominal weight. When positive the
   * internal forces are scaled at each vertex by (L/h)^2 (elasticity) and
   * (L/h)^4 (rigidity),
   * so that the same parameters produce the same surface whatever the mesh's
   * resolution (h the mesh's root mean square edge length at each
   * iteration); an iteration on edges shorter than L is split into
   * sub-steps of the internal forces (see the class documentation and
   * GetNumberOfSubSteps()). Typically the target edge length of the mesh
   * (for example the voxel size). 0: no scaling, the weights are relative to
   * the mesh's own edges (the established behaviour, which depends on the
   * resolution). Must be finite and non-negative. Default: 0. */
  itkSetMacro(ReferenceEdgeLength, double);
  itkGetConstMacro(ReferenceEdgeLength, double);

  /** Largest number of sub-steps of the internal forces an iteration may
   * take with ReferenceEdgeLength > 0; an update that would need more stops
   * with an exception saying so (a reference length far above the mesh's
   * edge lengths). At least 1. Default: 1000. */
  itkSetClampMacro(MaximumNumberOfSubSteps, unsigned int, 1, NumericTraits<unsigned int>::max());
  itkGetConstMacro(MaximumNumberOfSubSteps, unsigned int);

  /** Sub-steps of the internal forces at the last iteration: 1 without
   * ReferenceEdgeLength, else the smallest m >= 1 with
   * (a w + 2 b w^2) / m <= 1. */
  itkGetConstMacro(NumberOfSubSteps, unsigned int);

  /** Edge weight w = (L / h)^2 of the last iteration, h the root mean square
   * edge length of the mesh at its start: the factor applied to Elasticity
   * (w^2 to Rigidity). 1 without ReferenceEdgeLength. */
  itkGetConstMacro(EdgeWeight, double);

  /** Upper bound on the length of a vertex's displacement per iteration, in
   * physical units (per sub-step when an iteration has several, see
   * ReferenceEdgeLength); 0 means no bound. Useful with raw (unnormalised)
   * force fields. Must be finite and non-negative. Default: 0. */
  itkSetMacro(MaximumStepLength, double);
  itkGetConstMacro(MaximumStepLength, double);

  /** Convergence threshold on the largest vertex displacement of an
   * iteration, in physical units; 0 disables convergence detection.
   * Must be finite and non-negative. Default: 0. */
  itkSetMacro(ConvergenceTolerance, double);
  itkGetConstMacro(ConvergenceTolerance, double);

  /** Number of consecutive iterations whose largest displacement must stay
   * below ConvergenceTolerance to declare convergence. At least 1.
   * Default: 3. */
  itkSetClampMacro(ConvergenceWindow, unsigned int, 1, NumericTraits<unsigned int>::max());
  itkGetConstMacro(ConvergenceWindow, unsigned int);

  /** With ConvergenceFraction f > 0, an iteration is quiet when at most
   * f x (number of points) vertices move by ConvergenceTolerance or more
   * (0: when no vertex does, the largest displacement below the tolerance).
   * A few vertices that keep creeping (into a narrow cleft, along a thin
   * structure) then do not hold the whole surface. [0, 1), default 0. */
  itkSetClampMacro(ConvergenceFraction, double, 0.0, 1.0);
  itkGetConstMacro(ConvergenceFraction, double);

  /** When on, the convergence test (ConvergenceTolerance, ConvergenceWindow,
   * ConvergenceFraction, NumberOfActiveVertices) measures each vertex's
   * displacement along its unit normal (the normal at the start of the
   * iteration) instead of its whole displacement: vertices that only slide
   * along the surface, such as a contour's points that TangentialElasticity
   * spaces evenly after the shape has settled, do not keep the filter
   * running, since the shape they describe no longer changes. The geometry
   * pass then stores the normals whatever the other terms.
   * LastMaximumDisplacement remains the whole displacement. Default: off. */
  itkSetMacro(ConvergenceAlongNormals, bool);
  itkGetConstMacro(ConvergenceAlongNormals, bool);
  itkBooleanMacro(ConvergenceAlongNormals);

  /** Vertices that moved by ConvergenceTolerance or more in the last
   * iteration (along their normals with ConvergenceAlongNormals; counted
   * when ConvergenceFraction > 0, DampOscillations or ConvergenceAlongNormals
   * is on; 0 otherwise). */
  itkGetConstMacro(NumberOfActiveVertices, SizeValueType);

  /** When on, no step makes the surface intersect itself: after each step
   * the pairs of triangles sharing no vertex whose new positions intersect,
   * or come closer than MinimumDistance (and closer than before the step),
   * are found with a spatial index (SurfaceCollision), and the displacements
   * of their vertices are halved, halved again, then set to zero, until
   * every pair is clear. Since a step from a state without intersection
   * with every displacement zero is that state, every iteration's mesh is
   * free of intersections. At each reset the input mesh is checked: an input
   * that already intersects itself is rejected with an ExceptionObject naming
   * the first intersecting pair of triangles (and their cells). Triangles
   * and polygons (fan-triangulated) take part; lines do not. Only the
   * positions are checked, not the paths between them (a front can skip
   * across a gap narrower than its step; MinimumDistance above the largest
   * step makes that impossible). With adaptive remeshing
   * (RemeshingEdgeLength > 0) the remeshed surface is checked too: the
   * pairs that a remeshing would bring into contact (sharing no vertex and
   * closer than MinimumDistance or intersecting, or sharing one vertex and
   * folded into each other) have the points of their triangles and the
   * neighbours of those points locked (DeformableMeshRemesher's
   * SetLockedVertices()), and the remeshing is made again from the same
   * surface, until it brings no pair into contact; the locked points of the
   * last remeshing are counted by GetNumberOfPointsLockedByRemeshing().
   * Default: off (results and speed of the step
   * exactly as without it; the test costs a pass over the vertices and one
   * over the triangles per iteration on a surface that has settled, more
   * where it moves fast). */
  itkSetMacro(PreventSelfIntersections, bool);
  itkGetConstMacro(PreventSelfIntersections, bool);
  itkBooleanMacro(PreventSelfIntersections);

  /** Smallest distance between two triangles sharing no vertex that a step
   * may create when PreventSelfIntersections is on, physical units (mm).
   * Pairs already closer (in the input, or brought closer by a change of
   * parameters) may stay so but do not come closer. 0 prevents intersections
   * and contact only (closer than 1e-6 of the mean edge length counts as
   * contact). Keep it below about half the shortest edge length: triangles of
   * one sheet that share no vertex are about an edge length apart, and
   * would stiffen the surface. Must be finite and non-negative. Default: 0. */
  itkSetMacro(MinimumDistance, double);
  itkGetConstMacro(MinimumDistance, double);

  /** Contact memory, with PreventSelfIntersections: a vertex whose
   * displacement the collision test reduced moves, at the next iterations,
   * by a fraction of the displacement the step proposes: the fraction the
   * test let it keep (1/2, 1/4 or 0, times its previous fraction), doubled
   * at each iteration in which the test does not reduce it again (from 1/8
   * when it was 0) until it is 1. A front that the forces keep pushing
   * against another then proposes little into it, and the test does not
   * halve the whole contact zone again at every iteration: on the ch2bet
   * brain with a wide contact (edmodel --sigma 2) the finest level took half
   * the time, with the same accuracy. The test still decides every step, so
   * the guarantee (no intersection, MinimumDistance) is the same. Reset and
   * remeshing: a new vertex takes its parent's fraction. Default: on. */
  itkSetMacro(RememberContacts, bool);
  itkGetConstMacro(RememberContacts, bool);
  itkBooleanMacro(RememberContacts);

  /** Per-vertex damping of displacements that reverse the previous one
   * (see the class documentation). Off by default. */
  itkSetMacro(DampOscillations, bool);
  itkGetConstMacro(DampOscillations, bool);
  itkBooleanMacro(DampOscillations);

  /** Vertices whose displacement reversed their previous one in the last
   * iteration (DampOscillations on; 0 otherwise). */
  itkGetConstMacro(NumberOfDampedVertices, SizeValueType);

  /** Near-collisions handled by PreventSelfIntersections: pairs of
   * triangles found violating the constraint in the last iteration (each
   * time one is found: a pair still violating after its displacements were
   * halved counts again), the same summed over the iterations since the last
   * reset, and the vertices whose displacement the last iteration reduced
   * (by the test, or by RememberContacts). */
  itkGetConstMacro(NumberOfCollisionsPrevented, SizeValueType);
  itkGetConstMacro(TotalNumberOfCollisionsPrevented, SizeValueType);
  itkGetConstMacro(NumberOfConstrainedVertices, SizeValueType);

  /** How the collision test went since the filter was made: the steps
   * (and remeshings) whose positions the star-shaped certificate accepted
   * without the index, and the times the index over the triangles was built
   * (see SurfaceCollision). */
  SizeValueType
  GetNumberOfCertifiedSteps() const
  {
    return m_Collision.GetTotalNumberOfCertifiedSteps();
  }
  /** Of those, the steps certified by the margin carried from an earlier
   * certificate (SurfaceCollision::CarryCertificate()): a pass over the
   * points instead of the certificate's passes, and when a few points have
   * left the margin, exact signs for the triangles around them
   * (SurfaceCollision::CarriedTo()). */
  SizeValueType
  GetNumberOfCarriedCertificates() const
  {
    return m_Collision.GetTotalNumberOfCarriedCertificates();
  }
  /** How many times a point that had left a carried certificate's margin
   * was found within its own (the least own margin of its triangles), so
   * that its triangles needed no test: after a remeshing, where the
   * filter's rings lead to them (SurfaceCollision::SetPointFans()). */
  SizeValueType
  GetNumberOfPointsWithinOwnCarriedMargin() const
  {
    return m_Collision.GetTotalNumberOfPointsWithinOwnMargin();
  }
  SizeValueType
  GetNumberOfCollisionIndexRebuilds() const
  {
    return m_Collision.GetTotalNumberOfRebuilds();
  }

  /** True when the last update stopped because of convergence. */
  itkGetConstMacro(Converged, bool);

  /** Largest vertex displacement of the last iteration, physical units. */
  itkGetConstMacro(LastMaximumDisplacement, double);

  /** Per-vertex diagnostics of the last iteration, indexed by point
   * identifier, physical units: displacement length, external force
   * contribution s|F| and internal force contribution |aE + bR| (with
   * sub-steps: the whole iteration's displacement, and the internal force
   * per iteration at the last sub-step). Empty before
   * the first iteration. They are computed at the iterations that may end an
   * update (the last one scheduled, one that can complete convergence) and at
   * every iteration when the filter has an IterationEvent or ProgressEvent
   * observer; an update stopped otherwise (AbortGenerateData set by another
   * thread) leaves those of an earlier iteration. */
  const std::vector<float> &
  GetDisplacementMagnitudes() const
  {
    return this->GetOutputPointIdentifiers().empty() ? m_DisplacementMagnitudes : m_PublicDisplacementMagnitudes;
  }
  const std::vector<float> &
  GetExternalForceMagnitudes() const
  {
    return this->GetOutputPointIdentifiers().empty() ? m_ExternalForceMagnitudes : m_PublicExternalForceMagnitudes;
  }
  const std::vector<float> &
  GetInternalForceMagnitudes() const
  {
    return this->GetOutputPointIdentifiers().empty() ? m_InternalForceMagnitudes : m_PublicInternalForceMagnitudes;
  }

  /** Target edge length of the adaptive remeshing, physical units (mm):
   * every RemeshingInterval iterations the edges are brought into
   * [4/5, 4/3] times this length. 0 turns remeshing off: the mesh keeps the
   * input's points and cells. Must be finite and non-negative. Default: 0.
   * The first remeshing after a reset flips and relaxes the whole mesh; the
   * later ones, incrementally (DeformableMeshRemesher::SetIncremental()),
   * only around the points whose triangles the remeshings changed: between
   * two remeshings, the internal forces keep the points spread along the
   * surface elsewhere. */
  itkSetMacro(RemeshingEdgeLength, double);
  itkGetConstMacro(RemeshingEdgeLength, double);

  /** Number of iterations between two remeshings (the mesh is remeshed after
   * iterations K, 2K, ...). At least 1. Default: 10. */
  itkSetMacro(RemeshingInterval, unsigned int);
  itkGetConstMacro(RemeshingInterval, unsigned int);

  /** Number of remeshings since the last reset. */
  itkGetConstMacro(NumberOfRemeshings, SizeValueType);

  /** The operations of the remeshings since the last reset, summed: edges
   * split, collapsed and flipped, and vertices moved by the relaxation
   * (DeformableMeshRemesher::Statistics; of a remeshing made again with
   * points locked, the one kept). How much of the mesh each remeshing
   * rebuilds: on a surface at rest few edges leave the band between two
   * remeshings, on one whose vertices drift along it many do. */
  using RemeshingStatisticsType = DeformableMeshRemesher::Statistics;
  itkGetConstReferenceMacro(RemeshingStatistics, RemeshingStatisticsType);

  /** Points that the last remeshing left as they were because remeshing
   * their neighbourhood brought the surface into contact with itself
   * (PreventSelfIntersections on; see there). 0 when nothing was locked. */
  itkGetConstMacro(NumberOfPointsLockedByRemeshing, SizeValueType);

  /** When on (default), an input whose numbering is not local is renumbered
   * internally at reset, and a remeshed mesh after many remeshing operations
   * (see the class documentation). Off keeps the input's order and the
   * remesher's (for measurements). */
  itkSetMacro(RenumberForLocality, bool);
  itkGetConstMacro(RenumberForLocality, bool);
  itkBooleanMacro(RenumberForLocality);

  /** The number of renumberings of a remeshed mesh since the last reset
   * (see the class documentation). */
  itkGetConstMacro(NumberOfLocalityRenumberings, SizeValueType);

  /** Sign applied to the triangles' orientation to get outward normals: +1 for
   * an outward-oriented mesh, -1 for an inward-oriented one. Set by Reset()
   * from the signed volume of the triangles and kept across remeshings
   * (which keep the triangles' orientation). Always +1 for 2-D contours, whose orientation is normalised contour by
   * contour (see the class documentation). */
  itkGetConstMacro(OrientationSign, double);

  /** The boundary of an open mesh: the ends of an open 2-D contour, and the
   * boundary of an open 3-D surface (the vertices of edges that belong to
   * one triangle only, and the ends of line and polyline cells). When on,
   * these vertices keep their input position exactly (bit for bit) at every
   * iteration: a fixed boundary, as for a snake pinned at both ends or a
   * patch of surface attached along its rim. When off (default, the
   * behaviour of earlier versions), they move like the other vertices,
   * their internal forces coming from their neighbours on one side only:
   * the elastic force pulls an end toward its neighbour, so a free open
   * contour or surface shrinks along its boundary unless the image holds it.
   * Closed contours and closed surfaces have no boundary: the parameter
   * changes nothing for them. With remeshing (RemeshingEdgeLength > 0) the
   * boundary vertices of the input stay fixed (the remesher never moves a
   * boundary vertex) and the vertices it inserts at the midpoints of
   * boundary edges are fixed where they are inserted: the boundary curve is
   * kept exactly. Default: off. */
  itkSetMacro(FixedBoundary, bool);
  itkGetConstMacro(FixedBoundary, bool);
  itkBooleanMacro(FixedBoundary);

  /** Vertices on the boundary of the mesh (see FixedBoundary), found at the
   * last reset or remeshing. */
  SizeValueType
  GetNumberOfBoundaryVertices() const
  {
    return m_BoundaryVertices.size();
  }

  /** 2-D contours found at the last reset: closed ones (cycles of segments)
   * and open ones (chains with two ends). 0 for a 3-D mesh. */
  itkGetConstMacro(NumberOfClosedContours, SizeValueType);
  itkGetConstMacro(NumberOfOpenContours, SizeValueType);

protected:
  DeformableMeshFilter();
  ~DeformableMeshFilter() override = default;

  void
  PrintSelf(std::ostream & os, Indent indent) const override;

  void
  VerifyPreconditions() const override;

  void
  GenerateData() override;

  void
  Reset() override;

  void
  Iterate() override;

  bool
  HasConverged() const override
  {
    return m_Converged;
  }

private:
  using IndexType32 = uint32_t;

  /** The triangles (polygons fan-triangulated, for the normals) and edges of
   * the input's cells; \a onlyTriangles tells whether all cells are
   * triangles. For a 2-D mesh, \a triangles receives instead the directed
   * segments of the contours (2 point indices each, a line or polyline cell's
   * points in order); surface cells are refused. */
  void
  GatherInputCells(std::vector<IndexType32> & triangles, std::vector<uint64_t> & edges, bool & onlyTriangles) const;

  /** 2-D: removes duplicate segments and orients each contour: the segments
   * of an open contour (a chain) follow one direction, that of its first
   * segment from one end, and those of a closed contour (a cycle) run
   * counter-clockwise (positive signed area), so that the normal (c - b) x z
   * of each segment b -> c points outward. Where contours branch (a point
   * with more than two neighbours) the segments keep the input's direction.
   * Counts the contours; throws on a closed contour of fewer than 3 points. */
  void
  OrientContours(std::vector<IndexType32> & segments);

  /** The boundary vertices (see FixedBoundary) of the cached mesh, from the
   * triangles (2-D: the segments) in the cache's numbering. */
  void
  FindBoundaryVertices(const std::vector<IndexType32> & triangles);

  /** Gives the boundary vertices their coordinates of \a start in
   * m_NextCoordinates (FixedBoundary); when \a blockMaximum is given,
   * recomputes the largest displacement of the blocks that hold one and
   * zeroes their diagnosed displacement when \a diagnose. */
  void
  HoldBoundary(const double * start, std::vector<double> * blockMaximum, bool diagnose);

  /** The step's tables from triangles and edges (min << 32 | max, any order,
   * duplicates allowed unless \a edgesUnique; consumed). For a 2-D mesh
   * \a triangles holds the oriented segments of the contours, 2 indices
   * each (OrientContours()). \a orient: the orientation sign found again
   * from the triangles (see FinishTopology()). */
  void
  BuildTopology(const std::vector<IndexType32> & triangles,
                std::vector<uint64_t> &          edges,
                bool                             edgesUnique = false,
                bool                             orient = true);

  /** After a remeshing: the step's tables from the remesher's fans, the
   * same as BuildTopology() gives, without sorting each vertex's pairs;
   * false (nothing changed) when a vertex has no single fan. */
  bool
  BuildTopologyFromRemesher();

  /** The end of BuildTopology(): orientation sign (when \a orient; a
   * remeshing keeps the sign found at the reset, for the remesher keeps the
   * triangles' orientation), number of triangles, valence order. */
  void
  FinishTopology(const std::vector<IndexType32> & triangles, bool orient = true);

  /** Renumbers the cached points for locality when their numbering is not
   * local; relabels \a triangles and \a edges. */
  void
  RenumberForLocality(std::vector<IndexType32> & triangles, std::vector<uint64_t> & edges);

  /** Remeshes the cached surface and rebuilds the step's state. */
  void
  Remesh();

  /** With PreventSelfIntersections: remeshes again from \a x and
   * \a triangles (the surface before the remeshing, clear) with the points
   * around the contacts that the remeshing made locked, until it makes
   * none. */
  /** Renumbers the last remeshing's output \a x (and m_Triangles, and the
   * remesher's table) breadth-first when the operations since the last
   * renumbering call for it (see the class documentation). */
  void
  RenumberRemeshed(std::vector<double> & x);
  /** Moves point order[k] of \a x (3 coordinates a point, the first
   * order.size() points) to k; returns the new number of each point. */
  std::vector<IndexType32>
  ApplyOrder(std::vector<double> & x, const std::vector<IndexType32> & order);
  void
  RemeshWithoutContacts(const std::vector<double> & x, const std::vector<IndexType32> & triangles);

  /** Diagnostics in the output's numbering, when the points are renumbered. */
  void
  PublishDiagnostics();

  static constexpr SizeValueType RenumberingWindow = 2048;
  static constexpr double        RenumberingFarEdgeFraction = 0.1;
  // A remeshed mesh is renumbered once the splits and collapses since the
  // last renumbering (or the reset) exceed this fraction of its points,
  static constexpr double RenumberingOperationFraction = 0.1;
  // at a remeshing whose own operations are at most this fraction of the
  // points (a surface still travelling, a third of whose points a remeshing
  // replaces, would scramble a new numbering at once), or when they exceed
  // RenumberingOperationLimit times the points.
  static constexpr double RenumberingCalmFraction = 0.05;
  static constexpr double RenumberingOperationLimit = 2.0;

  void
  PrepareForceSampler();

  /** True when a term of the intensity image (region force) is on: the step
   * then adds m_NormalSpeeds along each vertex's unit normal. */
  bool
  UsesImageTerms() const
  {
    return m_RegionWeight > 0.0 || m_EdgeSearchWeight > 0.0;
  }

  /** Sets up the collision test (PreventSelfIntersections) for the current
   * mesh. \a triangles: the current triangles, 3 point indices each over the
   * cached points, in the cache's numbering; null (at reset, without
   * renumbering): the input mesh's triangles and fan-triangulated polygons.
   * They are kept (also with prevention off) for a later switch on. With
   * \a check (at reset): the cached coordinates are checked (throws, naming
   * the first intersecting pair, when they intersect themselves) and the
   * total count is reset; without (after a remeshing) the total is kept. */
  void
  ResetCollision(const std::vector<uint32_t> * triangles = nullptr, bool check = true);

  /** The collision hook of Iterate(): constrains m_NextCoordinates; keeps
   * the diagnostics, the blocks' largest displacements, the number of
   * active vertices and the largest displacement along the normals
   * (\a largestNormal, computed by FinishStep()) right: they measure the
   * displacements made, not those proposed. */
  void
  ConstrainSelfIntersections(std::vector<double> & blockMaximum, bool diagnose, double & largestNormal);

  /** After the step, when DampOscillations, ConvergenceFraction > 0 or
   * ConvergenceAlongNormals is on: scales each vertex's proposed displacement
   * (from start to m_NextCoordinates) by its step factor and updates the
   * factors and the blocks' largest displacements (DampOscillations), and
   * counts the vertices that move by ConvergenceTolerance or more (along
   * their normals with ConvergenceAlongNormals, whose largest such
   * displacement goes to \a largestNormal). */
  void
  FinishStep(const double * start, std::vector<double> & blockMaximum, bool diagnose, double & largestNormal);

  /** The checks of the image terms' parameters (VerifyPreconditions()). */
  void
  VerifyImageTermParameters() const;

  /** Smooths the intensity image (when it or RegionSigma changed) and
   * prepares its sampler; at each update with image terms. */
  void
  PrepareImageTerms();

  /** Estimates the object's intensity range from the cached input; at each
   * reset with image terms. */
  void
  EstimateImageTermModel();

  /** Fills m_NormalSpeeds (outward speed of each vertex, mm per iteration)
   * from the intensity image, at the current coordinates and the unit
   * normals m_Normals of the geometry pass. */
  /** Stores the region force's range in the image's units (the getters). */
  void
  StoreObjectIntensityRange();

  /** Moves the range's bounds from samples just outside the surface. */
  void
  EstimateBackground();

  void
  UpdateNormalSpeeds();

  /** Adds the edge search's speeds to m_NormalSpeeds. */
  void
  AddEdgeSearchSpeeds();

  double              m_ScaleFactor{ 1.0 };
  double              m_Elasticity{ 0.0 };
  bool                m_TangentialElasticity{ true };
  TangentialDriftEnum m_TangentialDrift{ TangentialDriftEnum::SuppressWhenRemeshing };
  double              m_Rigidity{ 0.0 };
  double              m_Balloon{ 0.0 };
  double              m_MaximumStepLength{ 0.0 };
  double              m_ReferenceEdgeLength{ 0.0 };
  unsigned int        m_MaximumNumberOfSubSteps{ 1000 };
  unsigned int        m_NumberOfSubSteps{ 1 };
  double              m_EdgeWeight{ 1.0 };
  double              m_RegionWeight{ 0.0 };
  double              m_RegionSigma{ 1.0 };
  double              m_IntensityTolerance{ 2.2 };
  bool                m_EstimateObjectIntensityRange{ true };
  double              m_ObjectIntensityLower{ 0.0 };
  double              m_ObjectIntensityUpper{ 0.0 };
  double              m_ObjectIntensityWidth{ 1.0 };
  double              m_ObjectIntensityMedian{ 0.0 };
  double              m_ObjectIntensitySpread{ 0.0 };
  bool                m_ObjectIntensityStatisticsGiven{ false };
  double              m_EdgeSearchWeight{ 0.0 };
  double              m_EdgeSearchDistance{ 2.0 };
  int                 m_EdgePolarity{ 0 };
  SizeValueType       m_NumberOfEdgeHits{ 0 };
  bool                m_EstimateBackgroundIntensity{ true };
  unsigned int        m_BackgroundUpdateInterval{ 10 };
  double              m_ConvergenceTolerance{ 0.0 };
  unsigned int        m_ConvergenceWindow{ 3 };
  double              m_ConvergenceFraction{ 0.0 };
  bool                m_ConvergenceAlongNormals{ false };
  SizeValueType       m_NumberOfActiveVertices{ 0 };
  bool                m_FixedBoundary{ false };
  SizeValueType       m_NumberOfClosedContours{ 0 };
  SizeValueType       m_NumberOfOpenContours{ 0 };
  // The boundary vertices (cache's numbering, increasing), found at reset;
  // for a 2-D mesh the first end of an open contour, or none (-1).
  std::vector<IndexType32> m_BoundaryVertices;
  int64_t                  m_FirstContourEnd{ -1 };
  double                   m_RemeshingEdgeLength{ 0.0 };
  unsigned int             m_RemeshingInterval{ 10 };
  bool                     m_RenumberForLocality{ true };
  bool                     m_Renumbered{ false };
  double                   m_FarEdgeFraction{ 0.0 };
  SizeValueType            m_OperationsSinceRenumbering{ 0 };
  SizeValueType            m_NumberOfLocalityRenumberings{ 0 };
  SizeValueType            m_NumberOfRemeshings{ 0 };
  RemeshingStatisticsType  m_RemeshingStatistics;
  SizeValueType            m_NumberOfPointsLockedByRemeshing{ 0 };
  // The surface's triangles in the internal numbering (remeshing only).
  std::vector<IndexType32> m_Triangles;
  // With PreventSelfIntersections, the input of the last remeshing (kept
  // between remeshings: their memory takes the next output).
  std::vector<double>      m_RemeshInputCoordinates;
  std::vector<IndexType32> m_RemeshInputTriangles;
  DeformableMeshRemesher   m_Remesher;
  bool                     m_PreventSelfIntersections{ false };
  bool                     m_DampOscillations{ false };
  SizeValueType            m_NumberOfDampedVertices{ 0 };
  /** Per vertex: the previous displacement (x, y, z) and the step factor. */
  std::vector<std::array<float, 4>> m_OscillationState;
  double                            m_MinimumDistance{ 0.0 };
  SizeValueType                     m_NumberOfCollisionsPrevented{ 0 };
  SizeValueType                     m_TotalNumberOfCollisionsPrevented{ 0 };
  SizeValueType                     m_NumberOfConstrainedVertices{ 0 };
  /** Contact memory (PreventSelfIntersections): per vertex, the fraction of
   * its proposed displacement it may move (1 unless a contact held it back
   * lately); the vertices below 1, in increasing order; their proposals of
   * the current iteration. */
  bool                     m_RememberContacts{ true };
  std::vector<float>       m_ContactFactors;
  std::vector<IndexType32> m_HeldPoints;
  std::vector<double>      m_HeldProposals;
  /** The collision test's tables and index (PreventSelfIntersections). */
  SurfaceCollision m_Collision;
  /** The triangles last given to ResetCollision() (empty: the input's),
   * unless m_CollisionTrianglesAreMeshTriangles: then m_Triangles (after a
   * remeshing, whose triangles are not copied: 24 MB at a million points). */
  std::vector<uint32_t> m_CollisionTriangles;
  bool                  m_CollisionTrianglesAreMeshTriangles{ false };
  /** Finite values and step bound of the force image (bad input). */
  ForceImageCheck<ForceImageType> m_ForceImageCheck;

  bool         m_Converged{ false };
  unsigned int m_QuietIterations{ 0 };
  double       m_LastMaximumDisplacement{ 0.0 };
  double       m_OrientationSign{ 1.0 };

  // Topology, unpacked once per Reset(): CSR neighbour table, ring-ordered
  // for ClosedRing and OpenRing vertices; the triangles of GeneralVertex
  // vertices as pairs (b, c), the edge opposite the vertex, in a second CSR
  // table indexed by their rank in m_GeneralVertices (sorted).
  std::vector<IndexType32> m_NeighbourOffsets;
  std::vector<IndexType32> m_Neighbours;
  // BuildTopologyFromRemesher()'s output, swapped with m_Neighbours: the
  // input's rings are read while the output's are written (kept so that
  // their pages are not faulted in at every remeshing).
  std::vector<IndexType32> m_SpareNeighbours;
  std::vector<uint8_t>     m_RingKinds;
  bool                     m_ClosedFans{ false }; // every ring a closed fan (FindBoundaryVertices())
  std::vector<IndexType32> m_GeneralVertices;
  std::vector<IndexType32> m_GeneralPairOffsets;
  std::vector<IndexType32> m_GeneralPairs;
  SizeValueType            m_NumberOfTriangles{ 0 };
  // When no number of neighbours is shared by three quarters of the vertices:
  // for each chunk of ChunkSize vertices, the offsets in the chunk of its
  // vertices sorted by number of neighbours; empty otherwise.
  std::vector<uint8_t> m_ValenceOrder;

  // Per-vertex state. Next coordinates: 3 per vertex and a guard value, as
  // the cached coordinates they are swapped with (Reset() appends the guard
  // to those); umbrella vectors and
  // normals (rigidity only): 4 floats per vertex.
  std::vector<double>  m_NextCoordinates;
  std::vector<float>   m_Umbrella;
  std::vector<float>   m_Normals;
  std::vector<uint8_t> m_BalloonReleased;
  std::vector<float>   m_NormalSpeeds;   // image terms only
  std::vector<float>   m_EdgeHits;       // edge search: distance to the edge along the normal, NaN: none
  std::vector<double>  m_IterationStart; // coordinates at the start of an iteration of several sub-steps

  // Image terms: the smoothed intensity image (kept while the input image and
  // RegionSigma are unchanged), its sampler and the object's model.
  // (3-D; a 2-D intensity image is smoothed in 2-D, then held as the slice
  // z = 0 of a 3-D image, which the samplers read as bilinear.)
  using SmoothedIntensityImageType = Image<float, 3>;
  typename SmoothedIntensityImageType::Pointer m_SmoothedIntensity;
  ModifiedTimeType                             m_SmoothedIntensityTime{ 0 };
  const IntensityImageType *                   m_SmoothedIntensitySource{ nullptr };
  double                                       m_SmoothedIntensitySigma{ -1.0 };
  DeformableMeshFilterDetail::IntensitySampler m_IntensitySampler;
  DeformableMeshFilterDetail::RegionForce      m_RegionForce;
  double                                       m_IntensityQuantiles[2]{}; // 2nd and 98th percentiles
  double                                       m_IntensityScale{ 1.0 };   // power of two applied before smoothing
  double                                       m_BackgroundStep{ 1.0 };   // smallest spacing of the intensity image
  double                                       m_IntensityGradientQuantile{ 0.0 }; // 99th percentile, per mm (scaled)
  using RegionForceType = DeformableMeshFilterDetail::RegionForce;
  std::vector<float> m_DisplacementMagnitudes;
  std::vector<float> m_ExternalForceMagnitudes;
  std::vector<float> m_InternalForceMagnitudes;
  // The same in the output's numbering, when the points are renumbered.
  std::vector<float> m_PublicDisplacementMagnitudes;
  std::vector<float> m_PublicExternalForceMagnitudes;
  std::vector<float> m_PublicInternalForceMagnitudes;

  // Force sampler, prepared at each update: continuous index
  // c = M (x - origin) - bufferStart, with M's columns as vectors.
  const ForcePixelType * m_ForceBuffer{ nullptr };
  /** The force image the sampler was set up for: its address, modification
   * times (of the image and of its buffer) and buffered region; a
   * continuation of the same run keeps the sampler. */
  const ForceImageType *                                   m_SampledForceImage{ nullptr };
  ModifiedTimeType                                         m_SampledForceTime{ 0 };
  ModifiedTimeType                                         m_SampledForceBufferTime{ 0 };
  typename ForceImageType::RegionType                      m_SampledForceRegion;
  double                                                   m_PhysicalToIndex[3][3]{};
  double                                                   m_ForceOrigin[3]{};
  double                                                   m_BufferStart[3]{};
  int64_t                                                  m_BufferSize[3]{};
  DeformableMeshFilterDetail::ForceSampler<ForcePixelType> m_Sampler{};
};
} // end namespace itk

#ifndef ITK_MANUAL_INSTANTIATION
#  include "itkDeformableMeshFilter.hxx"
#endif

#endif
