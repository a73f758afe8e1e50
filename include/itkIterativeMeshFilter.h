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
#ifndef itkIterativeMeshFilter_h
#define itkIterativeMeshFilter_h

#include "itkMeshToMeshFilter.h"
#include "itkExplicitDeformableModelCompatibility.h"

#include <algorithm>
#include <cstdint>
#include <utility>
#include <vector>

namespace itk
{

/** \class IterativeMeshFilter
 * \brief Base class of mesh filters that move the points of a mesh step by step
 * and can resume where the previous update stopped.
 *
 * The filter caches the coordinates of its input and transforms that cache one
 * iteration at a time; the input mesh is never modified. The iteration contract:
 *
 * - On the first update, when IterateFromZero is on, when NumberOfIterations is 0,
 *   when NumberOfIterations is below CurrentIteration, or when the input mesh
 *   has changed since it was cached, the input coordinates are cached,
 *   CurrentIteration returns to 0 and Reset() lets the subclass set its
 *   initial state.
 * - While CurrentIteration < NumberOfIterations (and the subclass has not
 *   converged, see HasConverged()), Iterate() runs one step and CurrentIteration
 *   increments. With IterateFromZero off, raising NumberOfIterations by one and
 *   updating runs exactly one more step: this is what makes animation cheap.
 * - NumberOfIterations == 0 gives the input back unchanged.
 * - Each step invokes an IterationEvent; an observer reads the current mesh
 *   with GetOutput(). Progress is reported after each step, and setting
 *   AbortGenerateData stops the loop cleanly between two steps (the output then
 *   holds the mesh of CurrentIteration; call Modified() before updating again to
 *   resume).
 *
 * Cells, cell data and point data of the input are copied to the output; only
 * point coordinates change. Point identifiers must be 0 to N-1 (the layout of
 * the default VectorContainer-based meshes).
 *
 * A subclass may change the mesh while it iterates (remeshing,
 * SetCachedTriangles()): from then on, until the next restart, the output has
 * the subclass's points (numbered 0 to N'-1) and one TriangleCell per
 * triangle (identifiers 0 to T-1, in the subclass's order); the input's point
 * data and cell data no longer apply and the output has none (empty
 * containers). The cells are rebuilt only when an output is seen: at the end
 * of an update and before an IterationEvent. A subclass may also hold its
 * points in an order of its own (SetOutputPointIdentifiers()); the output
 * keeps the input's numbering then.
 *
 * Subclasses implement Iterate() on the coordinate cache (GetCoordinates(): a
 * flat array of N * GetCoordinateStride() doubles in physical units, point
 * after point; the stride is PointDimension unless the subclass asks for more,
 * the extra coordinates being 0) and may override Reset() and HasConverged().
 *
 * \sa BrownianMeshFilter, DeformableMeshFilter
 * \ingroup ExplicitDeformableModel
 */
template <typename TInputMesh, typename TOutputMesh = TInputMesh>
class ITK_TEMPLATE_EXPORT IterativeMeshFilter : public MeshToMeshFilter<TInputMesh, TOutputMesh>
{
public:
  ITK_DISALLOW_COPY_AND_MOVE(IterativeMeshFilter);

  /** Standard class type aliases. */
  using Self = IterativeMeshFilter;
  using Superclass = MeshToMeshFilter<TInputMesh, TOutputMesh>;
  using Pointer = SmartPointer<Self>;
  using ConstPointer = SmartPointer<const Self>;

  /** Run-time type information (and related methods). */
  itkOverrideGetNameOfClassMacro(IterativeMeshFilter);

  using InputMeshType = TInputMesh;
  using OutputMeshType = TOutputMesh;
  using OutputPointType = typename OutputMeshType::PointType;
  using OutputPointsContainer = typename OutputMeshType::PointsContainer;

  static constexpr unsigned int PointDimension = OutputMeshType::PointDimension;

  /** Number of iterations the output should have undergone after the update.
   * Default: 0 (the output is the input). With IterateFromZero off, only the
   * iterations between CurrentIteration and NumberOfIterations are computed. */
  itkSetMacro(NumberOfIterations, SizeValueType);
  itkGetConstMacro(NumberOfIterations, SizeValueType);

  /** Number of iterations the current output has undergone. It equals
   * NumberOfIterations after a complete update, and is smaller when the update
   * was aborted or the subclass detected convergence. */
  itkGetConstMacro(CurrentIteration, SizeValueType);

  /** When on (default), every update restarts from the input and runs all
   * NumberOfIterations iterations. When off, an update continues from the mesh
   * of the previous update: raising NumberOfIterations by one runs one step. */
  itkSetMacro(IterateFromZero, bool);
  itkGetConstMacro(IterateFromZero, bool);
  itkBooleanMacro(IterateFromZero);

  /** True when the subclass changed the mesh (remeshing) since the last
   * restart: the output then has the subclass's points and triangle cells,
   * not the input's structure. */
  bool
  GetTopologyChanged() const
  {
    return m_TopologyChanged;
  }

protected:
  IterativeMeshFilter();
  ~IterativeMeshFilter() override;

  void
  PrintSelf(std::ostream & os, Indent indent) const override;

  /** Rejects a missing input mesh with a clear message. */
  void
  VerifyPreconditions() const override;

  /** Checks the input mesh (present, not empty, identifiers 0..N-1, finite
   * coordinates), then runs the iteration contract described above. A
   * non-finite coordinate after a step throws an ExceptionObject naming the
   * iteration (the output is not updated, the next update restarts from the
   * input); so does a failed memory allocation (std::bad_alloc). */
  void
  GenerateData() override;

  /** Called after the input coordinates have been cached and CurrentIteration
   * set to 0: subclasses set up their initial state here. Default: nothing. */
  virtual void
  Reset()
  {}

  /** One step: transform GetCoordinates() in place. */
  virtual void
  Iterate() = 0;

  /** A subclass that detects convergence returns true to stop the loop before
   * NumberOfIterations is reached. Default: false. */
  virtual bool
  HasConverged() const
  {
    return false;
  }

  /** The cached coordinates: N * GetCoordinateStride() doubles, point after
   * point (the point's PointDimension coordinates, then zeros up to the
   * stride). A subclass may append values of its own after them (in Reset())
   * or swap in an array of its own; only the first N * GetCoordinateStride()
   * are read. */
  std::vector<double> &
  GetCoordinates()
  {
    return m_Coordinates;
  }
  const std::vector<double> &
  GetCoordinates() const
  {
    return m_Coordinates;
  }

  /** Doubles per cached point: PointDimension unless the subclass set more
   * (SetCoordinateStride(), in its constructor): a subclass whose step works
   * on 3-D vectors caches a 2-D point as (x, y, 0). */
  unsigned int
  GetCoordinateStride() const
  {
    return m_CoordinateStride;
  }
  void
  SetCoordinateStride(unsigned int stride)
  {
    m_CoordinateStride = std::max(stride, PointDimension);
  }

  /** Number of points of the cached mesh. */
  SizeValueType
  GetNumberOfCachedPoints() const
  {
    return m_NumberOfCachedPoints;
  }

  /** Writes the cached coordinates into the output mesh points. */
  void
  UpdateOutputPoints();

  /** For a subclass that holds its points in an order of its own: the
   * output identifier of each cached point (a permutation of 0 to N-1), or
   * empty (the default, reset at each restart) for the cached order itself. */
  void
  SetOutputPointIdentifiers(std::vector<uint32_t> identifiers)
  {
    m_OutputPointIdentifiers = std::move(identifiers);
  }
  const std::vector<uint32_t> &
  GetOutputPointIdentifiers() const
  {
    return m_OutputPointIdentifiers;
  }

  /** For a subclass that changed the mesh (remeshing): the cache now holds
   * \a numberOfPoints points (GetCoordinates() resized by the subclass) and
   * the surface is \a triangles (3 point indices per triangle, in the cached
   * order). The output gets these triangles as its cells, no point or cell
   * data, and the cached numbering (SetOutputPointIdentifiers() is reset). */
  void
  SetCachedTriangles(SizeValueType numberOfPoints, const std::vector<uint32_t> & triangles);


private:
  using OutputCellsContainer = typename OutputMeshType::CellsContainer;

  /** GenerateData() without the conversion of std::bad_alloc. */
  void
  RunIterations();

  /** Throws the ExceptionObject of a diverged step, naming the first
   * non-finite point and the iterations of this update. */
  [[noreturn]] void
  ThrowNonFiniteCoordinate(SizeValueType firstIteration);

  void
  CacheInput();

  /** Drops the clone of the input cells; deletes the cells when no output
   * mesh shares them any more. */
  void
  ReleaseOutputCells();

  /** Gives the output the structure of the changed mesh: triangle cells
   * (rebuilt when stale), empty point and cell data. */
  void
  InstallChangedStructure();

  SizeValueType       m_NumberOfIterations{ 0 };
  SizeValueType       m_CurrentIteration{ 0 };
  bool                m_IterateFromZero{ true };
  bool                m_Cached{ false };
  ModifiedTimeType    m_CachedInputTime{ 0 };
  std::vector<double> m_Coordinates;
  unsigned int        m_CoordinateStride{ PointDimension };
  SizeValueType       m_NumberOfCachedPoints{ 0 };
  SizeValueType       m_NumberOfInputPoints{ 0 }; // of the input when it was cached
  bool                m_OutputPointsFinite{ true };

  // A mesh changed by the subclass: its triangles, and whether the output
  // cells describe them yet; the output identifiers of the cached points.
  bool                  m_TopologyChanged{ false };
  bool                  m_OutputCellsStale{ false };
  std::vector<uint32_t> m_CachedTriangles;
  std::vector<uint32_t> m_OutputPointIdentifiers;

  // The output's structure and points, reused from one update to the next:
  // cloning the cells at every update costs more than a step on large meshes.
  typename OutputCellsContainer::Pointer  m_OutputCells;
  typename OutputPointsContainer::Pointer m_OutputPoints;
};
} // end namespace itk

#ifndef ITK_MANUAL_INSTANTIATION
#  include "itkIterativeMeshFilter.hxx"
#endif

#endif
