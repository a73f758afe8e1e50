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
#ifndef itkDeformableMeshRemesher_h
#define itkDeformableMeshRemesher_h

#include "itkMacro.h"
#include "itkMultiThreaderBase.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numeric>
#include <vector>
#if defined(_MSC_VER)
#  include <intrin.h>
#endif

namespace itk
{

/** \class DeformableMeshRemesher
 * \brief Isotropic remeshing of a triangle surface held in flat arrays: the
 * remeshing step of DeformableMeshFilter, usable on its own.
 *
 * Remesh() brings the edge lengths of a triangle mesh into the band
 * [MinimumRatio L, MaximumRatio L] around the target edge length L (physical
 * units, mm), in the manner of the isotropic remeshing of Botsch and Kobbelt
 * (2004), in one round of four passes:
 * -# split: every edge longer than MaximumRatio L is split at its midpoint,
 *    repeatedly until none is;
 * -# collapse: an edge shorter than MinimumRatio L is collapsed to its
 *    midpoint, unless that would make the mesh non-manifold (the two
 *    end-points share neighbours other than the two opposite vertices, or an
 *    opposite vertex has only three neighbours), turn a triangle around (its
 *    normal reversed), or create an edge longer than MaximumRatio L;
 * -# flip: an edge shared by two triangles is flipped when that brings the
 *    numbers of neighbours of the four vertices closer to 6 (4 on a
 *    boundary), unless the new edge exists already or a triangle would turn
 *    around or fold (the two new triangles' normals more than 60 degrees
 *    apart while the old ones were not);
 * -# tangential relaxation: every free vertex moves halfway to the centroid
 *    of its neighbours, within the tangent plane (the component along the
 *    vertex normal removed), which evens the triangles' shapes without
 *    moving the surface; a move that would turn a triangle around is not
 *    made;
 * and a last split pass, so that no edge is longer than MaximumRatio L when
 * Remesh() returns. Edges shorter than MinimumRatio L may remain where every
 * collapse was refused.
 *
 * What is left alone: boundary edges (one triangle) are split at their
 * midpoint but never flipped or collapsed, and boundary vertices never move,
 * so an open surface keeps its boundary curve exactly; edges shared by more
 * than two triangles (or by two triangles of opposite orientations) and
 * vertices whose triangles do not form one fan (non-manifold parts) are
 * frozen: no operation touches them. Points that no triangle uses are
 * dropped.
 *
 * The output vertices are numbered for locality: the vertices kept, in their
 * input order, each followed by the vertices split from its edges, so a mesh
 * numbered for locality stays so. Parents() gives, for each output vertex,
 * the input vertex it comes from (the vertex itself, or the first end-point
 * of the edge it was split from), for carrying per-vertex state.
 *
 * Deterministic: the same input gives the same output, bit for bit, whatever
 * the threads. On a mesh of at least 2 PartitionSize points the collapse,
 * flip and lengthening passes run in parts of consecutive point numbers
 * (SetPartitionSize()): each part in corner order, in parallel with the
 * others, then the operations that reach across parts in corner order; the
 * output depends on the number of parts, which the mesh and PartitionSize
 * set.
 *
 * \sa DeformableMeshFilter
 * \ingroup ExplicitDeformableModel
 */
class DeformableMeshRemesher
{
public:
  using IndexType = uint32_t;

  /** Counts of the operations of the last Remesh(). */
  struct Statistics
  {
    std::size_t splits{ 0 };
    std::size_t collapses{ 0 };
    std::size_t flips{ 0 };
    std::size_t relaxed{ 0 };
  };

  /** Target edge length L, physical units (mm). Must be finite and
   * positive. Default: 1. */
  void
  SetTargetEdgeLength(double length)
  {
    m_TargetEdgeLength = length;
  }
  double
  GetTargetEdgeLength() const
  {
    return m_TargetEdgeLength;
  }

  /** The band of the edge lengths, as fractions of the target: edges below
   * MinimumRatio L are collapsed, above MaximumRatio L split. Defaults: 4/5
   * and 4/3 (Botsch and Kobbelt). Need 0 < MinimumRatio < MaximumRatio / 2
   * is not required, but MinimumRatio < MaximumRatio is. */
  void
  SetEdgeLengthRatios(double minimumRatio, double maximumRatio)
  {
    m_MinimumRatio = minimumRatio;
    m_MaximumRatio = maximumRatio;
  }
  double
  GetMinimumEdgeLength() const
  {
    return m_MinimumRatio * m_TargetEdgeLength;
  }
  double
  GetMaximumEdgeLength() const
  {
    return m_MaximumRatio * m_TargetEdgeLength;
  }

  /** Threads for the passes that run in parallel (building the corner
   * table, the manifold check, the relaxation): \a threader with
   * \a workUnits work units, or none (nullptr, the default: serial). The
   * result does not depend on it. */
  void
  SetMultiThreader(MultiThreaderBase * threader, unsigned int workUnits)
  {
    m_Threader = threader;
    m_WorkUnits = workUnits;
  }

  /** The collapse, flip and lengthening passes of a mesh of at least
   * 2 PartitionSize points run in parts: 2, 4 or 8 ranges of the input's
   * point numbers of at least PartitionSize points each (a point split from
   * an edge during the Remesh() belongs to the part of the point it comes
   * from). Each part makes, in parallel with the others, its operations
   * that read and change only its own points and the triangles among them,
   * in corner order; the operations that would reach another part's point
   * are made afterwards, in corner order, on the whole mesh. The result
   * depends on the number of parts (on the mesh and PartitionSize), not on
   * the threads; it differs from the serial sweep's only in the order of the
   * operations. A numbering for locality (LocalityOrder(), or the output of
   * a Remesh()) keeps the operations across parts few. 0: every pass one
   * serial sweep in corner order. Default: 8192. */
  void
  SetPartitionSize(std::size_t points)
  {
    m_PartitionSize = points;
  }
  std::size_t
  GetPartitionSize() const
  {
    return m_PartitionSize;
  }

  /** Number of tangential relaxation sweeps per Remesh(). Default: 1. */
  void
  SetRelaxationSweeps(unsigned int sweeps)
  {
    m_RelaxationSweeps = sweeps;
  }

  /** Incremental remeshing of a mesh that moves. When on, and the input of
   * Remesh() is the last output (the same triangles: the corner table is
   * kept), the flip pass and the relaxation visit only where the
   * connectivity changed since the last flip pass: the flip pass the edges
   * with an end-point or an opposite point that an operation (split,
   * collapse, flip) touched, the relaxation those points and their
   * neighbours. The first round of splits and collapses tests every edge;
   * the second (after the relaxation) only the edges of the triangles
   * around those points and the short edges the first round left, when
   * these are at most a sixteenth of the triangles. Elsewhere
   * the valences are as the last flip pass left them and the points as the
   * last relaxation left them, moved since by the caller: DeformableMeshFilter,
   * whose internal forces keep the points spread along the surface between
   * two remeshings, turns it on. A first Remesh(), one after ForgetTable() or
   * with locked vertices, or of another mesh, visits the whole mesh.
   * Default: off (each Remesh() flips and relaxes everywhere). */
  void
  SetIncremental(bool incremental)
  {
    m_Incremental = incremental;
  }
  bool
  GetIncremental() const
  {
    return m_Incremental;
  }

  /** Vertices of the next Remesh()'s input (a flag per input vertex, 1:
   * locked) that no operation touches, as if frozen: they do not move, and
   * no edge with a locked end-point is split, collapsed or flipped (nor
   * created by a flip). A triangle whose three vertices are locked comes out
   * as it went in. DeformableMeshFilter locks the neighbourhoods where a
   * remeshing would bring the surface into contact with itself. Used by the
   * next Remesh() only (it then rebuilds its corner table, and the one after
   * rebuilds it again); an empty vector locks nothing. */
  void
  SetLockedVertices(std::vector<uint8_t> locked)
  {
    m_Locked = std::move(locked);
  }

  /** Remeshes in place: \a coordinates holds 3 doubles per vertex (at least
   * 3 * numberOfPoints; the rest is ignored and dropped), \a triangles 3
   * vertex indices per triangle. On return both describe the new mesh.
   * Throws an ExceptionObject for a bad target length or a triangle that
   * refers to a missing point. */
  Statistics
  Remesh(std::vector<double> & coordinates, std::size_t numberOfPoints, std::vector<IndexType> & triangles);

  /** Remeshes \a inputCoordinates and \a inputTriangles (as the other
   * Remesh() takes them) into \a coordinates and \a triangles, whose
   * contents are replaced (their memory is reused); the inputs are left as
   * they are, so a caller that may remesh them again need not copy them.
   * The inputs and outputs may be the same vectors. */
  Statistics
  Remesh(const std::vector<double> &    inputCoordinates,
         std::size_t                    numberOfPoints,
         const std::vector<IndexType> & inputTriangles,
         std::vector<double> &          coordinates,
         std::vector<IndexType> &       triangles);

  /** The edges of the last Remesh()'s output, as (min << 32 | max) of their
   * end-points, in no particular order; returns true when each edge is
   * listed once (false when frozen non-manifold edges may repeat). */
  bool
  Edges(std::vector<uint64_t> & edges) const;

  /** Whether the last Remesh()'s output is a closed surface in the sense of
   * SurfaceCollision::IsClosedSurface(): at least 4 triangles, and every
   * directed edge (a, b) of a triangle is the edge (b, a) of exactly one
   * other triangle and of no other triangle in the same direction (which
   * excludes a triangle that repeats a point). Read from the corner table
   * the remesher keeps: every corner has its twin. False before any
   * Remesh(), after ForgetTable() and after a Remesh() with locked vertices
   * (when the table is not kept): the caller then checks for itself. */
  bool
  IsOutputClosed() const;

  /** Counts of the operations of the last Remesh() (what it returned). */
  const Statistics &
  GetStatistics() const
  {
    return m_Statistics;
  }

  /** Whether the last Remesh() changed the connectivity (a split, collapse
   * or flip). When it did not, the points and triangles kept their numbers
   * and only positions moved (relaxation). */
  bool
  GetTopologyChanged() const
  {
    return m_Statistics.splits + m_Statistics.collapses + m_Statistics.flips > 0;
  }

  /** Forgets the corner table kept from the last Remesh(): the next one
   * builds it from its input. Remesh() keeps the table of its output and
   * reuses it when it is given that output again (the next remeshing of a
   * mesh that only moved), which saves building it; the result is the same
   * either way unless Incremental is on (the next Remesh() then visits the
   * whole mesh). */
  void
  ForgetTable()
  {
    m_TableValid = false;
  }

  /** The neighbours of vertex \a v of the last Remesh()'s output in the
   * order of its fan of triangles (oriented as the triangles). Returns 1 for
   * a closed fan, 2 for an open one (a boundary vertex: the first and last
   * neighbours lie on the boundary), 0 for a frozen vertex (its triangles do
   * not form one fan; \a neighbours then is not the ring). */
  int
  OutputRing(IndexType v, std::vector<IndexType> & neighbours) const;

  /** The number of neighbours of vertex \a v of the last Remesh()'s output
   * as the remesher counts them: the size of OutputRing()'s ring when \a v
   * is not frozen. */
  std::size_t
  OutputValence(IndexType v) const
  {
    return m_TableValid && v < m_Valence.size() ? static_cast<std::size_t>(m_Valence[v]) : 0;
  }

  /** Whether an operation (split, collapse, flip) of the last Remesh()
   * changed the triangles around vertex \a v of its output. An output
   * triangle none of whose vertices was changed is one of the input's
   * triangles, with the same points (Parents()), moved by the relaxation at
   * most. */
  bool
  OutputPointChanged(IndexType v) const
  {
    return v < m_Touched.size() && (m_Touched[v] & TouchedNow) != 0;
  }

  /** For each vertex of the last Remesh()'s output, the input vertex it
   * comes from. */
  const std::vector<IndexType> &
  Parents() const
  {
    return m_Parents;
  }

  /** The number in the last Remesh()'s output of point \a p of its input,
   * Invalid when the remeshing removed it. The input's points that stay
   * keep their order (the output numbers them in the order of the input,
   * each followed by the points split from its edges). Invalid for every
   * point once RenumberOutput() has renumbered the output, or when no
   * Remesh() ran. */
  IndexType
  OutputOfInput(IndexType p) const
  {
    if (p >= m_InputPoints || m_InputMap == InputMapNone)
    {
      return Invalid;
    }
    return m_InputMap == InputMapIdentity ? p : m_NewIndex[p];
  }

  /** Renumbers the points of the last Remesh()'s output: \a order[k] is
   * the point that takes number k (a permutation of the output's points).
   * \a triangles, the output's triangles as Remesh() returned them, are
   * renumbered and reordered as Remesh() orders its output (by the smallest
   * new number of their points, stably), so that the triangles around a
   * point sit near each other in memory as the points do. The kept table
   * follows, so that the next Remesh() of the renumbered output reuses it,
   * incrementally (SetIncremental()), as it would the output itself;
   * Parents() and OutputPointChanged() follow too. Coordinates are the
   * caller's to permute (coordinates of new point k: those of order[k]).
   * False, and nothing changed, when no table describes the output (after a
   * Remesh() with locked vertices, or one whose table could not be kept). */
  bool
  RenumberOutput(const std::vector<IndexType> & order, std::vector<IndexType> & triangles);

  /** A renumbering of \a numberOfPoints points for locality: order[k] is the
   * point that takes number k. The points are sorted along a Morton
   * (Z-order) curve of their positions on a 2^21 grid over their bounding
   * box, so that neighbours on a surface mostly get close numbers. */
  static std::vector<IndexType>
  LocalityOrder(const double * coordinates, std::size_t numberOfPoints);

  /** A renumbering for locality that follows the surface: a breadth-first
   * walk over the \a edges ((min << 32 | max) of their end-points), from
   * the point first in LocalityOrder() of each connected part. The points
   * then come in rings around the start, so that the neighbours of a point
   * lie in the ring before, its own and the ring after: three streams that
   * the step reads in order. order[k] is the point that takes number k. */
  static std::vector<IndexType>
  BreadthFirstOrder(const double * coordinates, std::size_t numberOfPoints, const std::vector<uint64_t> & edges);

  /** A breadth-first numbering of the last Remesh()'s output (\a
   * coordinates: its points), as BreadthFirstOrder() gives, with its
   * neighbours read from the kept table instead of a list of edges, and
   * without the Morton order of all the points: the walk starts from the
   * point of smallest coordinate along the longest side of the bounding box,
   * then covers the other connected parts, if any, each from its point of
   * smallest number. Empty when no table describes the output (see
   * RenumberOutput()). */
  std::vector<IndexType>
  OutputBreadthFirstOrder(const double * coordinates) const;

  /** A locality measure of a numbering: the fraction of the edges of the
   * triangles whose end-points are numbered more than \a window apart. */
  static double
  FarEdgeFraction(const std::vector<IndexType> & triangles, std::size_t window);

private:
  /** The Morton codes of LocalityOrder(): the 21-bit grid coordinates of
   * each point over the bounding box, interleaved. */
  static std::vector<uint64_t>
  MortonKeys(const double * coordinates, std::size_t numberOfPoints);

  /** The breadth-first walk over the neighbour lists \a neighbours[offsets[v]]
   * to neighbours[offsets[v + 1]] of each point v: with \a morton, each
   * connected part from its first point in LocalityOrder()
   * (BreadthFirstOrder()); without, as OutputBreadthFirstOrder() says. */
  static std::vector<IndexType>
  BreadthFirstWalk(const double *                 coordinates,
                   std::size_t                    numberOfPoints,
                   const std::vector<IndexType> & offsets,
                   const std::vector<IndexType> & neighbours,
                   bool                           morton);

  static constexpr IndexType Invalid = std::numeric_limits<IndexType>::max();
  // A corner's link to the opposite half-edge: its corner, Boundary or
  // NonManifold. 32 bits (the corner table is the remesher's largest array):
  // Remesh() refuses meshes of more than about 2^31 corners.
  using Link = int32_t;
  static constexpr Link Boundary = -1;
  static constexpr Link NonManifold = -2;

  /** The position of the lowest set bit of \a bits (not 0). */
  static unsigned int
  LowestBit(uint64_t bits)
  {
#if defined(_MSC_VER)
    unsigned long position = 0;
    _BitScanForward64(&position, bits);
    return static_cast<unsigned int>(position);
#else
    return static_cast<unsigned int>(__builtin_ctzll(bits));
#endif
  }
  static IndexType
  Next(IndexType c)
  {
    return c % 3 == 2 ? c - 2 : c + 1;
  }
  static IndexType
  Prev(IndexType c)
  {
    return c % 3 == 0 ? c + 2 : c - 1;
  }

  void
  Build(std::size_t numberOfPoints);
  /** The neighbours (in fan order) and corners of vertex v; false for a
   * frozen vertex. */
  bool
  Ring(IndexType v, std::vector<IndexType> & neighbours, std::vector<IndexType> * corners) const;
  IndexType
  NewVertex(const double * p, IndexType parent);
  double
  Length2(IndexType a, IndexType b) const;
  void
  TriangleNormal(IndexType a, IndexType b, IndexType c, double n[3]) const;
  void
  TriangleNormal(const double * a, const double * b, const double * c, double n[3]) const;

  /** Splits the long edges: those of the whole mesh when \a all, else those
   * of the triangles the splits of the last pass touched (only they can be
   * long after a pass that split every long edge). */
  bool
  SplitPass(bool all);
  /** The squared length of the edge of corner \a c when a split pass splits
   * it (longer than the maximum, manifold, no end-point frozen), else 0. */
  double
  SplittableLength2(IndexType c) const;
  /** The corner an edge is listed from: the lower of corner \a c and its
   * twin (or \a c on a boundary). */
  IndexType
  ListingCorner(IndexType c) const;
  bool
  SplitWaits(IndexType c) const;
  void
  Split(IndexType c);
  void
  CollapsePass();
  struct SweepWorker;
  bool
  TryCollapse(SweepWorker & worker, IndexType c, bool fromTwin = false);
  void
  FlipPass();
  /** Flips the edge of corner c when that improves the valences or, with
   * \a lengthen, when the new edge is longer and at most the maximum. */
  bool
  TryFlip(SweepWorker & worker, IndexType c, bool lengthen = false);
  /** The cheap part of TryFlip(c): an interior edge listed from c whose
   * flip would bring the valences closer to 6 (4 on a boundary). */
  bool
  FlipImprovesValences(IndexType c, bool touchedOnly) const;
  void
  Relax();
  /** Moves the end-points of each edge still shorter than the minimum apart
   * along it, when no other edge of theirs leaves the band and no triangle
   * turns around; failing that, when their other edges all stay longer than
   * this edge was (and no longer than the maximum). */
  void
  LengthenPass();
  /** Whether moving free vertex \a v, of neighbours \a ring and corners
   * \a corners (Ring()), to \a q keeps its edges other than the one to
   * \a other no longer than the maximum and no shorter than \a floor2
   * (squared), and turns none of its triangles around. */
  bool
  MoveKeepsBand(IndexType                      v,
                const double *                 q,
                IndexType                      other,
                const std::vector<IndexType> & ring,
                const std::vector<IndexType> & corners,
                double                         floor2) const;
  /** Runs body(begin, end) over [0, n) in blocks of \a blockSize, on the
   * threader if any. */
  template <typename TBody>
  void
  ParallelFor(std::size_t n, TBody && body, std::size_t blockSize = 8192) const;

  /** What an operation of the running Sweep() changes in the tests of the
   * corners still to come: the lengths and twins of edges (collapse and
   * lengthening passes), or also the valences (flip pass). */
  enum class SweepInputs : uint8_t
  {
    None,
    Lengths,
    Valences
  };
  /** The state of a running sweep over a queue of corners (a bit per
   * corner): the whole mesh's, or one part's (RunQueue()). A part reads and
   * changes only its points [first, last) and the triangles all of whose
   * points are among them; the other parts run at the same time. An
   * operation that would reach another point (Reach()) is deferred, before
   * it changes anything, to the serial sweep after the parts. */
  struct SweepWorker
  {
    const uint8_t *          partOf{ nullptr }; // the part of each point
    std::size_t              numberOfPoints{ 0 };
    uint8_t                  part{ 0 };
    bool                     partitioned{ false };
    bool                     deferThis{ false }; // the running operation reached out of the part
    SweepInputs              inputs{ SweepInputs::None };
    IndexType                position{ 0 };
    std::vector<uint64_t> *  queue{ nullptr };
    bool                     trackStillShort{ false };
    std::vector<IndexType> * stillShort{ nullptr };
    std::vector<uint64_t>    ownQueue;
    std::vector<IndexType>   ownStillShort;
    std::vector<IndexType>   deferred;
    std::vector<IndexType>   ringA;
    std::vector<IndexType>   ringB;
    std::vector<IndexType>   cornersA;
    std::vector<IndexType>   cornersB;
    std::size_t              collapses{ 0 };
    std::size_t              flips{ 0 };
    /** Whether the sweep may read and change point v; when not, marks the
     * running operation for deferral. */
    bool
    Reach(IndexType v)
    {
      if (!partitioned || (v < numberOfPoints && partOf[v] == part))
      {
        return true;
      }
      deferThis = true;
      return false;
    }
  };
  /** Walks the ring of \a v into \a ring and reaches each of its points;
   * false when the ring cannot be walked (frozen) or reaches out. */
  bool
  ReachRing(SweepWorker & worker, IndexType v, std::vector<IndexType> & ring, std::vector<IndexType> * corners) const
  {
    if (!this->Ring(v, ring, corners))
    {
      return false;
    }
    for (const IndexType w : ring)
    {
      if (!worker.Reach(w))
      {
        return false;
      }
    }
    return true;
  }
  /** Calls body(worker, c) for each corner c, in increasing order, for which
   * candidate(c) holds, as a serial loop over every corner calling body()
   * would: candidate(c) is a necessary condition of body(c) doing anything,
   * tested in parallel on the mesh as it is before the sweep; the
   * operations body() makes queue again the corners whose test they may
   * have changed (Requeue()), so that the result is the same, bit for bit,
   * as that of the serial loop (for a mesh in parts: RunQueue()). */
  template <typename TCandidate, typename TBody>
  void
  Sweep(SweepInputs inputs, TCandidate && candidate, TBody && body);
  /** Runs body(worker, c) for the corners queued in m_Queue (the second
   * half of Sweep()): in increasing order on the whole mesh; or, for a mesh
   * in parts (SetPartitionSize()), each part's corners (those of its
   * points) in increasing order, the parts in parallel, then the deferred
   * corners in increasing order on the whole mesh. */
  template <typename TBody>
  void
  RunQueue(SweepInputs inputs, TBody && body);
  /** Runs \a worker's queue in increasing order. */
  template <typename TBody>
  void
  RunWorker(SweepWorker & worker, TBody & body);
  /** The number of parts of the passes on the current mesh (1: serial). */
  std::size_t
  NumberOfParts() const;
  /** Whether the edge of corner c is short, listed from c: an interior
   * edge seen from the lower of its two corners. */
  bool
  ShortEdge(IndexType c) const
  {
    return m_V[c] != Invalid && m_O[c] >= static_cast<int64_t>(c) && this->Length2(m_V[c], m_V[Next(c)]) < m_Min2;
  }
  /** Queues corner \a k and its twin for the running sweep, when ahead of
   * it; in a part, a corner of another part's point goes to the deferred
   * corners. */
  void
  Requeue(SweepWorker & worker, int64_t k)
  {
    for (const int64_t corner : { k, k >= 0 ? m_O[static_cast<std::size_t>(k)] : k })
    {
      if (corner < 0)
      {
        continue;
      }
      if (worker.partitioned)
      {
        const IndexType v = m_V[static_cast<std::size_t>(corner)];
        if (v >= worker.numberOfPoints || worker.partOf[v] != worker.part)
        {
          worker.deferred.push_back(static_cast<IndexType>(corner));
          continue;
        }
      }
      if (corner > static_cast<int64_t>(worker.position))
      {
        (*worker.queue)[static_cast<std::size_t>(corner) >> 6] |= uint64_t{ 1 } << (corner & 63);
      }
      else if (worker.trackStillShort)
      {
        worker.stillShort->push_back(static_cast<IndexType>(corner));
      }
    }
  }
  /** Incremental second round: the triangles with a point in m_RelaxSet
   * and those of the corners in m_LeftShort, as the splits' candidates
   * (m_SplitTouched) and the collapses' (m_ShortEdgesStale over an empty
   * m_ShortEdges); false, with nothing queued, when they are more than a
   * sixteenth of the triangles (a scan of the whole mesh is then cheaper). */
  bool
  QueueSecondRound();
  /** Queues the three corners (and their twins) of each triangle of the
   * fan of \a v. */
  void
  RequeueFan(SweepWorker & worker, IndexType v);
  /** Writes the output: the points to \a coordinates, the triangles to
   * \a triangles (left alone when they already hold the input's and the
   * remeshing changed no corner: \a trianglesHoldInput). */
  void
  Compact(std::vector<double> & coordinates, std::vector<IndexType> & triangles, bool trianglesHoldInput);
  /** The table in a new numbering of its points (\a newIndex, Invalid for
   * removed points, \a newPoints in all): the triangles left, ordered by
   * their smallest new point (a stable counting sort), written to \a
   * triangles and to the table. False when a corner's twin was removed
   * without it (the table then does not describe the triangles). */
  bool
  ReorderTable(const std::vector<IndexType> & newIndex, std::size_t newPoints, std::vector<IndexType> & triangles);
  /** m_VertexCorner as Build() sets it: the first corner of each point. */
  void
  SetFirstCorners();
  /** body(0) and body(1), in parallel on the threader if any. */
  template <typename TBody>
  void
  Halves(TBody && body) const;

  MultiThreaderBase * m_Threader{ nullptr };
  unsigned int        m_WorkUnits{ 1 };
  double              m_TargetEdgeLength{ 1.0 };
  double              m_MinimumRatio{ 0.8 };
  double              m_MaximumRatio{ 4.0 / 3.0 };
  unsigned int        m_RelaxationSweeps{ 1 };
  bool                m_Incremental{ false };

  // Corner table: corner c = 3 t + k is vertex m_V[c] of triangle t; the
  // half-edge of corner c goes from m_V[c] to m_V[Next(c)]; m_O[c] is the
  // corner of the opposite half-edge, Boundary or NonManifold.
  std::vector<IndexType> m_V;
  std::vector<Link>      m_O;
  std::vector<IndexType> m_VertexCorner; // a corner of each vertex, Invalid if none
  std::vector<int32_t>   m_Valence;
  std::vector<uint8_t>   m_State; // 0 free, 1 boundary, 2 frozen, 3 removed
  std::vector<double>    m_X;
  std::vector<IndexType> m_Parents;
  bool                   m_TableValid{ false };
  std::vector<uint8_t>   m_Locked; // SetLockedVertices(), for the next Remesh()
  // Per point: TouchedSinceFlips when an operation changed its fan since the
  // last flip pass (every point of a table just built), TouchedNow when one
  // did in the running (or last) Remesh(). Incremental (m_Local): the flip
  // pass and relaxation visit the first ones (and their rings, marked in
  // m_RelaxSet).
  enum : uint8_t
  {
    TouchedSinceFlips = 1,
    TouchedNow = 2
  };
  std::vector<uint8_t>   m_Touched;
  std::vector<uint8_t>   m_RelaxSet;
  std::vector<IndexType> m_FlipSeeds;        // scratch of FlipPass(), incremental: the touched points
  std::vector<uint64_t>  m_FlipMarked;       // scratch of FlipPass(), incremental: the corners to test
  std::vector<uint64_t>  m_FlipMarkedSecond; // the same, from the second half of the touched points
  bool                   m_Local{ false };
  std::vector<IndexType> m_SplitTouched;     // triangles the splits of a pass changed or made
  std::vector<uint64_t>  m_SplitTouchedBits; // scratch of SplitPass(): m_SplitTouched, a bit per triangle
  // The short edges found by the scan of SplitPass(true), a bit per corner
  // as CollapsePass() lists them, and the triangles whose corners the
  // splits since then changed (their edges, or the corner an edge is listed
  // from): the next CollapsePass() starts from these instead of a scan.
  std::vector<uint64_t>  m_ShortEdges;
  std::vector<IndexType> m_ShortEdgesStale;
  bool                   m_ShortEdgesValid{ false };
  // The corners whose edge may still be short after a CollapsePass(): those
  // it visited and left short, and those it changed behind its position.
  // The LengthenPass() right after it starts from these instead of a scan.
  std::vector<IndexType> m_StillShort;
  std::vector<IndexType> m_LeftShort; // m_StillShort after the first CollapsePass(), incremental
  bool                   m_TrackStillShort{ false };
  bool                   m_StillShortValid{ false };
  std::vector<IndexType> m_NewIndex;    // scratch of Compact()
  std::vector<IndexType> m_SecondStart; // scratch of ReorderTable()
  std::vector<IndexType> m_NewCorner;
  std::vector<IndexType> m_ScratchCorner; // scratch of SetFirstCorners()
  std::vector<IndexType> m_TriangleKey;   // scratch of Compact()
  std::size_t            m_InputPoints{ 0 };
  Statistics             m_Statistics;
  double                 m_Min2{ 0.0 };
  double                 m_Max2{ 0.0 };

  // What OutputOfInput() reads: nothing, the identity (Compact() kept the
  // numbering), or m_NewIndex as Compact() left it.
  enum : uint8_t
  {
    InputMapNone,
    InputMapIdentity,
    InputMapNewIndex
  };
  uint8_t m_InputMap{ InputMapNone };

  // The queue of the next RunQueue() (a bit per corner), its workers: the
  // whole mesh's, and the parts'.
  std::vector<uint64_t>    m_Queue;
  std::size_t              m_PartitionSize{ 8192 };
  SweepWorker              m_SerialWorker;
  std::vector<SweepWorker> m_Workers;
  std::vector<uint8_t>     m_PartOf;           // the part of each point (RunQueue())
  std::size_t              m_PartOfParts{ 0 }; // for this many parts; 0: to be made
  // Scratch, kept between calls so that large arrays are not allocated (and
  // their pages faulted in) at every remeshing.
  std::vector<std::pair<double, IndexType>> m_SplitCandidates;
  std::vector<double>                       m_Moved;
  std::vector<IndexType>                    m_Root;
  std::vector<IndexType>                    m_Start;
  std::vector<IndexType>                    m_ScratchParents;
  std::vector<uint8_t>                      m_ScratchState;
  std::vector<uint8_t>                      m_ScratchTouched;
  std::vector<int32_t>                      m_ScratchValence;
  std::vector<Link>                         m_ScratchO;
};

enum : uint8_t
{
  RemesherFree = 0,
  RemesherBoundary = 1,
  RemesherFrozen = 2,
  RemesherRemoved = 3
};

inline int
DeformableMeshRemesher::OutputRing(IndexType v, std::vector<IndexType> & neighbours) const
{
  if (!m_TableValid || v >= m_State.size() || !this->Ring(v, neighbours, nullptr))
  {
    return 0;
  }
  return m_State[v] == RemesherBoundary ? 2 : 1;
}

inline double
DeformableMeshRemesher::Length2(IndexType a, IndexType b) const
{
  const double * p = m_X.data() + 3 * static_cast<std::size_t>(a);
  const double * q = m_X.data() + 3 * static_cast<std::size_t>(b);
  const double   d0 = p[0] - q[0];
  const double   d1 = p[1] - q[1];
  const double   d2 = p[2] - q[2];
  return d0 * d0 + d1 * d1 + d2 * d2;
}

inline void
DeformableMeshRemesher::TriangleNormal(const double * a, const double * b, const double * c, double n[3]) const
{
  const double u[3] = { b[0] - a[0], b[1] - a[1], b[2] - a[2] };
  const double v[3] = { c[0] - a[0], c[1] - a[1], c[2] - a[2] };
  n[0] = u[1] * v[2] - u[2] * v[1];
  n[1] = u[2] * v[0] - u[0] * v[2];
  n[2] = u[0] * v[1] - u[1] * v[0];
}

inline void
DeformableMeshRemesher::TriangleNormal(IndexType a, IndexType b, IndexType c, double n[3]) const
{
  this->TriangleNormal(m_X.data() + 3 * static_cast<std::size_t>(a),
                       m_X.data() + 3 * static_cast<std::size_t>(b),
                       m_X.data() + 3 * static_cast<std::size_t>(c),
                       n);
}

inline DeformableMeshRemesher::IndexType
DeformableMeshRemesher::NewVertex(const double * p, IndexType parent)
{
  const auto v = static_cast<IndexType>(m_State.size());
  m_X.insert(m_X.end(), p, p + 3);
  m_VertexCorner.push_back(Invalid);
  m_Valence.push_back(0);
  m_State.push_back(RemesherFree);
  m_Touched.push_back(TouchedSinceFlips | TouchedNow);
  m_Parents.push_back(parent);
  return v;
}

template <typename TBody>
void
DeformableMeshRemesher::ParallelFor(std::size_t n, TBody && body, std::size_t blockSize) const
{
  const std::size_t blocks = (n + blockSize - 1) / blockSize;
  if (m_Threader == nullptr || blocks < 2)
  {
    body(std::size_t{ 0 }, n);
    return;
  }
  m_Threader->SetNumberOfWorkUnits(std::max(1u, m_WorkUnits));
  m_Threader->ParallelizeArray(
    0,
    blocks,
    [&](SizeValueType block) {
      const std::size_t begin = block * blockSize;
      body(begin, std::min(n, begin + blockSize));
    },
    nullptr);
}

template <typename TCandidate, typename TBody>
void
DeformableMeshRemesher::Sweep(SweepInputs inputs, TCandidate && candidate, TBody && body)
{
  const std::size_t numberOfCorners = m_V.size();
  const std::size_t words = (numberOfCorners + 63) / 64;
  m_Queue.resize(words);
  this->ParallelFor(
    words,
    [&](std::size_t first, std::size_t last) {
      for (std::size_t w = first; w < last; ++w)
      {
        uint64_t          bits = 0;
        const std::size_t end = std::min<std::size_t>(64, numberOfCorners - 64 * w);
        for (std::size_t j = 0; j < end; ++j)
        {
          bits |= static_cast<uint64_t>(candidate(static_cast<IndexType>(64 * w + j))) << j;
        }
        m_Queue[w] = bits;
      }
    },
    1024);
  this->RunQueue(inputs, std::forward<TBody>(body));
}

template <typename TBody>
void
DeformableMeshRemesher::RunWorker(SweepWorker & worker, TBody & body)
{
  std::vector<uint64_t> & queue = *worker.queue;
  const std::size_t       words = queue.size();
  for (std::size_t w = 0; w < words; ++w)
  {
    // Read again after each corner: its operation may queue later corners
    // of the same word.
    for (uint64_t bits = queue[w]; bits != 0; bits = queue[w])
    {
      const unsigned int j = LowestBit(bits);
      queue[w] = bits & (bits - 1);
      worker.position = static_cast<IndexType>(64 * w + j);
      worker.deferThis = false;
      body(worker, worker.position);
      if (worker.deferThis)
      {
        worker.deferred.push_back(worker.position);
      }
    }
  }
}

inline std::size_t
DeformableMeshRemesher::NumberOfParts() const
{
  const std::size_t numberOfPoints = m_State.size();
  if (m_PartitionSize == 0 || numberOfPoints < 2 * m_PartitionSize)
  {
    return 1;
  }
  const std::size_t most = numberOfPoints / m_PartitionSize;
  return most >= 8 ? 8 : (most >= 4 ? 4 : 2);
}

template <typename TBody>
void
DeformableMeshRemesher::RunQueue(SweepInputs inputs, TBody && body)
{
  const std::size_t parts = this->NumberOfParts();
  SweepWorker &     serial = m_SerialWorker;
  serial.partitioned = false;
  serial.inputs = inputs;
  serial.queue = &m_Queue;
  serial.trackStillShort = m_TrackStillShort;
  serial.stillShort = &m_StillShort;
  serial.deferred.clear();
  serial.collapses = 0;
  serial.flips = 0;
  if (parts > 1)
  {
    // The parts: ranges of the input's point numbers, each point split from
    // an edge in the part of the point it comes from (Parents(); the new
    // points are numbered after the input's, far from their neighbours).
    const std::size_t numberOfPoints = m_State.size();
    const std::size_t words = m_Queue.size();
    // Kept from the last sweep of this Remesh() when the parts are the same:
    // the points added since (splits) come after, their parents before.
    const std::size_t known = m_PartOfParts == parts ? std::min(m_PartOf.size(), numberOfPoints) : 0;
    m_PartOf.resize(numberOfPoints);
    m_PartOfParts = parts;
    for (std::size_t v = known; v < numberOfPoints; ++v)
    {
      m_PartOf[v] = v < m_InputPoints ? static_cast<uint8_t>(v * parts / m_InputPoints) : m_PartOf[m_Parents[v]];
    }
    m_Workers.resize(parts);
    for (std::size_t p = 0; p < parts; ++p)
    {
      SweepWorker & worker = m_Workers[p];
      worker.partOf = m_PartOf.data();
      worker.numberOfPoints = numberOfPoints;
      worker.part = static_cast<uint8_t>(p);
      worker.partitioned = true;
      worker.inputs = inputs;
      worker.ownQueue.resize(words); // all 0: each run empties its queue
      worker.queue = &worker.ownQueue;
      worker.trackStillShort = m_TrackStillShort;
      worker.ownStillShort.clear();
      worker.stillShort = &worker.ownStillShort;
      worker.deferred.clear();
      worker.collapses = 0;
      worker.flips = 0;
    }
    for (std::size_t w = 0; w < words; ++w)
    {
      const uint64_t queued = m_Queue[w];
      m_Queue[w] = 0;
      for (uint64_t bits = queued; bits != 0; bits &= bits - 1)
      {
        const std::size_t c = 64 * w + LowestBit(bits);
        const IndexType   v = m_V[c];
        if (v != Invalid)
        {
          m_Workers[m_PartOf[v]].ownQueue[w] |= uint64_t{ 1 } << (c & 63);
        }
      }
    }
    // The parts in parallel; then what they deferred, in order.
    const auto runPart = [this, &body](SizeValueType p) { this->RunWorker(m_Workers[p], body); };
    if (m_Threader != nullptr)
    {
      m_Threader->SetNumberOfWorkUnits(std::max(1u, m_WorkUnits));
      m_Threader->ParallelizeArray(0, parts, runPart, nullptr);
    }
    else
    {
      for (std::size_t p = 0; p < parts; ++p)
      {
        runPart(p);
      }
    }
    for (SweepWorker & worker : m_Workers)
    {
      for (const IndexType c : worker.deferred)
      {
        m_Queue[c >> 6] |= uint64_t{ 1 } << (c & 63);
      }
      m_StillShort.insert(m_StillShort.end(), worker.ownStillShort.begin(), worker.ownStillShort.end());
      m_Statistics.collapses += worker.collapses;
      m_Statistics.flips += worker.flips;
    }
  }
  this->RunWorker(serial, body);
  m_Statistics.collapses += serial.collapses;
  m_Statistics.flips += serial.flips;
}

inline void
DeformableMeshRemesher::RequeueFan(SweepWorker & worker, IndexType v)
{
  if (!this->Ring(v, worker.ringA, &worker.cornersA))
  {
    return;
  }
  for (const IndexType k : worker.cornersA)
  {
    this->Requeue(worker, k);
    this->Requeue(worker, Next(k));
    this->Requeue(worker, Prev(k));
  }
}

inline void
DeformableMeshRemesher::Build(std::size_t numberOfPoints)
{
  const std::size_t numberOfCorners = m_V.size();
  // Corners of each vertex (CSR), to find the opposite half-edges.
  std::vector<IndexType> offsets(numberOfPoints + 1, 0);
  for (const IndexType v : m_V)
  {
    ++offsets[v + 1];
  }
  for (std::size_t i = 0; i < numberOfPoints; ++i)
  {
    offsets[i + 1] += offsets[i];
  }
  // With each corner, the vertices after and before it in its triangle: the
  // search of the twins below then reads them in sequence.
  std::vector<IndexType> corners(numberOfCorners);
  std::vector<IndexType> nextVertex(numberOfCorners);
  std::vector<IndexType> previousVertex(numberOfCorners);
  {
    std::vector<IndexType> fill(offsets.begin(), offsets.end() - 1);
    for (std::size_t t = 0; t < numberOfCorners; t += 3)
    {
      for (unsigned int k = 0; k < 3; ++k)
      {
        const IndexType slot = fill[m_V[t + k]]++;
        corners[slot] = static_cast<IndexType>(t + k);
        nextVertex[slot] = m_V[t + (k + 1) % 3];
        previousVertex[slot] = m_V[t + (k + 2) % 3];
      }
    }
  }
  m_O.assign(numberOfCorners, Boundary);
  this->ParallelFor(numberOfCorners, [&](std::size_t first, std::size_t last) {
    for (std::size_t c = first; c < last; ++c)
    {
      const IndexType a = m_V[c];
      const IndexType b = m_V[Next(static_cast<IndexType>(c))];
      unsigned        same = 0;
      unsigned        opposite = 0;
      IndexType       twin = Invalid;
      if (a == b)
      {
        m_O[c] = NonManifold;
        continue;
      }
      for (IndexType k = offsets[a]; k < offsets[a + 1]; ++k)
      {
        same += nextVertex[k] == b;
        opposite += previousVertex[k] == b; // half-edge b -> a ends at a
        if (previousVertex[k] == b)
        {
          twin = Prev(corners[k]);
        }
      }
      if (same == 1 && opposite == 1)
      {
        m_O[c] = twin;
      }
      else if (same == 1 && opposite == 0)
      {
        m_O[c] = Boundary;
      }
      else
      {
        m_O[c] = NonManifold;
      }
    }
  });
  m_VertexCorner.assign(numberOfPoints, Invalid);
  m_State.assign(numberOfPoints, RemesherFree);
  m_Valence.assign(numberOfPoints, 0);
  m_Touched.assign(numberOfPoints, TouchedSinceFlips);
  for (std::size_t i = 0; i < numberOfPoints; ++i)
  {
    if (offsets[i] == offsets[i + 1])
    {
      m_State[i] = RemesherRemoved; // used by no triangle: dropped
    }
    else
    {
      m_VertexCorner[i] = corners[offsets[i]];
    }
  }
  for (std::size_t c = 0; c < numberOfCorners; ++c)
  {
    const IndexType a = m_V[c];
    const IndexType b = m_V[Next(static_cast<IndexType>(c))];
    if (m_O[c] == NonManifold)
    {
      m_State[a] = RemesherFrozen;
      m_State[b] = RemesherFrozen;
    }
    else if (m_O[c] == Boundary)
    {
      m_State[a] = std::max<uint8_t>(m_State[a], RemesherBoundary);
      m_State[b] = std::max<uint8_t>(m_State[b], RemesherBoundary);
    }
    if (m_O[c] < 0 || static_cast<int64_t>(c) < m_O[c])
    {
      ++m_Valence[a];
      ++m_Valence[b];
    }
  }
  // A vertex whose corners do not form one fan is non-manifold: frozen.
  // (Ring() reads only the state of the vertex it walks around.)
  this->ParallelFor(numberOfPoints, [&](std::size_t first, std::size_t last) {
    std::vector<IndexType> ring;
    std::vector<IndexType> fan;
    for (std::size_t i = first; i < last; ++i)
    {
      if (m_State[i] == RemesherFree || m_State[i] == RemesherBoundary)
      {
        if (!this->Ring(static_cast<IndexType>(i), ring, &fan) || fan.size() != offsets[i + 1] - offsets[i])
        {
          m_State[i] = RemesherFrozen;
        }
      }
    }
  });
  // Start the ring walk of a boundary vertex anywhere: Ring() finds the end.
}

inline bool
DeformableMeshRemesher::Ring(IndexType v, std::vector<IndexType> & neighbours, std::vector<IndexType> * corners) const
{
  neighbours.clear();
  if (corners)
  {
    corners->clear();
  }
  const IndexType start = m_VertexCorner[v];
  if (start == Invalid || m_State[v] >= RemesherFrozen)
  {
    return false;
  }
  // Back to the first corner of the fan: reverse swing c -> Next(O[c]). The
  // fan of a free vertex is closed (it has no boundary edge): the walk
  // would come back to the start, so it is skipped.
  IndexType   c = start;
  std::size_t guard = 0;
  while (m_State[v] != RemesherFree)
  {
    const Link o = m_O[c];
    if (o == NonManifold)
    {
      return false;
    }
    if (o == Boundary)
    {
      break;
    }
    c = Next(static_cast<IndexType>(o));
    if (c == start)
    {
      break;
    }
    if (++guard > 1000)
    {
      return false;
    }
  }
  const IndexType first = c;
  guard = 0;
  while (true)
  {
    if (corners)
    {
      corners->push_back(c);
    }
    neighbours.push_back(m_V[Next(c)]);
    const IndexType p = Prev(c);
    const Link      o = m_O[p];
    if (o == NonManifold)
    {
      return false;
    }
    if (o == Boundary)
    {
      neighbours.push_back(m_V[p]);
      break;
    }
    c = static_cast<IndexType>(o);
    if (c == first)
    {
      break;
    }
    if (++guard > 1000)
    {
      return false;
    }
  }
  return true;
}

inline void
DeformableMeshRemesher::Split(IndexType c)
{
  const IndexType a = m_V[c];
  const IndexType nc = Next(c);
  const IndexType pc = Prev(c);
  const IndexType b = m_V[nc];
  const IndexType C = m_V[pc];
  const Link      o = m_O[c];
  const double *  pa = m_X.data() + 3 * static_cast<std::size_t>(a);
  const double *  pb = m_X.data() + 3 * static_cast<std::size_t>(b);
  const double    mid[3] = { 0.5 * (pa[0] + pb[0]), 0.5 * (pa[1] + pb[1]), 0.5 * (pa[2] + pb[2]) };
  const IndexType m = this->NewVertex(mid, a);
  if (o == Boundary)
  {
    m_State[m] = RemesherBoundary;
  }

  // Triangle t = (a, b, C) becomes (a, m, C); new t2 = (m, b, C).
  const auto t2 = static_cast<IndexType>(m_V.size());
  const Link oldNext = m_O[nc]; // twin of b -> C
  m_V[nc] = m;
  m_V.push_back(m);
  m_V.push_back(b);
  m_V.push_back(C);
  m_O.push_back(Boundary); // m -> b, set below
  m_O.push_back(oldNext);  // b -> C
  m_O.push_back(nc);       // C -> m
  m_O[nc] = t2 + 2;        // m -> C
  if (oldNext >= 0)
  {
    m_O[oldNext] = t2 + 1;
  }
  if (m_VertexCorner[b] == nc)
  {
    m_VertexCorner[b] = t2 + 1;
  }
  m_VertexCorner[m] = t2;
  ++m_Valence[C];
  m_Valence[m] = 3;
  m_Touched[a] = TouchedSinceFlips | TouchedNow;
  m_Touched[b] = TouchedSinceFlips | TouchedNow;
  m_Touched[C] = TouchedSinceFlips | TouchedNow;

  if (o >= 0)
  {
    // Triangle u = (b, a, D) with corner o at b becomes (b, m, D); new
    // u2 = (m, a, D).
    const auto      oc = static_cast<IndexType>(o);
    const IndexType no = Next(oc);
    const IndexType po = Prev(oc);
    const IndexType D = m_V[po];
    const auto      u2 = static_cast<IndexType>(m_V.size());
    const Link      oldNextU = m_O[no]; // twin of a -> D
    m_V[no] = m;
    m_V.push_back(m);
    m_V.push_back(a);
    m_V.push_back(D);
    m_O.push_back(c);        // m -> a
    m_O.push_back(oldNextU); // a -> D
    m_O.push_back(no);       // D -> m
    m_O[no] = u2 + 2;
    if (oldNextU >= 0)
    {
      m_O[oldNextU] = u2 + 1;
    }
    m_O[c] = u2;  // a -> m
    m_O[oc] = t2; // b -> m
    m_O[t2] = oc; // m -> b
    if (m_VertexCorner[a] == no)
    {
      m_VertexCorner[a] = u2 + 1;
    }
    ++m_Valence[D];
    m_Valence[m] = 4;
    m_Touched[D] = TouchedSinceFlips | TouchedNow;
  }
  else
  {
    m_O[c] = Boundary;
    m_O[t2] = Boundary;
  }
  m_SplitTouched.push_back(c / 3);
  m_SplitTouched.push_back(t2 / 3);
  if (o >= 0)
  {
    m_SplitTouched.push_back(static_cast<IndexType>(o) / 3);
    m_SplitTouched.push_back(t2 / 3 + 1);
  }
  if (m_ShortEdgesValid)
  {
    // Besides the triangles changed or made, those whose corner's twin
    // moved to a new corner: the corner their edge is listed from may change.
    m_ShortEdgesStale.insert(m_ShortEdgesStale.end(), m_SplitTouched.end() - (o >= 0 ? 4 : 2), m_SplitTouched.end());
    for (const Link k : { oldNext, o >= 0 ? m_O[t2 + 4] : Link{ Boundary } }) // t2 + 4: a -> D
    {
      if (k >= 0)
      {
        m_ShortEdgesStale.push_back(static_cast<IndexType>(k) / 3);
      }
    }
  }
  ++m_Statistics.splits;
}

inline bool
DeformableMeshRemesher::SplitPass(bool all)
{
  m_StillShortValid = false;
  // The long edges of the mesh as it is (split below each before the
  // shorter ones of its triangles). Each edge is listed from its corner of
  // lower index (or its only one).
  std::vector<std::pair<double, IndexType>> & candidates = m_SplitCandidates;
  candidates.clear();
  const auto consider = [this](IndexType c, std::vector<std::pair<double, IndexType>> & found) {
    const double length2 = this->SplittableLength2(c);
    if (length2 > 0.0)
    {
      found.emplace_back(length2, this->ListingCorner(c));
    }
  };
  if (all)
  {
    // In parallel: the candidates are sorted below, so their order here
    // does not matter. In the same scan, the short edges for the next
    // CollapsePass() (blocks of whole triangles and whole 64-bit words).
    constexpr std::size_t                                  blockSize = 192 * 341;
    const std::size_t                                      numberOfCorners = m_V.size();
    std::vector<std::vector<std::pair<double, IndexType>>> parts((numberOfCorners + blockSize - 1) / blockSize);
    m_ShortEdges.assign((numberOfCorners + 63) / 64, 0);
    this->ParallelFor(
      numberOfCorners,
      [&](std::size_t first, std::size_t last) {
        std::vector<std::pair<double, IndexType>> & part = parts[first / blockSize];
        uint64_t                                    bits = 0;
        // consider() (SplittableLength2(), ListingCorner()) and
        // ShortEdge() in one, a triangle at a time: its three points read
        // once for its three edges (the lengths as Length2() computes
        // them), without branches on which corner lists an edge (half of
        // them, in no order a predictor follows); the end-points' states
        // only for the long edges.
        for (std::size_t t = first; t < last; t += 3)
        {
          const IndexType v[3] = { m_V[t], m_V[t + 1], m_V[t + 2] };
          double          length2[3] = { 0.0, 0.0, 0.0 };
          if (v[0] != Invalid && v[1] != Invalid && v[2] != Invalid)
          {
            const double * p[3] = { m_X.data() + 3 * static_cast<std::size_t>(v[0]),
                                    m_X.data() + 3 * static_cast<std::size_t>(v[1]),
                                    m_X.data() + 3 * static_cast<std::size_t>(v[2]) };
            for (unsigned int k = 0; k < 3; ++k)
            {
              const double * a = p[k];
              const double * b = p[k == 2 ? 0 : k + 1];
              const double   d0 = a[0] - b[0];
              const double   d1 = a[1] - b[1];
              const double   d2 = a[2] - b[2];
              length2[k] = d0 * d0 + d1 * d1 + d2 * d2;
            }
          }
          for (unsigned int k = 0; k < 3; ++k)
          {
            const std::size_t c = t + k;
            const IndexType   a = v[k];
            const Link        o = m_O[c];
            const bool        valid = a != Invalid;
            const bool        above = o > static_cast<int64_t>(c);
            const bool        listed = valid & ((o < 0) | above);
            if (length2[k] > m_Max2 && listed && o != NonManifold && m_State[a] != RemesherFrozen &&
                m_State[v[k == 2 ? 0 : k + 1]] != RemesherFrozen)
            {
              part.emplace_back(length2[k], static_cast<IndexType>(c));
            }
            bits |= static_cast<uint64_t>(valid & above & (length2[k] < m_Min2)) << (c & 63);
            if ((c & 63) == 63 || c + 1 == last)
            {
              m_ShortEdges[c >> 6] = bits;
              bits = 0;
            }
          }
        }
      },
      blockSize);
    m_ShortEdgesStale.clear();
    m_ShortEdgesValid = true;
    for (const auto & part : parts)
    {
      candidates.insert(candidates.end(), part.begin(), part.end());
    }
  }
  else
  {
    // The listed triangles (a split lists four, some listed again by the
    // next split) as a bit each, then their corners considered once, in
    // parallel and in the order of the table: the candidates are sorted
    // below. (A sort of the list cost 40 to 60 ms a remeshing, serial, in
    // the benchmark's travel at a million points.)
    const std::size_t       numberOfTriangles = m_V.size() / 3;
    std::vector<uint64_t> & listed = m_SplitTouchedBits;
    listed.assign((numberOfTriangles + 63) / 64, 0);
    for (const IndexType t : m_SplitTouched)
    {
      listed[t >> 6] |= uint64_t{ 1 } << (t & 63);
    }
    constexpr std::size_t                                  wordsPerBlock = 1024;
    std::vector<std::vector<std::pair<double, IndexType>>> parts((listed.size() + wordsPerBlock - 1) / wordsPerBlock);
    this->ParallelFor(
      listed.size(),
      [&](std::size_t first, std::size_t last) {
        std::vector<std::pair<double, IndexType>> & part = parts[first / wordsPerBlock];
        for (std::size_t w = first; w < last; ++w)
        {
          for (uint64_t bits = listed[w]; bits != 0; bits &= bits - 1)
          {
            const auto t = static_cast<IndexType>(64 * w + LowestBit(bits));
            for (IndexType c = 3 * t; c < 3 * t + 3; ++c)
            {
              consider(c, part);
            }
          }
        }
      },
      wordsPerBlock);
    for (const auto & part : parts)
    {
      candidates.insert(candidates.end(), part.begin(), part.end());
    }
  }
  m_SplitTouched.clear();
  // Each edge before the shorter ones around it (splitting a long edge
  // before the shorter ones of its triangles avoids fans of thin triangles),
  // in corner order, the order of the table in memory: an edge waits while
  // one of its two triangles has a longer edge still to split, and the
  // edges that waited are swept again. Taken one by one in the order of
  // their lengths over the whole mesh, the candidates (about 7 % of a large
  // mesh's edges per remeshing in the benchmark) would reach the table at
  // random, a cache miss at each access. After 8 sweeps (a long gradient of
  // lengths along a strip of triangles), the edges still waiting are split
  // longest first.
  std::sort(candidates.begin(), candidates.end(), [](const auto & p, const auto & q) { return p.second < q.second; });
  candidates.erase(std::unique(candidates.begin(), candidates.end()), candidates.end());
  const bool any = !candidates.empty();
  const auto splitIfLong = [this](IndexType c) {
    // A split changes the edges of the corners of its triangles: check again.
    if (m_O[c] != NonManifold && this->Length2(m_V[c], m_V[Next(c)]) > m_Max2)
    {
      if (m_V.size() + 6 > static_cast<std::size_t>(std::numeric_limits<Link>::max()))
      {
        itkGenericExceptionMacro("DeformableMeshRemesher: the splits make more than 2^31 triangle corners.");
      }
      this->Split(c);
    }
  };
  for (unsigned int sweep = 0; sweep < 8 && !candidates.empty(); ++sweep)
  {
    std::size_t waiting = 0;
    for (const auto & candidate : candidates)
    {
      const IndexType c = candidate.second;
      if (this->SplitWaits(c))
      {
        candidates[waiting++] = candidate;
      }
      else
      {
        splitIfLong(c);
      }
    }
    candidates.resize(waiting);
  }
  for (auto & candidate : candidates)
  {
    const IndexType c = candidate.second;
    candidate.first = this->Length2(m_V[c], m_V[Next(c)]);
  }
  std::sort(candidates.begin(), candidates.end(), [](const auto & p, const auto & q) {
    return p.first > q.first || (p.first == q.first && p.second < q.second);
  });
  for (const auto & candidate : candidates)
  {
    splitIfLong(candidate.second);
  }
  return any;
}

inline double
DeformableMeshRemesher::SplittableLength2(IndexType c) const
{
  if (m_V[c] == Invalid || m_O[c] == NonManifold)
  {
    return 0.0;
  }
  const IndexType a = m_V[c];
  const IndexType b = m_V[Next(c)];
  if (m_State[a] == RemesherFrozen || m_State[b] == RemesherFrozen)
  {
    return 0.0;
  }
  const double length2 = this->Length2(a, b);
  return length2 > m_Max2 ? length2 : 0.0;
}

inline DeformableMeshRemesher::IndexType
DeformableMeshRemesher::ListingCorner(IndexType c) const
{
  const Link o = m_O[c];
  return o >= 0 && o < static_cast<int64_t>(c) ? static_cast<IndexType>(o) : c;
}

inline bool
DeformableMeshRemesher::SplitWaits(IndexType c) const
{
  // Whether another edge of the triangles of corner c is to be split first:
  // one that a split pass would split and longer than c's edge (or as long
  // and listed from a lower corner: a strict order, so that the longest
  // edge of all never waits).
  const Link o = m_O[c];
  if (m_V[c] == Invalid || o == NonManifold)
  {
    return false;
  }
  const double    length2 = this->Length2(m_V[c], m_V[Next(c)]);
  const IndexType listed = this->ListingCorner(c);
  for (const Link side : { static_cast<Link>(c), o })
  {
    if (side < 0)
    {
      continue;
    }
    const auto first = static_cast<IndexType>(side) - static_cast<IndexType>(side) % 3;
    for (IndexType k = first; k < first + 3; ++k)
    {
      if (k == c || static_cast<Link>(k) == o)
      {
        continue;
      }
      const double other2 = this->SplittableLength2(k);
      if (other2 > length2 || (other2 > 0.0 && other2 == length2 && this->ListingCorner(k) < listed))
      {
        return true;
      }
    }
  }
  return false;
}

inline bool
DeformableMeshRemesher::TryCollapse(SweepWorker & worker, IndexType c, bool fromTwin)
{
  const Link o = m_O[c];
  if (o < 0)
  {
    return false;
  }
  const IndexType a = m_V[c];
  const IndexType b = m_V[Next(c)];
  if (!worker.Reach(a) || !worker.Reach(b))
  {
    return false;
  }
  if (m_State[b] != RemesherFree)
  {
    // Into a boundary end-point, which stays where it is: from its side.
    return m_State[a] == RemesherFree && m_State[b] == RemesherBoundary && !fromTwin &&
           this->TryCollapse(worker, static_cast<IndexType>(o), true);
  }
  if (m_State[a] != RemesherFree && m_State[a] != RemesherBoundary)
  {
    return false;
  }
  const bool      keepA = m_State[a] == RemesherBoundary;
  const IndexType C = m_V[Prev(c)];
  const IndexType D = m_V[Prev(static_cast<IndexType>(o))];
  if (!worker.Reach(C) || !worker.Reach(D) || C == D || m_Valence[C] <= 3 || m_Valence[D] <= 3)
  {
    return false;
  }
  std::vector<IndexType> & ringA = worker.ringA;
  std::vector<IndexType> & ringB = worker.ringB;
  std::vector<IndexType> & cornersA = worker.cornersA;
  std::vector<IndexType> & cornersB = worker.cornersB;
  // Both fans and every point of them in reach: the operation reads and
  // changes nothing else.
  if (!this->ReachRing(worker, a, ringA, &cornersA) || !this->ReachRing(worker, b, ringB, &cornersB))
  {
    return false;
  }
  // Link condition: the common neighbours of a and b are C and D only.
  for (const IndexType w : ringA)
  {
    if (w != C && w != D && w != b && std::find(ringB.begin(), ringB.end(), w) != ringB.end())
    {
      return false;
    }
  }
  if (ringA.size() + ringB.size() < 8)
  {
    return false; // the result would have a vertex of valence below 3
  }
  const double *  pa = m_X.data() + 3 * static_cast<std::size_t>(a);
  const double *  pb = m_X.data() + 3 * static_cast<std::size_t>(b);
  const IndexType tc = c / 3;
  const IndexType to = static_cast<IndexType>(o) / 3;
  // The merged vertex goes to the midpoint, or else to either end-point.
  const auto acceptable = [&](const double * p) {
    // No edge longer than the maximum.
    for (const std::vector<IndexType> * ring : { &ringA, &ringB })
    {
      for (const IndexType w : *ring)
      {
        if (w == a || w == b)
        {
          continue;
        }
        const double * q = m_X.data() + 3 * static_cast<std::size_t>(w);
        const double   d0 = q[0] - p[0];
        const double   d1 = q[1] - p[1];
        const double   d2 = q[2] - p[2];
        if (d0 * d0 + d1 * d1 + d2 * d2 > m_Max2)
        {
          return false;
        }
      }
    }
    // No triangle turned around: each triangle of a or b other than the two
    // removed stays within 60 degrees of its former direction, and is not
    // degenerate.
    for (const std::vector<IndexType> * corners : { &cornersA, &cornersB })
    {
      for (const IndexType k : *corners)
      {
        if (k / 3 == tc || k / 3 == to)
        {
          continue;
        }
        const IndexType q1 = m_V[Next(k)];
        const IndexType q2 = m_V[Prev(k)];
        double          before[3];
        double          after[3];
        this->TriangleNormal(m_V[k], q1, q2, before);
        this->TriangleNormal(
          p, m_X.data() + 3 * static_cast<std::size_t>(q1), m_X.data() + 3 * static_cast<std::size_t>(q2), after);
        const double dot = before[0] * after[0] + before[1] * after[1] + before[2] * after[2];
        const double nb = std::sqrt(before[0] * before[0] + before[1] * before[1] + before[2] * before[2]);
        const double na = std::sqrt(after[0] * after[0] + after[1] * after[1] + after[2] * after[2]);
        if (!(dot > 0.5 * nb * na) || !(na > 1e-6 * m_Min2))
        {
          return false;
        }
      }
    }
    return true;
  };
  double mid[3] = { 0.5 * (pa[0] + pb[0]), 0.5 * (pa[1] + pb[1]), 0.5 * (pa[2] + pb[2]) };
  if (keepA)
  {
    std::copy(pa, pa + 3, mid);
    if (!acceptable(mid))
    {
      return false;
    }
  }
  else if (!acceptable(mid))
  {
    if (acceptable(pa))
    {
      std::copy(pa, pa + 3, mid);
    }
    else if (acceptable(pb))
    {
      std::copy(pb, pb + 3, mid);
    }
    else
    {
      return false;
    }
  }

  // Collapse: b's corners become a's, the two triangles go, their outer
  // half-edges are glued.
  for (const IndexType k : cornersB)
  {
    m_V[k] = a;
  }
  const IndexType nc = Next(c);
  const IndexType pc = Prev(c);
  const auto      oc = static_cast<IndexType>(o);
  const IndexType no = Next(oc);
  const IndexType po = Prev(oc);
  const Link      x = m_O[nc]; // C -> b
  const Link      y = m_O[pc]; // a -> C
  const Link      z = m_O[no]; // D -> a
  const Link      w = m_O[po]; // b -> D
  // x and w are interior (b is free); y and z may be boundary half-edges
  // when a is a boundary vertex.
  m_O[x] = y;
  if (y >= 0)
  {
    m_O[y] = x;
  }
  m_O[w] = z;
  if (z >= 0)
  {
    m_O[z] = w;
  }
  for (const IndexType k : { c, nc, pc, oc, no, po })
  {
    m_V[k] = Invalid;
    m_O[k] = NonManifold;
  }
  m_VertexCorner[a] = static_cast<IndexType>(y >= 0 ? y : w);
  m_VertexCorner[C] = static_cast<IndexType>(x);
  m_VertexCorner[D] = z >= 0 ? static_cast<IndexType>(z) : Next(static_cast<IndexType>(w));
  m_VertexCorner[b] = Invalid;
  m_Valence[a] = m_Valence[a] + m_Valence[b] - 4;
  --m_Valence[C];
  --m_Valence[D];
  m_Touched[a] = TouchedSinceFlips | TouchedNow;
  m_Touched[C] = TouchedSinceFlips | TouchedNow;
  m_Touched[D] = TouchedSinceFlips | TouchedNow;
  m_State[b] = RemesherRemoved;
  std::copy(mid, mid + 3, m_X.data() + 3 * static_cast<std::size_t>(a));
  ++worker.collapses;
  if (worker.inputs != SweepInputs::None)
  {
    // Every edge of a changed (its end-point, twin or length).
    for (const std::vector<IndexType> * corners : { &cornersA, &cornersB })
    {
      for (const IndexType k : *corners)
      {
        if (k / 3 != tc && k / 3 != to)
        {
          this->Requeue(worker, k);
          this->Requeue(worker, Prev(k));
        }
      }
    }
  }
  return true;
}

inline void
DeformableMeshRemesher::CollapsePass()
{
  // The short edges: those of the mesh before the pass, and those that the
  // collapses and flips of the pass change (queued again).
  const auto shortEdge = [this](IndexType c) { return this->ShortEdge(c); };
  const auto body = [&](SweepWorker & worker, IndexType c) {
    // A short edge that cannot be collapsed is flipped to the longer
    // diagonal when that one is within the band.
    if (m_V[c] == Invalid || !worker.Reach(m_V[c]) || !worker.Reach(m_V[Next(c)]))
    {
      return;
    }
    if (shortEdge(c) && !this->TryCollapse(worker, c) && !worker.deferThis)
    {
      this->TryFlip(worker, c, true);
    }
    if (!worker.deferThis && shortEdge(c))
    {
      worker.stillShort->push_back(c);
    }
  };
  m_StillShort.clear();
  m_TrackStillShort = true;
  m_StillShortValid = false;
  if (!m_ShortEdgesValid)
  {
    this->Sweep(SweepInputs::Lengths, shortEdge, body);
    m_TrackStillShort = false;
    m_StillShortValid = true;
    return;
  }
  // The short edges of the last SplitPass(true)'s scan, those of the
  // triangles its splits changed or made looked at again: the queue a scan
  // would give.
  m_Queue.swap(m_ShortEdges);
  m_Queue.resize((m_V.size() + 63) / 64, 0);
  for (const IndexType t : m_ShortEdgesStale)
  {
    for (IndexType c = 3 * t; c < 3 * t + 3; ++c)
    {
      const uint64_t bit = uint64_t{ 1 } << (c & 63);
      m_Queue[c >> 6] = shortEdge(c) ? (m_Queue[c >> 6] | bit) : (m_Queue[c >> 6] & ~bit);
    }
  }
  m_ShortEdgesStale.clear();
  m_ShortEdgesValid = false;
  this->RunQueue(SweepInputs::Lengths, body);
  m_TrackStillShort = false;
  m_StillShortValid = true;
}

inline bool
DeformableMeshRemesher::FlipImprovesValences(IndexType c, bool touchedOnly) const
{
  const Link o = m_O[c];
  if (o < static_cast<int64_t>(c))
  {
    return false; // boundary, frozen, or seen from its twin
  }
  const IndexType a = m_V[c];
  const IndexType b = m_V[Next(c)];
  const IndexType C = m_V[Prev(c)];
  const IndexType D = m_V[Prev(static_cast<IndexType>(o))];
  if (C == D || m_State[a] >= RemesherFrozen || m_State[b] >= RemesherFrozen || m_State[C] >= RemesherFrozen ||
      m_State[D] >= RemesherFrozen)
  {
    return false;
  }
  if (touchedOnly && ((m_Touched[a] | m_Touched[b] | m_Touched[C] | m_Touched[D]) & TouchedSinceFlips) == 0)
  {
    return false;
  }
  const auto deviation = [this](IndexType v, int change) {
    return std::abs(m_Valence[v] + change - (m_State[v] == RemesherBoundary ? 4 : 6));
  };
  return deviation(a, -1) + deviation(b, -1) + deviation(C, 1) + deviation(D, 1) <
         deviation(a, 0) + deviation(b, 0) + deviation(C, 0) + deviation(D, 0);
}

inline bool
DeformableMeshRemesher::TryFlip(SweepWorker & worker, IndexType c, bool lengthen)
{
  const Link o = m_O[c];
  if (o < 0)
  {
    return false;
  }
  const auto      oc = static_cast<IndexType>(o);
  const IndexType nc = Next(c);
  const IndexType pc = Prev(c);
  const IndexType no = Next(oc);
  const IndexType po = Prev(oc);
  const IndexType a = m_V[c];
  const IndexType b = m_V[nc];
  const IndexType C = m_V[pc];
  const IndexType D = m_V[po];
  if (!worker.Reach(a) || !worker.Reach(b) || !worker.Reach(C) || !worker.Reach(D) || C == D)
  {
    return false;
  }
  for (const IndexType v : { a, b, C, D })
  {
    if (m_State[v] >= RemesherFrozen)
    {
      return false;
    }
  }
  const auto target = [this](IndexType v) { return m_State[v] == RemesherBoundary ? 4 : 6; };
  const auto deviation = [&](int da, int db, int dc, int dd) {
    return std::abs(m_Valence[a] + da - target(a)) + std::abs(m_Valence[b] + db - target(b)) +
           std::abs(m_Valence[C] + dc - target(C)) + std::abs(m_Valence[D] + dd - target(D));
  };
  if (lengthen)
  {
    const double newLength2 = this->Length2(C, D);
    if (!(newLength2 > this->Length2(a, b) && newLength2 <= m_Max2) ||
        deviation(-1, -1, 1, 1) > deviation(0, 0, 0, 0) + 2)
    {
      return false;
    }
  }
  else if (deviation(-1, -1, 1, 1) >= deviation(0, 0, 0, 0))
  {
    return false;
  }
  if (m_Valence[a] <= 3 || m_Valence[b] <= 3)
  {
    return false;
  }
  // The new edge C - D must not exist.
  std::vector<IndexType> & ring = worker.ringA;
  if (!this->Ring(C, ring, nullptr) || std::find(ring.begin(), ring.end(), D) != ring.end())
  {
    return false;
  }
  // Geometry: the new triangles (a, D, C) and (b, C, D) keep the side of
  // the old ones and do not fold onto each other.
  double n1[3];
  double n2[3];
  double m1[3];
  double m2[3];
  this->TriangleNormal(a, b, C, n1);
  this->TriangleNormal(b, a, D, n2);
  this->TriangleNormal(a, D, C, m1);
  this->TriangleNormal(b, C, D, m2);
  const double old[3] = { n1[0] + n2[0], n1[1] + n2[1], n1[2] + n2[2] };
  const auto   dot = [](const double * u, const double * v) { return u[0] * v[0] + u[1] * v[1] + u[2] * v[2]; };
  const auto   norm = [&](const double * u) { return std::sqrt(dot(u, u)); };
  if (!(dot(m1, old) > 0.0) || !(dot(m2, old) > 0.0))
  {
    return false;
  }
  const double oldCos = dot(n1, n2) / (norm(n1) * norm(n2));
  const double newCos = dot(m1, m2) / (norm(m1) * norm(m2));
  if (!(newCos > 0.5 || newCos >= oldCos))
  {
    return false;
  }

  // t = (a, D, C), u = (b, C, D).
  const Link a1 = m_O[no]; // twin of a -> D
  const Link b1 = m_O[nc]; // twin of b -> C
  if (worker.partitioned)
  {
    // The triangles across a - D and b - C get new twins: their third
    // points in reach; with the valences as inputs, the fans of the four
    // points, whose edges are queued again.
    if ((a1 >= 0 && !worker.Reach(m_V[Prev(static_cast<IndexType>(a1))])) ||
        (b1 >= 0 && !worker.Reach(m_V[Prev(static_cast<IndexType>(b1))])))
    {
      return false;
    }
    if (worker.inputs == SweepInputs::Valences)
    {
      for (const IndexType v : { a, b, C, D })
      {
        if (!this->ReachRing(worker, v, worker.ringB, nullptr))
        {
          return false;
        }
      }
    }
  }
  m_V[nc] = D;
  m_V[no] = C;
  m_O[c] = a1;
  if (a1 >= 0)
  {
    m_O[a1] = c;
  }
  m_O[oc] = b1;
  if (b1 >= 0)
  {
    m_O[b1] = oc;
  }
  m_O[nc] = no;
  m_O[no] = nc;
  m_VertexCorner[a] = c;
  m_VertexCorner[b] = oc;
  m_VertexCorner[C] = pc;
  m_VertexCorner[D] = po;
  --m_Valence[a];
  --m_Valence[b];
  ++m_Valence[C];
  ++m_Valence[D];
  for (const IndexType v : { a, b, C, D })
  {
    m_Touched[v] = TouchedSinceFlips | TouchedNow;
  }
  ++worker.flips;
  if (worker.inputs == SweepInputs::Valences)
  {
    // The valence test of every edge with one of the four as an end-point
    // or an opposite vertex.
    for (const IndexType v : { a, b, C, D })
    {
      this->RequeueFan(worker, v);
    }
  }
  else if (worker.inputs == SweepInputs::Lengths)
  {
    for (const IndexType k : { c, nc, pc, oc, no, po })
    {
      this->Requeue(worker, k);
    }
  }
  return true;
}

inline void
DeformableMeshRemesher::FlipPass()
{
  m_StillShortValid = false;
  const auto body = [this](SweepWorker & worker, IndexType c) {
    if (m_V[c] != Invalid && m_O[c] >= static_cast<int64_t>(c))
    {
      this->TryFlip(worker, c);
    }
  };
  // The scan of the whole table (FlipImprovesValences()'s test, of touched
  // points only when incremental).
  const auto scan = [this, &body]() {
    this->Sweep(
      SweepInputs::Valences,
      [this](IndexType c) { return m_V[c] != Invalid && this->FlipImprovesValences(c, m_Local); },
      body);
  };
  if (!m_Local)
  {
    scan();
    return;
  }
  // Incremental: FlipImprovesValences() considers an edge only when one of
  // its four points (those of its two triangles) is touched. On a mesh at
  // rest a few thousand points of a million are: the corners of the
  // triangles around them, and their twins, are the only ones to test,
  // instead of a scan of the whole corner table. The same queue as the scan
  // (a touched point's fan holds the edge's triangle or its twin's), which
  // is run when the touched points are many or one's fan cannot be walked
  // (non-manifold).
  const std::size_t        numberOfPoints = m_State.size();
  const std::size_t        numberOfCorners = m_V.size();
  std::vector<IndexType> & touched = m_FlipSeeds;
  touched.clear();
  bool targeted = true;
  for (std::size_t v = 0; v < numberOfPoints && targeted; ++v)
  {
    if ((m_Touched[v] & TouchedSinceFlips) != 0 && m_VertexCorner[v] != Invalid && m_State[v] < RemesherFrozen)
    {
      touched.push_back(static_cast<IndexType>(v));
      targeted = 16 * touched.size() <= numberOfPoints;
    }
  }
  if (!targeted)
  {
    scan();
    return;
  }
  // The corners marked in two halves of the touched points in parallel,
  // each into its own bits, or-ed after (a set: the order does not
  // matter), then tested in parallel word by word (each word of the queue
  // written by one thread): 10 to 20 ms an update in series at a million
  // points at rest.
  const std::size_t       words = (numberOfCorners + 63) / 64;
  std::vector<uint64_t> & marked = m_FlipMarked;
  std::vector<uint64_t> & markedSecond = m_FlipMarkedSecond;
  marked.assign(words, 0);
  markedSecond.assign(words, 0);
  bool walked[2] = { true, true };
  this->Halves([&](std::size_t part) {
    std::vector<uint64_t> & bits = part == 0 ? marked : markedSecond;
    std::vector<IndexType>  ring;
    std::vector<IndexType>  corners;
    const std::size_t       half = touched.size() / 2;
    for (std::size_t k = part == 0 ? 0 : half; k < (part == 0 ? half : touched.size()); ++k)
    {
      if (!this->Ring(touched[k], ring, &corners))
      {
        walked[part] = false; // a fan that cannot be walked
        return;
      }
      for (const IndexType corner : corners)
      {
        const IndexType triangle = corner - corner % 3;
        for (IndexType c = triangle; c < triangle + 3; ++c)
        {
          bits[c >> 6] |= uint64_t{ 1 } << (c & 63);
          const Link o = m_O[c];
          if (o >= 0)
          {
            bits[static_cast<std::size_t>(o) >> 6] |= uint64_t{ 1 } << (o & 63);
          }
        }
      }
    }
  });
  if (!walked[0] || !walked[1])
  {
    scan();
    return;
  }
  m_Queue.assign(words, 0);
  this->ParallelFor(
    words,
    [&](std::size_t first, std::size_t last) {
      for (std::size_t w = first; w < last; ++w)
      {
        uint64_t queued = 0;
        for (uint64_t bits = marked[w] | markedSecond[w]; bits != 0; bits &= bits - 1)
        {
          const unsigned int bit = LowestBit(bits);
          const auto         c = static_cast<IndexType>(64 * w + bit);
          if (m_V[c] != Invalid && this->FlipImprovesValences(c, true))
          {
            queued |= uint64_t{ 1 } << bit;
          }
        }
        m_Queue[w] = queued;
      }
    },
    1024);
  this->RunQueue(SweepInputs::Valences, body);
}

inline void
DeformableMeshRemesher::Relax()
{
  m_StillShortValid = false;
  const std::size_t     numberOfPoints = m_State.size();
  std::vector<double> & moved = m_Moved;
  moved.resize(m_X.size());
  std::atomic<std::size_t> relaxed{ 0 };
  this->ParallelFor(numberOfPoints, [&](std::size_t first, std::size_t last) {
    // The block's positions as they are (in parallel: the copy of a large
    // mesh costs as much as a relaxation's arithmetic).
    std::copy(m_X.begin() + 3 * first, m_X.begin() + 3 * last, moved.begin() + 3 * first);
    std::vector<IndexType> ring; // per block
    std::vector<IndexType> corners;
    std::vector<double>    around;  // the neighbours' positions, the first again at the end
    std::vector<double>    normals; // of the vertex's triangles, as they are
    std::size_t            count = 0;
    for (std::size_t i = first; i < last; ++i)
    {
      if (m_State[i] != RemesherFree || (m_Local && m_RelaxSet[i] == 0) ||
          !this->Ring(static_cast<IndexType>(i), ring, &corners))
      {
        continue;
      }
      // A free vertex's fan is closed: the triangle of corner j is
      // (i, ring[j], ring[j + 1]). The neighbours' positions are read once.
      const std::size_t n = corners.size();
      bool              closed = ring.size() == n && n >= 3;
      for (std::size_t j = 0; closed && j < n; ++j)
      {
        closed = m_V[Prev(corners[j])] == ring[j + 1 < n ? j + 1 : 0];
      }
      if (!closed)
      {
        continue;
      }
      around.resize(3 * (n + 1));
      for (std::size_t j = 0; j <= n; ++j)
      {
        const double * w = m_X.data() + 3 * static_cast<std::size_t>(ring[j < n ? j : 0]);
        std::copy(w, w + 3, around.data() + 3 * j);
      }
      const double * p = m_X.data() + 3 * i;
      double         centroid[3] = { 0.0, 0.0, 0.0 };
      double         normal[3] = { 0.0, 0.0, 0.0 };
      for (std::size_t j = 0; j < n; ++j)
      {
        for (unsigned int d = 0; d < 3; ++d)
        {
          centroid[d] += around[3 * j + d];
        }
      }
      normals.resize(3 * n);
      for (std::size_t j = 0; j < n; ++j)
      {
        double * nj = normals.data() + 3 * j;
        this->TriangleNormal(p, around.data() + 3 * j, around.data() + 3 * j + 3, nj);
        for (unsigned int d = 0; d < 3; ++d)
        {
          normal[d] += nj[d];
        }
      }
      const double length = std::sqrt(normal[0] * normal[0] + normal[1] * normal[1] + normal[2] * normal[2]);
      if (!(length > 0.0))
      {
        continue;
      }
      double step[3];
      double along = 0.0;
      for (unsigned int d = 0; d < 3; ++d)
      {
        normal[d] /= length;
        step[d] = centroid[d] / static_cast<double>(n) - p[d];
        along += step[d] * normal[d];
      }
      double q[3];
      for (unsigned int d = 0; d < 3; ++d)
      {
        q[d] = p[d] + 0.5 * (step[d] - along * normal[d]);
      }
      // Refuse a move that turns one of the vertex's triangles around.
      bool keeps = true;
      for (std::size_t j = 0; j < n; ++j)
      {
        const double * before = normals.data() + 3 * j;
        double         after[3];
        this->TriangleNormal(q, around.data() + 3 * j, around.data() + 3 * j + 3, after);
        if (!(before[0] * after[0] + before[1] * after[1] + before[2] * after[2] > 0.0))
        {
          keeps = false;
          break;
        }
      }
      if (keeps)
      {
        std::copy(q, q + 3, moved.data() + 3 * i);
        ++count;
      }
    }
    relaxed += count;
  });
  m_Statistics.relaxed += relaxed;
  m_X.swap(moved);
}

inline bool
DeformableMeshRemesher::MoveKeepsBand(IndexType                      v,
                                      const double *                 q,
                                      IndexType                      other,
                                      const std::vector<IndexType> & ring,
                                      const std::vector<IndexType> & corners,
                                      double                         floor2) const
{
  for (const IndexType w : ring)
  {
    if (w == other)
    {
      continue;
    }
    const double * p = m_X.data() + 3 * static_cast<std::size_t>(w);
    const double   d2 = (p[0] - q[0]) * (p[0] - q[0]) + (p[1] - q[1]) * (p[1] - q[1]) + (p[2] - q[2]) * (p[2] - q[2]);
    if (!(d2 >= floor2) || d2 > m_Max2)
    {
      return false;
    }
  }
  const double * p = m_X.data() + 3 * static_cast<std::size_t>(v);
  for (const IndexType k : corners)
  {
    const double * q1 = m_X.data() + 3 * static_cast<std::size_t>(m_V[Next(k)]);
    const double * q2 = m_X.data() + 3 * static_cast<std::size_t>(m_V[Prev(k)]);
    double         before[3];
    double         after[3];
    this->TriangleNormal(p, q1, q2, before);
    this->TriangleNormal(q, q1, q2, after);
    const double dot = before[0] * after[0] + before[1] * after[1] + before[2] * after[2];
    const double nb = std::sqrt(before[0] * before[0] + before[1] * before[1] + before[2] * before[2]);
    const double na = std::sqrt(after[0] * after[0] + after[1] * after[1] + after[2] * after[2]);
    if (!(dot > 0.5 * nb * na))
    {
      return false;
    }
  }
  return true;
}

inline void
DeformableMeshRemesher::LengthenPass()
{
  const double minimum = std::sqrt(m_Min2);
  // The short edges of the mesh before the pass are all it visits. A move
  // that keeps the other edges of the two end-points within the band makes
  // no edge short; the fallback move may shorten one below the minimum, but
  // never to the length of the edge it lengthens: the shortest edge grows.
  const auto shortEdge = [this](IndexType c) {
    if (m_V[c] == Invalid || m_O[c] < static_cast<int64_t>(c))
    {
      return false;
    }
    const double length2 = this->Length2(m_V[c], m_V[Next(c)]);
    return length2 < m_Min2 && length2 > 0.0;
  };
  const auto body = [&](SweepWorker & worker, IndexType c) {
    if (m_V[c] == Invalid || !worker.Reach(m_V[c]) || !worker.Reach(m_V[Next(c)]) || !shortEdge(c))
    {
      return;
    }
    const IndexType a = m_V[c];
    const IndexType b = m_V[Next(c)];
    const double    length2 = this->Length2(a, b);
    const double    length = std::sqrt(length2);
    double *        pa = m_X.data() + 3 * static_cast<std::size_t>(a);
    double *        pb = m_X.data() + 3 * static_cast<std::size_t>(b);
    const double    u[3] = { (pb[0] - pa[0]) / length, (pb[1] - pa[1]) / length, (pb[2] - pa[2]) / length };
    const double    missing = 1.01 * minimum - length;
    // Both end-points half the way, or one of them all the way. The rings of
    // a and b are walked once, when first needed (nothing moves before the
    // move made); in a part, both at once, and every point of them in reach.
    std::vector<IndexType> & ringA = worker.ringA;
    std::vector<IndexType> & ringB = worker.ringB;
    std::vector<IndexType> & cornersA = worker.cornersA;
    std::vector<IndexType> & cornersB = worker.cornersB;
    int                      walked[2] = { -1, -1 };
    const auto               walk = [&](unsigned int which) {
      if (walked[which] < 0)
      {
        const IndexType v = which == 0 ? a : b;
        walked[which] = m_State[v] == RemesherFree &&
                        this->ReachRing(worker, v, which == 0 ? ringA : ringB, which == 0 ? &cornersA : &cornersB);
      }
    };
    if (worker.partitioned)
    {
      walk(0);
      walk(1);
      if (worker.deferThis)
      {
        return;
      }
    }
    const auto movable = [&](unsigned int which) {
      walk(which);
      return walked[which] == 1;
    };
    // First within the band; failing that, a move that leaves every other
    // edge of the two longer than this one is now: the shortest edge around
    // grows (a short edge hemmed in by edges just above the minimum).
    const double shares[3][2] = { { 0.5, 0.5 }, { 1.0, 0.0 }, { 0.0, 1.0 } };
    for (const double floor2 : { m_Min2, length2 * 1.0001 })
    {
      for (const auto & share : shares)
      {
        double qa[3];
        double qb[3];
        for (unsigned int d = 0; d < 3; ++d)
        {
          qa[d] = pa[d] - share[0] * missing * u[d];
          qb[d] = pb[d] + share[1] * missing * u[d];
        }
        if ((share[0] == 0.0 || (movable(0) && this->MoveKeepsBand(a, qa, b, ringA, cornersA, floor2))) &&
            (share[1] == 0.0 || (movable(1) && this->MoveKeepsBand(b, qb, a, ringB, cornersB, floor2))))
        {
          std::copy(qa, qa + 3, pa);
          std::copy(qb, qb + 3, pb);
          return;
        }
      }
    }
  };
  if (!m_StillShortValid)
  {
    this->Sweep(SweepInputs::None, shortEdge, body);
    return;
  }
  // The CollapsePass() just before left these corners possibly short: the
  // queue a scan would give.
  m_StillShortValid = false;
  m_Queue.assign((m_V.size() + 63) / 64, 0);
  for (const IndexType c : m_StillShort)
  {
    if (shortEdge(c))
    {
      m_Queue[c >> 6] |= uint64_t{ 1 } << (c & 63);
    }
  }
  this->RunQueue(SweepInputs::None, body);
}

inline bool
DeformableMeshRemesher::QueueSecondRound()
{
  m_SplitTouched.clear();
  const std::size_t numberOfCorners = m_V.size();
  const std::size_t most = numberOfCorners / 48; // a sixteenth of the triangles
  // At least two triangles per point of m_RelaxSet (six around a point,
  // each counted at most three times): too many without listing them.
  if (2 * static_cast<std::size_t>(std::count(m_RelaxSet.begin(), m_RelaxSet.end(), uint8_t{ 1 })) > most)
  {
    return false;
  }
  for (std::size_t c = 0; c < numberOfCorners && m_SplitTouched.size() <= most; c += 3)
  {
    const IndexType a = m_V[c];
    if (a != Invalid && (m_RelaxSet[a] | m_RelaxSet[m_V[c + 1]] | m_RelaxSet[m_V[c + 2]]) != 0)
    {
      m_SplitTouched.push_back(static_cast<IndexType>(c / 3));
    }
  }
  for (const IndexType c : m_LeftShort)
  {
    m_SplitTouched.push_back(c / 3);
  }
  if (m_SplitTouched.size() > most)
  {
    m_SplitTouched.clear();
    return false;
  }
  m_ShortEdges.assign((numberOfCorners + 63) / 64, 0);
  m_ShortEdgesStale.assign(m_SplitTouched.begin(), m_SplitTouched.end());
  m_ShortEdgesValid = true;
  return true;
}

inline void
DeformableMeshRemesher::Compact(std::vector<double> &    coordinates,
                                std::vector<IndexType> & triangles,
                                bool                     trianglesHoldInput)
{
  const std::size_t numberOfPoints = m_State.size();
  const bool        removed =
    m_Statistics.collapses > 0 || std::find(m_State.begin(), m_State.end(), RemesherRemoved) != m_State.end();
  if (numberOfPoints == m_InputPoints && !removed)
  {
    // No point added or removed: the numbering and the triangles' order stay
    // (flips changed some corners).
    m_InputMap = InputMapIdentity;
    coordinates.assign(m_X.begin(), m_X.end());
    if (m_Statistics.flips > 0 || !trianglesHoldInput)
    {
      triangles.assign(m_V.begin(), m_V.end());
    }
  }
  else
  {
    // Order: the input vertices kept, in order, each followed by the vertices
    // split from its edges (a counting sort on the input ancestor).
    std::vector<IndexType> & root = m_Root;
    root.resize(numberOfPoints);
    this->ParallelFor(numberOfPoints, [&](std::size_t first, std::size_t last) {
      for (std::size_t i = first; i < last; ++i)
      {
        // A split point's parent may be another split point: follow to the
        // input.
        IndexType r = static_cast<IndexType>(i);
        while (r >= m_InputPoints)
        {
          r = m_Parents[r];
        }
        root[i] = r;
      }
    });
    // A counting sort on the input ancestor: each input point kept counts
    // one in its own group, in parallel; the points split during this
    // remeshing (few at rest) are added to their ancestors' groups.
    const std::size_t        inputPoints = m_InputPoints;
    std::vector<IndexType> & start = m_Start;
    start.resize(inputPoints + 1);
    start[0] = 0;
    this->ParallelFor(inputPoints, [&](std::size_t first, std::size_t last) {
      for (std::size_t i = first; i < last; ++i)
      {
        start[i + 1] = m_State[i] != RemesherRemoved ? 1 : 0;
      }
    });
    for (std::size_t i = inputPoints; i < numberOfPoints; ++i)
    {
      if (m_State[i] != RemesherRemoved)
      {
        ++start[root[i] + 1];
      }
    }
    for (std::size_t i = 0; i < inputPoints; ++i)
    {
      start[i + 1] += start[i];
    }
    const IndexType          kept = start[inputPoints];
    std::vector<IndexType> & newIndex = m_NewIndex;
    newIndex.resize(numberOfPoints);
    std::vector<IndexType> & parents = m_ScratchParents;
    std::vector<uint8_t> &   state = m_ScratchState;
    std::vector<uint8_t> &   touched = m_ScratchTouched;
    std::vector<int32_t> &   valence = m_ScratchValence;
    parents.resize(kept);
    state.resize(kept);
    touched.resize(kept);
    valence.resize(kept);
    coordinates.resize(3 * static_cast<std::size_t>(kept));
    const auto place = [&](std::size_t i, IndexType k) {
      newIndex[i] = k;
      parents[k] = root[i];
      state[k] = m_State[i];
      touched[k] = m_Touched[i];
      valence[k] = m_Valence[i];
      std::copy(m_X.data() + 3 * i, m_X.data() + 3 * i + 3, coordinates.data() + 3 * static_cast<std::size_t>(k));
    };
    // Each input point first in its group (in parallel: each touches its own
    // group's cursor), then the split points in the order of their numbers,
    // as a serial pass over all the points in order places them.
    this->ParallelFor(inputPoints, [&](std::size_t first, std::size_t last) {
      for (std::size_t i = first; i < last; ++i)
      {
        if (m_State[i] != RemesherRemoved)
        {
          place(i, start[i]++);
        }
        else
        {
          newIndex[i] = Invalid;
        }
      }
    });
    for (std::size_t i = inputPoints; i < numberOfPoints; ++i)
    {
      if (m_State[i] != RemesherRemoved)
      {
        place(i, start[root[i]]++);
      }
      else
      {
        newIndex[i] = Invalid;
      }
    }
    m_Parents.swap(parents);
    m_State.swap(state);
    m_Touched.swap(touched);
    m_Valence.swap(valence);
    m_InputMap = InputMapNewIndex;

    // A table that does not describe the output is built again next time.
    m_TableValid = this->ReorderTable(newIndex, kept, triangles);
  }
  this->SetFirstCorners();
}

inline void
DeformableMeshRemesher::SetFirstCorners()
{
  // As Build() sets it: the first corner of each vertex. The corners in two
  // halves, each walked backwards in parallel with the other (the second
  // into a scratch array), then a vertex's first corner is its first half's
  // if it has one (a serial walk cost 10 ms a remeshing at a million points).
  const std::size_t        numberOfPoints = m_State.size();
  const std::size_t        numberOfCorners = m_V.size();
  const std::size_t        half = numberOfCorners / 6 * 3;
  std::vector<IndexType> & second = m_ScratchCorner;
  m_VertexCorner.assign(numberOfPoints, Invalid);
  second.assign(numberOfPoints, Invalid);
  this->Halves([&](std::size_t part) {
    std::vector<IndexType> & first = part == 0 ? m_VertexCorner : second;
    const std::size_t        begin = part == 0 ? 0 : half;
    for (std::size_t c = part == 0 ? half : numberOfCorners; c-- > begin;)
    {
      first[m_V[c]] = static_cast<IndexType>(c);
    }
  });
  this->ParallelFor(numberOfPoints, [&](std::size_t first, std::size_t last) {
    for (std::size_t v = first; v < last; ++v)
    {
      if (m_VertexCorner[v] == Invalid)
      {
        m_VertexCorner[v] = second[v];
      }
    }
  });
}

template <typename TBody>
void
DeformableMeshRemesher::Halves(TBody && body) const
{
  if (m_Threader == nullptr)
  {
    body(std::size_t{ 0 });
    body(std::size_t{ 1 });
    return;
  }
  m_Threader->SetNumberOfWorkUnits(2);
  m_Threader->ParallelizeArray(
    0, 2, [&](SizeValueType part) { body(static_cast<std::size_t>(part)); }, nullptr);
  m_Threader->SetNumberOfWorkUnits(std::max(1u, m_WorkUnits)); // as ParallelFor() leaves it
}

inline bool
DeformableMeshRemesher::ReorderTable(const std::vector<IndexType> & newIndex,
                                     std::size_t                    newPoints,
                                     std::vector<IndexType> &       triangles)
{
  const std::size_t numberOfCorners = m_V.size();
  // The corner table in the new numbering: the remaining triangles
  // ordered by their smallest new vertex (a stable counting sort), so that
  // the corners of a fan sit near each other in memory as the vertices
  // do. In the order of the table, the triangles that splits appended
  // would lie far from their neighbours, in the order of their edge
  // lengths.
  std::vector<IndexType> & newCorner = m_NewCorner;
  newCorner.resize(numberOfCorners);
  // The keys in parallel (three reads of the new numbers each); the
  // counting sort itself reads them in order.
  const std::size_t        numberOfTriangles = numberOfCorners / 3;
  std::vector<IndexType> & key = m_TriangleKey;
  key.resize(numberOfTriangles);
  this->ParallelFor(numberOfTriangles, [&](std::size_t first, std::size_t last) {
    for (std::size_t t = first; t < last; ++t)
    {
      const std::size_t c = 3 * t;
      key[t] = m_V[c] == Invalid ? Invalid : std::min({ newIndex[m_V[c]], newIndex[m_V[c + 1]], newIndex[m_V[c + 2]] });
    }
  });
  // The stable counting sort in two halves of the triangles, each counted
  // and placed in parallel with the other: the triangles of a key from the
  // first half, then those from the second, each half in its order (the
  // order of a serial counting sort).
  const std::size_t        half = numberOfTriangles / 2;
  std::vector<IndexType> & start = m_Start;
  std::vector<IndexType> & secondStart = m_SecondStart;
  start.assign(newPoints + 1, 0);
  secondStart.assign(newPoints + 1, 0);
  const auto count = [&](std::size_t part) {
    std::vector<IndexType> & counts = part == 0 ? start : secondStart;
    for (std::size_t t = part == 0 ? 0 : half; t < (part == 0 ? half : numberOfTriangles); ++t)
    {
      if (key[t] != Invalid)
      {
        ++counts[key[t] + 1];
      }
    }
  };
  this->Halves(count);
  // Per key: the first half's triangles from start[k], the second half's
  // from secondStart[k].
  IndexType offset = 0;
  for (std::size_t k = 0; k < newPoints; ++k)
  {
    const IndexType first = start[k + 1];
    const IndexType second = secondStart[k + 1];
    start[k] = offset;
    secondStart[k] = offset + first;
    offset += first + second;
  }
  start[newPoints] = offset;
  this->Halves([&](std::size_t part) {
    std::vector<IndexType> & cursor = part == 0 ? start : secondStart;
    for (std::size_t t = part == 0 ? 0 : half; t < (part == 0 ? half : numberOfTriangles); ++t)
    {
      const IndexType k = key[t];
      const IndexType nt = k != Invalid ? 3 * cursor[k]++ : Invalid;
      newCorner[3 * t] = nt;
      newCorner[3 * t + 1] = k != Invalid ? nt + 1 : Invalid;
      newCorner[3 * t + 2] = k != Invalid ? nt + 2 : Invalid;
    }
  });
  const IndexType next = 3 * offset;
  triangles.resize(next);
  std::vector<Link> & opposite = m_ScratchO;
  opposite.resize(next);
  std::atomic<bool> consistent{ true };
  this->ParallelFor(numberOfCorners, [&](std::size_t first, std::size_t last) {
    bool consistentHere = true;
    for (std::size_t c = first; c < last; ++c)
    {
      const IndexType nc = newCorner[c];
      if (nc == Invalid)
      {
        continue;
      }
      triangles[nc] = newIndex[m_V[c]];
      const Link o = m_O[c];
      if (o < 0)
      {
        opposite[nc] = o;
      }
      else
      {
        const IndexType no = newCorner[static_cast<std::size_t>(o)];
        consistentHere = consistentHere && no != Invalid;
        opposite[nc] = no != Invalid ? static_cast<Link>(no) : NonManifold;
      }
    }
    if (!consistentHere)
    {
      consistent = false;
    }
  });
  m_V.assign(triangles.begin(), triangles.end());
  m_O.swap(opposite);
  return consistent;
}

inline bool
DeformableMeshRemesher::RenumberOutput(const std::vector<IndexType> & order, std::vector<IndexType> & triangles)
{
  if (!m_TableValid)
  {
    return false;
  }
  const std::size_t numberOfPoints = m_State.size();
  const std::size_t numberOfCorners = m_V.size();
  if (order.size() != numberOfPoints)
  {
    itkGenericExceptionMacro("DeformableMeshRemesher: a renumbering of " << order.size() << " points for an output of "
                                                                         << numberOfPoints << ".");
  }
  std::atomic<bool> differs{ triangles.size() != numberOfCorners };
  if (!differs)
  {
    this->ParallelFor(
      numberOfCorners,
      [&](std::size_t first, std::size_t last) {
        if (!std::equal(triangles.begin() + first, triangles.begin() + last, m_V.begin() + first))
        {
          differs = true;
        }
      },
      65536);
  }
  if (differs)
  {
    itkGenericExceptionMacro("DeformableMeshRemesher: RenumberOutput() needs the triangles of the last Remesh()'s "
                             "output.");
  }
  m_InputMap = InputMapNone; // m_NewIndex becomes the rank
  std::vector<IndexType> & rank = m_NewIndex;
  rank.assign(numberOfPoints, Invalid);
  for (std::size_t k = 0; k < numberOfPoints; ++k)
  {
    if (order[k] >= numberOfPoints || rank[order[k]] != Invalid)
    {
      itkGenericExceptionMacro("DeformableMeshRemesher: the renumbering is not a permutation of the output's points.");
    }
    rank[order[k]] = static_cast<IndexType>(k);
  }
  // The per-point arrays, in parallel.
  const auto permute = [this, &order, numberOfPoints](auto & values, auto & scratch) {
    scratch.resize(numberOfPoints);
    this->ParallelFor(numberOfPoints, [&](std::size_t first, std::size_t last) {
      for (std::size_t k = first; k < last; ++k)
      {
        scratch[k] = values[order[k]];
      }
    });
    values.swap(scratch);
  };
  permute(m_State, m_ScratchState);
  permute(m_Touched, m_ScratchTouched);
  permute(m_Valence, m_ScratchValence);
  permute(m_Parents, m_ScratchParents);
  std::vector<double> & x = m_Moved;
  x.resize(3 * numberOfPoints);
  this->ParallelFor(numberOfPoints, [&](std::size_t first, std::size_t last) {
    for (std::size_t k = first; k < last; ++k)
    {
      std::copy(m_X.data() + 3 * static_cast<std::size_t>(order[k]),
                m_X.data() + 3 * static_cast<std::size_t>(order[k]) + 3,
                x.data() + 3 * k);
    }
  });
  m_X.swap(x);
  // The triangles by their smallest new point, as Compact() orders them: in
  // the table's old order they would be read at random by a scan in the new
  // numbering.
  this->ReorderTable(rank, numberOfPoints, triangles);
  this->SetFirstCorners();
  return true;
}

inline bool
DeformableMeshRemesher::Edges(std::vector<uint64_t> & edges) const
{
  edges.clear();
  bool unique = true;
  for (std::size_t c = 0; c < m_V.size(); ++c)
  {
    const Link o = m_O[c];
    if (o < 0 || static_cast<int64_t>(c) < o)
    {
      const uint64_t a = m_V[c];
      const uint64_t b = m_V[Next(static_cast<IndexType>(c))];
      edges.push_back(std::min(a, b) << 32 | std::max(a, b));
      unique = unique && o != NonManifold;
    }
  }
  return unique;
}

inline DeformableMeshRemesher::Statistics
DeformableMeshRemesher::Remesh(std::vector<double> &    coordinates,
                               std::size_t              numberOfPoints,
                               std::vector<IndexType> & triangles)
{
  return this->Remesh(coordinates, numberOfPoints, triangles, coordinates, triangles);
}

inline DeformableMeshRemesher::Statistics
DeformableMeshRemesher::Remesh(const std::vector<double> &    inputCoordinates,
                               std::size_t                    numberOfPoints,
                               const std::vector<IndexType> & inputTriangles,
                               std::vector<double> &          coordinates,
                               std::vector<IndexType> &       outputTriangles)
{
  // The inputs are read only before Compact() writes the outputs: they may
  // be the same vectors.
  const std::vector<IndexType> & triangles = inputTriangles;
  if (!(m_TargetEdgeLength > 0.0 && std::isfinite(m_TargetEdgeLength)))
  {
    itkGenericExceptionMacro("DeformableMeshRemesher: the target edge length "
                             "must be finite and positive; it is "
                             << m_TargetEdgeLength << ".");
  }
  if (!(m_MinimumRatio > 0.0 && m_MinimumRatio < m_MaximumRatio && std::isfinite(m_MaximumRatio)))
  {
    itkGenericExceptionMacro("DeformableMeshRemesher: the edge length ratios "
                             "must satisfy 0 < minimum < maximum; they "
                             "are "
                             << m_MinimumRatio << " and " << m_MaximumRatio << ".");
  }
  if (triangles.size() % 3 != 0 || inputCoordinates.size() < 3 * numberOfPoints ||
      numberOfPoints >= std::numeric_limits<IndexType>::max() / 2 ||
      triangles.size() >= static_cast<std::size_t>(std::numeric_limits<Link>::max() / 2))
  {
    itkGenericExceptionMacro("DeformableMeshRemesher: " << triangles.size() << " triangle indices and "
                                                        << inputCoordinates.size() << " coordinates for "
                                                        << numberOfPoints << " points.");
  }
  // The table of the last output describes this input when it is given
  // again: no need to build it, nor to check the triangles' point numbers
  // (the table's are those of its points).
  // Locked vertices are frozen in a table of their own, which is not kept.
  const bool lock = std::find(m_Locked.begin(), m_Locked.end(), uint8_t{ 1 }) != m_Locked.end();
  bool       reuse = !lock && m_TableValid && m_State.size() == numberOfPoints && m_V.size() == triangles.size();
  if (reuse)
  {
    std::atomic<bool> differs{ false };
    this->ParallelFor(
      triangles.size(),
      [&](std::size_t first, std::size_t last) {
        if (!std::equal(triangles.begin() + first, triangles.begin() + last, m_V.begin() + first))
        {
          differs = true;
        }
      },
      65536);
    reuse = !differs;
  }
  if (!reuse)
  {
    // In parallel (a serial pass over the corners costs about as much as a
    // remeshing's operations on a large mesh at rest); the first bad point for
    // the message.
    std::atomic<bool> outOfRange{ false };
    this->ParallelFor(
      triangles.size(),
      [&](std::size_t first, std::size_t last) {
        IndexType largest = 0;
        for (std::size_t c = first; c < last; ++c)
        {
          largest = std::max(largest, triangles[c]);
        }
        if (last > first && largest >= numberOfPoints)
        {
          outOfRange = true;
        }
      },
      65536);
    if (outOfRange)
    {
      for (const IndexType v : triangles)
      {
        if (v >= numberOfPoints)
        {
          itkGenericExceptionMacro("DeformableMeshRemesher: a triangle refers to point " << v << " of "
                                                                                         << numberOfPoints << ".");
        }
      }
    }
  }
  m_Statistics = Statistics{};
  m_ShortEdgesValid = false;
  m_StillShortValid = false;
  m_InputMap = InputMapNone;
  m_InputPoints = numberOfPoints;
  m_PartOfParts = 0;
  m_Min2 = GetMinimumEdgeLength() * GetMinimumEdgeLength();
  m_Max2 = GetMaximumEdgeLength() * GetMaximumEdgeLength();
  m_X.assign(inputCoordinates.begin(), inputCoordinates.begin() + 3 * numberOfPoints);
  m_Parents.resize(numberOfPoints);
  std::iota(m_Parents.begin(), m_Parents.end(), IndexType{ 0 });
  std::vector<uint8_t> locked;
  locked.swap(m_Locked);
  m_TableValid = false;
  if (!reuse)
  {
    m_V.assign(triangles.begin(), triangles.end());
    this->Build(numberOfPoints);
  }
  if (lock)
  {
    const std::size_t count = std::min(locked.size(), numberOfPoints);
    for (std::size_t i = 0; i < count; ++i)
    {
      if (locked[i] != 0 && m_State[i] != RemesherRemoved)
      {
        m_State[i] = RemesherFrozen;
      }
    }
  }
  m_TableValid = true;
  m_Local = m_Incremental && reuse;
  if (!m_Local)
  {
    m_Touched.assign(m_State.size(), TouchedSinceFlips);
  }
  else
  {
    for (uint8_t & touched : m_Touched)
    {
      touched &= TouchedSinceFlips;
    }
  }
  for (unsigned int pass = 0; pass < 16 && this->SplitPass(pass == 0); ++pass)
  {}
  this->CollapsePass();
  if (m_Local)
  {
    m_LeftShort.assign(m_StillShort.begin(), m_StillShort.end());
  }
  this->FlipPass();
  if (m_Local)
  {
    // The points of the triangles with a touched point: the touched points
    // and their rings.
    // The triangles found in parallel (a serial pass over the corners costs
    // several milliseconds at a million points), their points marked after.
    m_RelaxSet.assign(m_State.size(), 0);
    const std::size_t                   numberOfTriangles = m_V.size() / 3;
    constexpr std::size_t               blockSize = 65536;
    std::vector<std::vector<IndexType>> parts((numberOfTriangles + blockSize - 1) / blockSize);
    this->ParallelFor(
      numberOfTriangles,
      [&](std::size_t first, std::size_t last) {
        std::vector<IndexType> & part = parts[first / blockSize];
        for (std::size_t c = 3 * first; c < 3 * last; c += 3)
        {
          const IndexType a = m_V[c];
          if (a != Invalid && ((m_Touched[a] | m_Touched[m_V[c + 1]] | m_Touched[m_V[c + 2]]) & TouchedSinceFlips) != 0)
          {
            part.insert(part.end(), { a, m_V[c + 1], m_V[c + 2] });
          }
        }
      },
      blockSize);
    for (const auto & part : parts)
    {
      for (const IndexType v : part)
      {
        m_RelaxSet[v] = 1;
      }
    }
  }
  for (unsigned int sweep = 0; sweep < m_RelaxationSweeps; ++sweep)
  {
    this->Relax();
  }
  // From here on, what the next Remesh() flips and relaxes.
  for (uint8_t & touched : m_Touched)
  {
    touched &= TouchedNow;
  }
  if (m_Local)
  {
    // Since the first round's scan, the first round's operations changed
    // edges around the points they touched and the relaxation moved only
    // points of m_RelaxSet, which holds those: the edges that may have left
    // the band are those of the triangles with a point in m_RelaxSet, and
    // the short edges the first collapse pass could not remove. The second
    // round looks at these instead of scanning the whole mesh again, unless
    // they are so many that the parallel scan costs less.
    const bool queued = this->QueueSecondRound();
    for (unsigned int pass = 0; pass < 16 && this->SplitPass(!queued && pass == 0); ++pass)
    {}
  }
  else
  {
    for (unsigned int pass = 0; pass < 16 && this->SplitPass(pass == 0); ++pass)
    {}
  }
  this->CollapsePass();
  this->LengthenPass();
  this->Compact(coordinates, outputTriangles, &outputTriangles == &inputTriangles);
  if (lock)
  {
    m_TableValid = false; // its frozen states are not the mesh's
  }
  return m_Statistics;
}

inline bool
DeformableMeshRemesher::IsOutputClosed() const
{
  const std::size_t numberOfCorners = m_V.size();
  if (!m_TableValid || numberOfCorners < 12 || m_O.size() != numberOfCorners)
  {
    return false;
  }
  std::atomic<bool> closed{ true };
  this->ParallelFor(numberOfCorners, [&](std::size_t first, std::size_t last) {
    for (std::size_t c = first; c < last; ++c)
    {
      if (m_O[c] < 0)
      {
        closed = false;
        return;
      }
    }
  });
  return closed;
}

inline std::vector<uint64_t>
DeformableMeshRemesher::MortonKeys(const double * coordinates, std::size_t numberOfPoints)
{
  double lower[3] = { std::numeric_limits<double>::max(),
                      std::numeric_limits<double>::max(),
                      std::numeric_limits<double>::max() };
  double upper[3] = { std::numeric_limits<double>::lowest(),
                      std::numeric_limits<double>::lowest(),
                      std::numeric_limits<double>::lowest() };
  for (std::size_t i = 0; i < numberOfPoints; ++i)
  {
    for (unsigned int d = 0; d < 3; ++d)
    {
      lower[d] = std::min(lower[d], coordinates[3 * i + d]);
      upper[d] = std::max(upper[d], coordinates[3 * i + d]);
    }
  }
  const double extent = std::max({ upper[0] - lower[0], upper[1] - lower[1], upper[2] - lower[2], 1e-300 });
  const double scale = 2097151.0 / extent;
  // Spreads the 21 bits of v two bits apart.
  const auto spread = [](uint64_t v) {
    v &= 0x1fffff;
    v = (v | v << 32) & 0x1f00000000ffffULL;
    v = (v | v << 16) & 0x1f0000ff0000ffULL;
    v = (v | v << 8) & 0x100f00f00f00f00fULL;
    v = (v | v << 4) & 0x10c30c30c30c30c3ULL;
    v = (v | v << 2) & 0x1249249249249249ULL;
    return v;
  };
  std::vector<uint64_t> keys(numberOfPoints);
  for (std::size_t i = 0; i < numberOfPoints; ++i)
  {
    uint64_t code = 0;
    for (unsigned int d = 0; d < 3; ++d)
    {
      const auto q =
        static_cast<uint64_t>(std::max(0.0, std::min(2097151.0, (coordinates[3 * i + d] - lower[d]) * scale)));
      code |= spread(q) << d;
    }
    keys[i] = code;
  }
  return keys;
}

inline std::vector<DeformableMeshRemesher::IndexType>
DeformableMeshRemesher::LocalityOrder(const double * coordinates, std::size_t numberOfPoints)
{
  const std::vector<uint64_t> keys = MortonKeys(coordinates, numberOfPoints);
  std::vector<IndexType>      order(numberOfPoints);
  std::iota(order.begin(), order.end(), IndexType{ 0 });
  std::stable_sort(order.begin(), order.end(), [&keys](IndexType a, IndexType b) { return keys[a] < keys[b]; });
  return order;
}

inline std::vector<DeformableMeshRemesher::IndexType>
DeformableMeshRemesher::BreadthFirstOrder(const double *                coordinates,
                                          std::size_t                   numberOfPoints,
                                          const std::vector<uint64_t> & edges)
{
  std::vector<IndexType> offsets(numberOfPoints + 1, 0);
  for (const uint64_t e : edges)
  {
    ++offsets[(e >> 32) + 1];
    ++offsets[(e & 0xffffffffULL) + 1];
  }
  for (std::size_t i = 0; i < numberOfPoints; ++i)
  {
    offsets[i + 1] += offsets[i];
  }
  std::vector<IndexType> neighbours(offsets[numberOfPoints]);
  {
    std::vector<IndexType> fill(offsets.begin(), offsets.end() - 1);
    for (const uint64_t e : edges)
    {
      const auto a = static_cast<IndexType>(e >> 32);
      const auto b = static_cast<IndexType>(e & 0xffffffffULL);
      neighbours[fill[a]++] = b;
      neighbours[fill[b]++] = a;
    }
  }
  return BreadthFirstWalk(coordinates, numberOfPoints, offsets, neighbours, true);
}

inline std::vector<DeformableMeshRemesher::IndexType>
DeformableMeshRemesher::OutputBreadthFirstOrder(const double * coordinates) const
{
  if (!m_TableValid)
  {
    return {};
  }
  // Each half-edge gives its end to its start's list; a half-edge without a
  // twin (boundary, non-manifold) its start to its end's too. A point may be
  // listed twice around a non-manifold edge: the walk takes it once.
  const std::size_t      numberOfPoints = m_State.size();
  const std::size_t      numberOfCorners = m_V.size();
  std::vector<IndexType> offsets(numberOfPoints + 1, 0);
  for (std::size_t c = 0; c < numberOfCorners; ++c)
  {
    if (m_V[c] == Invalid)
    {
      return {}; // not a compacted output (cannot happen with a valid table)
    }
    ++offsets[m_V[c] + 1];
    if (m_O[c] < 0)
    {
      ++offsets[m_V[Next(static_cast<IndexType>(c))] + 1];
    }
  }
  for (std::size_t i = 0; i < numberOfPoints; ++i)
  {
    offsets[i + 1] += offsets[i];
  }
  std::vector<IndexType> neighbours(offsets[numberOfPoints]);
  {
    std::vector<IndexType> fill(offsets.begin(), offsets.end() - 1);
    for (std::size_t c = 0; c < numberOfCorners; ++c)
    {
      const IndexType a = m_V[c];
      const IndexType b = m_V[Next(static_cast<IndexType>(c))];
      neighbours[fill[a]++] = b;
      if (m_O[c] < 0)
      {
        neighbours[fill[b]++] = a;
      }
    }
  }
  return BreadthFirstWalk(coordinates, numberOfPoints, offsets, neighbours, false);
}

inline std::vector<DeformableMeshRemesher::IndexType>
DeformableMeshRemesher::BreadthFirstWalk(const double *                 coordinates,
                                         std::size_t                    numberOfPoints,
                                         const std::vector<IndexType> & offsets,
                                         const std::vector<IndexType> & neighbours,
                                         bool                           morton)
{
  std::vector<uint8_t>   visited(numberOfPoints, 0);
  std::vector<IndexType> order;
  order.reserve(numberOfPoints);
  const auto walk = [&](IndexType start) {
    if (visited[start])
    {
      return;
    }
    visited[start] = 1;
    std::size_t head = order.size();
    order.push_back(start);
    while (head < order.size())
    {
      const IndexType v = order[head++];
      for (IndexType k = offsets[v]; k < offsets[v + 1]; ++k)
      {
        const IndexType w = neighbours[k];
        if (!visited[w])
        {
          visited[w] = 1;
          order.push_back(w);
        }
      }
    }
  };
  if (numberOfPoints == 0)
  {
    return order;
  }
  if (!morton)
  {
    // From the point of smallest coordinate along the longest side of the
    // bounding box (an end of an elongated surface: short rings), then the
    // other parts from their points of smallest number.
    double         lower[3];
    double         upper[3];
    IndexType      lowest[3] = { 0, 0, 0 };
    const double * p = coordinates;
    for (unsigned int d = 0; d < 3; ++d)
    {
      lower[d] = upper[d] = p[d];
    }
    for (std::size_t i = 1; i < numberOfPoints; ++i)
    {
      p = coordinates + 3 * i;
      for (unsigned int d = 0; d < 3; ++d)
      {
        if (p[d] < lower[d])
        {
          lower[d] = p[d];
          lowest[d] = static_cast<IndexType>(i);
        }
        upper[d] = std::max(upper[d], p[d]);
      }
    }
    unsigned int axis = 0;
    for (unsigned int d = 1; d < 3; ++d)
    {
      axis = upper[d] - lower[d] > upper[axis] - lower[axis] ? d : axis;
    }
    walk(lowest[axis]);
    for (std::size_t i = 0; i < numberOfPoints; ++i)
    {
      walk(static_cast<IndexType>(i));
    }
    return order;
  }
  // The parts in the order of their first point in LocalityOrder(): the
  // first point of that order (smallest key, then smallest number), then,
  // when points remain (more than one part), the remaining ones sorted.
  // Usually one part: no sort of all the points.
  const std::vector<uint64_t> keys = MortonKeys(coordinates, numberOfPoints);
  walk(static_cast<IndexType>(std::min_element(keys.begin(), keys.end()) - keys.begin()));
  if (order.size() < numberOfPoints)
  {
    std::vector<IndexType> starts;
    starts.reserve(numberOfPoints - order.size());
    for (std::size_t i = 0; i < numberOfPoints; ++i)
    {
      if (!visited[i])
      {
        starts.push_back(static_cast<IndexType>(i));
      }
    }
    std::stable_sort(starts.begin(), starts.end(), [&keys](IndexType a, IndexType b) { return keys[a] < keys[b]; });
    for (const IndexType start : starts)
    {
      walk(start);
    }
  }
  return order;
}

inline double
DeformableMeshRemesher::FarEdgeFraction(const std::vector<IndexType> & triangles, std::size_t window)
{
  if (triangles.empty())
  {
    return 0.0;
  }
  std::size_t far = 0;
  for (std::size_t t = 0; t + 2 < triangles.size(); t += 3)
  {
    for (unsigned int k = 0; k < 3; ++k)
    {
      const IndexType a = triangles[t + k];
      const IndexType b = triangles[t + (k + 1) % 3];
      far += (a > b ? a - b : b - a) > window;
    }
  }
  return static_cast<double>(far) / static_cast<double>(triangles.size());
}

} // end namespace itk

#endif
