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
#ifndef itkDeformableMeshFilter_hxx
#define itkDeformableMeshFilter_hxx

#include "itkDeformableMeshFilter.h"
#include "itkDeformableMeshFilterKernels.h"
#include "itkDeformableMeshUpdateRule.h"
#include "itkMultiThreaderBase.h"

#include <type_traits>

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <utility>

namespace itk
{

template <typename TMesh, typename TForceImage>
DeformableMeshFilter<TMesh, TForceImage>::DeformableMeshFilter()
{
  // The force image is checked in VerifyPreconditions() with a clearer message
  // than the generic one of a required input.
  this->SetNumberOfRequiredInputs(1);
  // The step works on 3-D vectors: a 2-D point is cached as (x, y, 0).
  this->SetCoordinateStride(3);
}

template <typename TMesh, typename TForceImage>
void
DeformableMeshFilter<TMesh, TForceImage>::VerifyPreconditions() const
{
  Superclass::VerifyPreconditions();
  if (this->GetForceImage() == nullptr)
  {
    itkExceptionMacro("No force image: call SetForceImage() before Update().");
  }
  if (!std::isfinite(m_ScaleFactor))
  {
    itkExceptionMacro("ScaleFactor must be finite; it is " << m_ScaleFactor << ".");
  }
  if (!(m_Elasticity >= 0.0 && m_Elasticity <= 1.0))
  {
    itkExceptionMacro("Elasticity must be in [0, 1]; it is " << m_Elasticity << ".");
  }
  if (!(m_Rigidity >= 0.0 && m_Rigidity <= 1.0))
  {
    itkExceptionMacro("Rigidity must be in [0, 1]; it is " << m_Rigidity << ".");
  }
  if (!std::isfinite(m_Balloon))
  {
    itkExceptionMacro("Balloon must be finite; it is " << m_Balloon << ".");
  }
  if (!(m_ReferenceEdgeLength >= 0.0 && std::isfinite(m_ReferenceEdgeLength)))
  {
    itkExceptionMacro("ReferenceEdgeLength must be finite and non-negative (0: the mesh's own edges); it is "
                      << m_ReferenceEdgeLength << ".");
  }
  if (!(m_MaximumStepLength >= 0.0 && std::isfinite(m_MaximumStepLength)))
  {
    itkExceptionMacro("MaximumStepLength must be finite and non-negative; it is " << m_MaximumStepLength << ".");
  }
  if (!(m_ConvergenceTolerance >= 0.0 && std::isfinite(m_ConvergenceTolerance)))
  {
    itkExceptionMacro("ConvergenceTolerance must be finite and non-negative; it is " << m_ConvergenceTolerance << ".");
  }
  if (!(m_RemeshingEdgeLength >= 0.0 && std::isfinite(m_RemeshingEdgeLength)))
  {
    itkExceptionMacro("RemeshingEdgeLength must be finite and positive (or 0 to turn remeshing off); it is "
                      << m_RemeshingEdgeLength << ".");
  }
  if (m_RemeshingInterval == 0)
  {
    itkExceptionMacro("RemeshingInterval must be at least 1 iteration; it is 0.");
  }
  if (m_TangentialDrift != TangentialDriftEnum::Keep && m_TangentialDrift != TangentialDriftEnum::Suppress &&
      m_TangentialDrift != TangentialDriftEnum::SuppressWhenRemeshing)
  {
    itkExceptionMacro("TangentialDrift must be Keep, Suppress or SuppressWhenRemeshing; it is "
                      << static_cast<int>(m_TangentialDrift) << ".");
  }
  if (!(m_MinimumDistance >= 0.0 && std::isfinite(m_MinimumDistance)))
  {
    itkExceptionMacro("MinimumDistance must be finite and non-negative; it is " << m_MinimumDistance << ".");
  }
  if (PointDimension == 2 && m_PreventSelfIntersections)
  {
    itkExceptionMacro("PreventSelfIntersections is on, but the mesh is 2-D (contours): the collision test works on "
                      "the triangles of 3-D surfaces. Turn PreventSelfIntersections off.");
  }
  if (PointDimension == 2 && m_RemeshingEdgeLength > 0.0)
  {
    itkExceptionMacro("RemeshingEdgeLength is " << m_RemeshingEdgeLength
                                                << ", but the mesh is 2-D (contours): remeshing works on the "
                                                   "triangles of 3-D surfaces. Set RemeshingEdgeLength to 0.");
  }
  this->VerifyImageTermParameters();
}

template <typename TMesh, typename TForceImage>
void
DeformableMeshFilter<TMesh, TForceImage>::GenerateData()
{
  this->PrepareForceSampler();
  m_ForceImageCheck.Verify(this->GetForceImage(),
                           m_ScaleFactor,
                           std::abs(m_Balloon) + m_RegionWeight + m_EdgeSearchWeight,
                           m_MaximumStepLength);
  if (this->UsesImageTerms())
  {
    this->PrepareImageTerms();
  }
  Superclass::GenerateData();
}

template <typename TMesh, typename TForceImage>
void
DeformableMeshFilter<TMesh, TForceImage>::PrepareForceSampler()
{
  const ForceImageType * image = this->GetForceImage();
  const auto             region = image->GetBufferedRegion();
  if (region.GetNumberOfPixels() == 0 || image->GetBufferPointer() == nullptr)
  {
    itkExceptionMacro("The force image has no buffered region (no pixel in memory): allocate it or update the "
                      "filter that produces it.");
  }
  if (image == m_SampledForceImage && image->GetBufferPointer() == m_ForceBuffer &&
      image->GetMTime() == m_SampledForceTime && image->GetPixelContainer()->GetMTime() == m_SampledForceBufferTime &&
      region == m_SampledForceRegion)
  {
    return;
  }
  m_SampledForceImage = image;
  m_SampledForceTime = image->GetMTime();
  m_SampledForceBufferTime = image->GetPixelContainer()->GetMTime();
  m_SampledForceRegion = region;
  m_ForceBuffer = image->GetBufferPointer();

  // A 2-D image is sampled as the slice z = 0 of a 3-D one: the points'
  // z is 0, so the third weight is 0 and the trilinear sample is bilinear.
  DeformableMeshFilterDetail::PhysicalToIndexMatrix(image, m_PhysicalToIndex);
  for (unsigned int r = 0; r < 3; ++r)
  {
    m_ForceOrigin[r] = r < PointDimension ? image->GetOrigin()[r] : 0.0;
    m_BufferStart[r] = r < PointDimension ? static_cast<double>(region.GetIndex()[r]) : 0.0;
    m_BufferSize[r] = r < PointDimension ? static_cast<int64_t>(region.GetSize()[r]) : 1;
  }
  // Continuous index c = M (x - origin) - start = M x - (M origin + start).
  DeformableMeshFilterDetail::ForceSampler<ForcePixelType> & sampler = m_Sampler;
  for (unsigned int c = 0; c < 3; ++c)
  {
    for (unsigned int r = 0; r < 3; ++r)
    {
      sampler.columns[c][r] = m_PhysicalToIndex[r][c];
    }
  }
  for (unsigned int r = 0; r < 3; ++r)
  {
    sampler.offset[r] = m_PhysicalToIndex[r][0] * m_ForceOrigin[0] + m_PhysicalToIndex[r][1] * m_ForceOrigin[1] +
                        m_PhysicalToIndex[r][2] * m_ForceOrigin[2] + m_BufferStart[r];
    // Same inside test as itk::LinearInterpolateImageFunction: half a voxel
    // beyond the first and last voxel centres, values clamped at the border.
    sampler.lower[r] = -0.5;
    sampler.upper[r] = static_cast<double>(m_BufferSize[r]) - 0.5;
    sampler.last[r] = m_BufferSize[r] - 1;
  }
  sampler.buffer = m_ForceBuffer;
  sampler.strideY = m_BufferSize[0];
  sampler.strideZ = m_BufferSize[0] * m_BufferSize[1];
  sampler.lastPixel = m_BufferSize[0] * m_BufferSize[1] * m_BufferSize[2] - 1;
  constexpr double pixelBytes = sizeof(ForcePixelType);
  sampler.byteStrides[0] = pixelBytes;
  sampler.byteStrides[1] = pixelBytes * static_cast<double>(sampler.strideY);
  sampler.byteStrides[2] = pixelBytes * static_cast<double>(sampler.strideZ);
  sampler.smallBuffer = (sampler.lastPixel + 1) * static_cast<int64_t>(sizeof(ForcePixelType)) <
                        static_cast<int64_t>(std::numeric_limits<int32_t>::max());
}

template <typename TMesh, typename TForceImage>
void
DeformableMeshFilter<TMesh, TForceImage>::GatherInputCells(std::vector<IndexType32> & triangles,
                                                           std::vector<uint64_t> &    edges,
                                                           bool &                     onlyTriangles) const
{
  const MeshType *    input = this->GetInput();
  const SizeValueType numberOfPoints = this->GetNumberOfCachedPoints();
  if (numberOfPoints >= std::numeric_limits<IndexType32>::max())
  {
    itkExceptionMacro("The input mesh has too many points (" << numberOfPoints << ").");
  }
  onlyTriangles = true;
  auto addEdge = [&](uint64_t a, uint64_t b) {
    if (a != b)
    {
      edges.push_back(std::min(a, b) << 32 | std::max(a, b));
    }
  };

  if (input->GetCells() != nullptr)
  {
    for (auto it = input->GetCells()->Begin(); it != input->GetCells()->End(); ++it)
    {
      const auto * cell = it.Value();
      const auto   type = cell->GetType();
      const auto   n = static_cast<unsigned int>(cell->GetNumberOfPoints());
      const auto * ids = cell->PointIdsBegin();
      const bool   isSurface = type == CommonEnums::CellGeometry::TRIANGLE_CELL ||
                             type == CommonEnums::CellGeometry::QUADRILATERAL_CELL ||
                             type == CommonEnums::CellGeometry::POLYGON_CELL;
      const bool isCurve = type == CommonEnums::CellGeometry::LINE_CELL;
      for (unsigned int k = 0; k < n; ++k)
      {
        if (static_cast<SizeValueType>(ids[k]) >= numberOfPoints)
        {
          itkExceptionMacro("Cell " << it.Index() << " refers to point " << ids[k] << ", but the mesh has only "
                                    << numberOfPoints << " points.");
        }
      }
      onlyTriangles = onlyTriangles && type == CommonEnums::CellGeometry::TRIANGLE_CELL && n == 3;
      if (PointDimension == 2)
      {
        // Contours: line cells (a segment each, or a chain of segments for a
        // line cell of more than 2 points, chained into open or closed
        // contours) and polygon cells (a closed contour each, its points in
        // order); ITK 5.2 has no polyline cell.
        const bool isPolygon = type == CommonEnums::CellGeometry::POLYGON_CELL;
        if (!isCurve && !isPolygon && type != CommonEnums::CellGeometry::VERTEX_CELL)
        {
          itkExceptionMacro(
            "Cell " << it.Index()
                    << " is a surface or volume cell (triangle, quadrilateral...), but the mesh is 2-D: "
                       "a 2-D mesh holds contours, as line cells and polygon cells (closed contours).");
        }
        unsigned int distinct = n;
        for (unsigned int k = 0; k < n && n > 1; ++k)
        {
          distinct -= ids[k] == ids[(k + 1) % n] ? 1 : 0;
        }
        unsigned int lineSegments = 0;
        for (unsigned int k = 0; k + 1 < n; ++k)
        {
          lineSegments += ids[k] != ids[k + 1] ? 1 : 0;
        }
        if (isPolygon ? distinct < 3 : lineSegments == 0)
        {
          itkExceptionMacro("Cell " << it.Index() << " is a " << (isPolygon ? "closed contour" : "contour") << " of "
                                    << (isPolygon ? distinct : 1)
                                    << " distinct point(s): an open contour needs at least 2 points, a closed one "
                                       "(polygon cell) at least 3.");
        }
        const unsigned int segments = isPolygon ? n : n - 1;
        for (unsigned int k = 0; k < segments; ++k)
        {
          const auto a = ids[k];
          const auto b = ids[(k + 1) % n];
          if (a != b)
          {
            triangles.push_back(static_cast<IndexType32>(a));
            triangles.push_back(static_cast<IndexType32>(b));
            addEdge(a, b);
          }
        }
        continue;
      }
      if (isSurface && n >= 3)
      {
        for (unsigned int k = 0; k < n; ++k)
        {
          addEdge(ids[k], ids[(k + 1) % n]);
        }
        // Fan triangulation, for normals.
        for (unsigned int k = 1; k + 1 < n; ++k)
        {
          triangles.push_back(static_cast<IndexType32>(ids[0]));
          triangles.push_back(static_cast<IndexType32>(ids[k]));
          triangles.push_back(static_cast<IndexType32>(ids[k + 1]));
        }
      }
      else if (isCurve || (isSurface && n == 2))
      {
        for (unsigned int k = 0; k + 1 < n; ++k)
        {
          addEdge(ids[k], ids[k + 1]);
        }
      }
    }
  }
}

template <typename TMesh, typename TForceImage>
void
DeformableMeshFilter<TMesh, TForceImage>::BuildTopology(const std::vector<IndexType32> & triangles,
                                                        std::vector<uint64_t> &          edges,
                                                        bool                             edgesUnique,
                                                        bool                             orient)
{
  using namespace DeformableMeshFilterDetail;
  const SizeValueType numberOfPoints = this->GetNumberOfCachedPoints();
  if (!edgesUnique)
  {
    SortEdgeKeys(edges, numberOfPoints);
    edges.erase(std::unique(edges.begin(), edges.end()), edges.end());
  }

  // CSR vertex-neighbour table.
  m_NeighbourOffsets.assign(numberOfPoints + 1, 0);
  for (const uint64_t e : edges)
  {
    ++m_NeighbourOffsets[(e >> 32) + 1];
    ++m_NeighbourOffsets[(e & 0xffffffffULL) + 1];
  }
  for (SizeValueType i = 0; i < numberOfPoints; ++i)
  {
    m_NeighbourOffsets[i + 1] += m_NeighbourOffsets[i];
  }
  m_Neighbours.resize(m_NeighbourOffsets[numberOfPoints]);
  {
    std::vector<IndexType32> fill(m_NeighbourOffsets.begin(), m_NeighbourOffsets.end() - 1);
    for (const uint64_t e : edges)
    {
      const auto a = static_cast<IndexType32>(e >> 32);
      const auto b = static_cast<IndexType32>(e & 0xffffffffULL);
      m_Neighbours[fill[a]++] = b;
      m_Neighbours[fill[b]++] = a;
    }
  }
  std::vector<uint64_t>().swap(edges);

  // For each vertex, the edges opposite it in its triangles, oriented as the
  // triangles: pairs (b, c); its normal sums (b - x) x (c - x) over them.
  // 2-D: the segments b -> c that hold the vertex (its normal sums
  // (c - b) x z); no vertex has a fan, all are GeneralVertex.
  constexpr unsigned int   cellSize = PointDimension == 2 ? 2 : 3;
  const SizeValueType      numberOfTriangles = triangles.size() / cellSize;
  std::vector<IndexType32> pairOffsets(numberOfPoints + 1, 0);
  for (const IndexType32 v : triangles)
  {
    ++pairOffsets[v + 1];
  }
  for (SizeValueType i = 0; i < numberOfPoints; ++i)
  {
    pairOffsets[i + 1] += pairOffsets[i];
  }
  std::vector<IndexType32> pairs(2 * static_cast<SizeValueType>(pairOffsets[numberOfPoints]));
  {
    std::vector<IndexType32> fill(pairOffsets.begin(), pairOffsets.end() - 1);
    for (SizeValueType t = 0; t < numberOfTriangles; ++t)
    {
      for (unsigned int k = 0; k < cellSize; ++k)
      {
        IndexType32 * pair = pairs.data() + 2 * static_cast<SizeValueType>(fill[triangles[cellSize * t + k]]++);
        if (cellSize == 2)
        {
          pair[0] = triangles[2 * t];
          pair[1] = triangles[2 * t + 1];
        }
        else
        {
          pair[0] = triangles[3 * t + (k + 1) % 3];
          pair[1] = triangles[3 * t + (k + 2) % 3];
        }
      }
    }
  }

  // Where the pairs chain into one fan (c of a pair is b of the next) whose
  // vertices are exactly the vertex's neighbours, store the neighbours in fan
  // order: the step then gets the umbrella vector and the normal from the
  // same loads, sum (x_j - x) and sum (x_j - x) x (x_j+1 - x). Otherwise keep
  // the vertex's pairs apart.
  m_RingKinds.assign(numberOfPoints, GeneralVertex);
  m_GeneralVertices.clear();
  m_GeneralPairOffsets.assign(1, 0);
  m_GeneralPairs.clear();
  // Vertices in blocks over threads (each writes its own neighbours' range);
  // the vertices outside a single fan are gathered per block and joined in
  // block order, so the tables do not depend on the number of threads.
  struct GeneralPart
  {
    std::vector<IndexType32> vertices;
    std::vector<IndexType32> pairs;
    std::vector<IndexType32> pairCounts;
  };
  constexpr SizeValueType  topologyBlock = 16384;
  const SizeValueType      numberOfTopologyBlocks = (numberOfPoints + topologyBlock - 1) / topologyBlock;
  std::vector<GeneralPart> parts(numberOfTopologyBlocks);
  const auto               fanBlock = [&](SizeValueType block) {
    GeneralPart &                                    part = parts[block];
    std::vector<IndexType32>                         ring;
    std::vector<IndexType32>                         sortedRing;
    std::vector<IndexType32>                         sortedNeighbours;
    std::vector<std::pair<IndexType32, IndexType32>> fan;  // pairs sorted by b
    std::vector<IndexType32>                         ends; // the c of the pairs, sorted
    const SizeValueType                              blockEnd = std::min(numberOfPoints, (block + 1) * topologyBlock);
    for (SizeValueType i = block * topologyBlock; i < blockEnd; ++i)
    {
      const IndexType32 * vertexPairs = pairs.data() + 2 * static_cast<SizeValueType>(pairOffsets[i]);
      const IndexType32   numberOfPairs = pairOffsets[i + 1] - pairOffsets[i];
      const IndexType32   numberOfNeighbours = m_NeighbourOffsets[i + 1] - m_NeighbourOffsets[i];
      RingKind            kind = GeneralVertex;
      fan.clear();
      ends.clear();
      for (IndexType32 p = 0; p < numberOfPairs; ++p)
      {
        fan.emplace_back(vertexPairs[2 * p], vertexPairs[2 * p + 1]);
        ends.push_back(vertexPairs[2 * p + 1]);
      }
      std::sort(fan.begin(), fan.end());
      std::sort(ends.begin(), ends.end());
      const auto sameFirst = [](const std::pair<IndexType32, IndexType32> & a,
                                const std::pair<IndexType32, IndexType32> & b) { return a.first == b.first; };
      // In one fan every neighbour begins at most one pair and ends at most one.
      const bool oneFanPossible = std::adjacent_find(fan.begin(), fan.end(), sameFirst) == fan.end() &&
                                  std::adjacent_find(ends.begin(), ends.end()) == ends.end();
      if (numberOfNeighbours == 0)
      {
        kind = ClosedRing; // isolated vertex: no umbrella, no normal
      }
      else if (numberOfPairs > 0 && oneFanPossible && PointDimension == 3)
      {
        // Start at a pair whose b ends no other pair (a boundary fan), if any.
        IndexType32 start = 0;
        unsigned    boundaryStarts = 0;
        for (IndexType32 p = 0; p < numberOfPairs; ++p)
        {
          if (!std::binary_search(ends.begin(), ends.end(), fan[p].first))
          {
            start = p;
            ++boundaryStarts;
          }
        }
        // Follow the pairs: c of one is b of the next. With distinct b and c the
        // walk can only come back to where it started.
        ring.assign(1, fan[start].first);
        IndexType32 last = fan[start].second;
        IndexType32 chained = 1;
        while (chained < numberOfPairs && last != ring.front())
        {
          const auto next = std::lower_bound(fan.begin(),
                                             fan.end(),
                                             std::make_pair(last, IndexType32{ 0 }),
                                             [](const auto & a, const auto & b) { return a.first < b.first; });
          if (next == fan.end() || next->first != last)
          {
            break;
          }
          ring.push_back(last);
          last = next->second;
          ++chained;
        }
        RingKind candidate = ClosedRing;
        if (last != ring.front())
        {
          ring.push_back(last);
          candidate = OpenRing;
        }
        if (chained == numberOfPairs && boundaryStarts <= 1 && (candidate == OpenRing) == (boundaryStarts == 1) &&
            ring.size() == numberOfNeighbours)
        {
          sortedRing = ring;
          std::sort(sortedRing.begin(), sortedRing.end());
          sortedNeighbours.assign(m_Neighbours.begin() + m_NeighbourOffsets[i],
                                  m_Neighbours.begin() + m_NeighbourOffsets[i + 1]);
          std::sort(sortedNeighbours.begin(), sortedNeighbours.end());
          if (sortedRing == sortedNeighbours)
          {
            kind = candidate;
            std::copy(ring.begin(), ring.end(), m_Neighbours.begin() + m_NeighbourOffsets[i]);
          }
        }
      }
      m_RingKinds[i] = kind;
      if (kind == GeneralVertex)
      {
        part.vertices.push_back(static_cast<IndexType32>(i));
        part.pairs.insert(part.pairs.end(), vertexPairs, vertexPairs + 2 * numberOfPairs);
        part.pairCounts.push_back(numberOfPairs);
      }
    }
  };
  MultiThreaderBase * topologyThreader = this->GetMultiThreader();
  topologyThreader->SetNumberOfWorkUnits(this->GetNumberOfWorkUnits());
  topologyThreader->ParallelizeArray(0, numberOfTopologyBlocks, fanBlock, nullptr);
  for (const GeneralPart & part : parts)
  {
    m_GeneralVertices.insert(m_GeneralVertices.end(), part.vertices.begin(), part.vertices.end());
    m_GeneralPairs.insert(m_GeneralPairs.end(), part.pairs.begin(), part.pairs.end());
    for (const IndexType32 count : part.pairCounts)
    {
      m_GeneralPairOffsets.push_back(m_GeneralPairOffsets.back() + count);
    }
  }

  this->FinishTopology(triangles, orient);
}

template <typename TMesh, typename TForceImage>
bool
DeformableMeshFilter<TMesh, TForceImage>::BuildTopologyFromRemesher()
{
  using namespace DeformableMeshFilterDetail;
  // Each vertex's fan from the remesher's corner table: a closed ring from
  // its smallest neighbour, an open one from its boundary end, as
  // BuildTopology() orders them. The rings' sizes are the remesher's
  // valences, so that each ring is walked once, straight into its place.
  const SizeValueType      numberOfPoints = this->GetNumberOfCachedPoints();
  constexpr SizeValueType  block = 16384;
  const SizeValueType      numberOfBlocks = (numberOfPoints + block - 1) / block;
  std::vector<IndexType32> offsets(numberOfPoints + 1, 0);
  for (SizeValueType i = 0; i < numberOfPoints; ++i)
  {
    offsets[i + 1] = offsets[i] + static_cast<IndexType32>(m_Remesher.OutputValence(static_cast<IndexType32>(i)));
  }
  std::vector<uint8_t> kinds(numberOfPoints, GeneralVertex);
  std::vector<uint8_t> blockFans(numberOfBlocks, 1);
  // A vertex whose triangles no operation changed (the remesher's
  // OutputPointChanged()) has the ring its input point had, in the new
  // numbers (OutputOfInput(): the input's points keep their order, so that
  // a closed ring still starts at its smallest neighbour), unless a
  // neighbour was collapsed into another point (it then has no number).
  // Read from the input's tables (those of the mesh the remesher was given)
  // in order, that ring costs less than a walk around the fan in the
  // remesher's corner table (the walks cost 13 to 15 ms a remeshing at a
  // million points at rest, these 6 to 7). Not after a renumbering
  // (RenumberRemeshed(): no input point has a number then; the input's
  // tables would be read at random, as slowly as the walks).
  const std::vector<IndexType32> & parents = m_Remesher.Parents();
  std::vector<IndexType32> &       neighbours = m_SpareNeighbours;
  const bool                       inputRings = PointDimension == 3 && m_GeneralVertices.empty() &&
                          m_NeighbourOffsets.size() == m_RingKinds.size() + 1 && parents.size() == numberOfPoints;
  const IndexType32 * inputOffsets = m_NeighbourOffsets.data();
  const IndexType32 * inputNeighbours = m_Neighbours.data();
  const uint8_t *     inputKinds = m_RingKinds.data();
  const SizeValueType inputPoints = m_RingKinds.size();
  neighbours.resize(offsets[numberOfPoints]);
  MultiThreaderBase * threader = this->GetMultiThreader();
  threader->SetNumberOfWorkUnits(this->GetNumberOfWorkUnits());
  threader->ParallelizeArray(
    0,
    numberOfBlocks,
    [&](SizeValueType b) {
      std::vector<IndexType32> ring;
      for (SizeValueType i = b * block; i < std::min(numberOfPoints, (b + 1) * block); ++i)
      {
        const IndexType32 p = parents[i];
        if (inputRings && p < inputPoints && !m_Remesher.OutputPointChanged(static_cast<IndexType32>(i)) &&
            (inputKinds[p] == ClosedRing || inputKinds[p] == OpenRing) &&
            inputOffsets[p + 1] - inputOffsets[p] == offsets[i + 1] - offsets[i])
        {
          IndexType32 * out = neighbours.data() + offsets[i];
          bool          mapped = true;
          for (IndexType32 k = inputOffsets[p]; k < inputOffsets[p + 1] && mapped; ++k)
          {
            const IndexType32 w = m_Remesher.OutputOfInput(inputNeighbours[k]);
            mapped = w != std::numeric_limits<IndexType32>::max();
            *out++ = w;
          }
          if (mapped)
          {
            kinds[i] = inputKinds[p];
            continue;
          }
        }
        const int kind = m_Remesher.OutputRing(static_cast<IndexType32>(i), ring);
        if (kind == 0 || ring.size() < 2 || ring.size() != offsets[i + 1] - offsets[i])
        {
          blockFans[b] = 0;
          return;
        }
        kinds[i] = kind == 1 ? ClosedRing : OpenRing;
        if (kind == 1)
        {
          std::rotate(ring.begin(), std::min_element(ring.begin(), ring.end()), ring.end());
        }
        std::copy(ring.begin(), ring.end(), neighbours.begin() + offsets[i]);
      }
    },
    nullptr);
  if (std::find(blockFans.begin(), blockFans.end(), 0) != blockFans.end())
  {
    return false;
  }
  m_Neighbours.swap(neighbours);
  m_NeighbourOffsets.swap(offsets);
  m_RingKinds.swap(kinds);
  m_GeneralVertices.clear();
  m_GeneralPairOffsets.assign(1, 0);
  m_GeneralPairs.clear();
  this->FinishTopology(m_Triangles, false);
  return true;
}

template <typename TMesh, typename TForceImage>
void
DeformableMeshFilter<TMesh, TForceImage>::FinishTopology(const std::vector<IndexType32> & triangles, bool orient)
{
  using namespace DeformableMeshFilterDetail;
  const SizeValueType numberOfPoints = this->GetNumberOfCachedPoints();
  // 2-D: \a triangles holds the contours' segments, oriented contour by
  // contour (OrientContours()): the sign is +1.
  const SizeValueType numberOfTriangles = PointDimension == 2 ? 0 : triangles.size() / 3;
  if (orient)
  {
    // Outward orientation from the signed volume enclosed by the triangles.
    // Not after a remeshing: the remesher keeps the triangles' orientation,
    // and the sign found at the reset stays (found again, it could change
    // with the shape of an open surface, whose "volume" is that of the cone
    // from the origin; and it is a serial pass over the triangles).
    const double * x = this->GetCoordinates().data();
    double         volume = 0.0;
    for (SizeValueType t = 0; t < numberOfTriangles; ++t)
    {
      const double * a = x + 3 * triangles[3 * t];
      const double * b = x + 3 * triangles[3 * t + 1];
      const double * c = x + 3 * triangles[3 * t + 2];
      volume +=
        a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0]) + a[2] * (b[0] * c[1] - b[1] * c[0]);
    }
    m_OrientationSign = volume < 0.0 ? -1.0 : 1.0;
  }
  m_NumberOfTriangles = numberOfTriangles;

  // The step has straight-line code for 4 to 8 neighbours, chosen by a jump
  // on the number of neighbours. Where that number varies from vertex to
  // vertex (marching-cubes meshes) the jumps are mispredicted; there each
  // chunk of vertices is processed in the order of its numbers of neighbours
  // (a counting sort, done once here), which changes nothing in the results.
  std::vector<uint8_t>().swap(m_ValenceOrder);
  constexpr unsigned int keys = 10; // 0 to 8 neighbours, and more
  const auto             keyOf = [this](SizeValueType i) {
    return std::min<IndexType32>(keys - 1, m_NeighbourOffsets[i + 1] - m_NeighbourOffsets[i]);
  };
  SizeValueType histogram[keys] = {};
  for (SizeValueType i = 0; i < numberOfPoints; ++i)
  {
    ++histogram[keyOf(i)];
  }
  if (4 * *std::max_element(histogram, histogram + keys) < 3 * numberOfPoints)
  {
    m_ValenceOrder.resize(numberOfPoints);
    for (SizeValueType chunkBegin = 0; chunkBegin < numberOfPoints; chunkBegin += DeformableMeshFilterDetail::ChunkSize)
    {
      const SizeValueType chunkEnd = std::min(numberOfPoints, chunkBegin + DeformableMeshFilterDetail::ChunkSize);
      unsigned int        next[keys + 1] = {};
      for (SizeValueType i = chunkBegin; i < chunkEnd; ++i)
      {
        ++next[keyOf(i) + 1];
      }
      for (unsigned int k = 1; k <= keys; ++k)
      {
        next[k] += next[k - 1];
      }
      for (SizeValueType i = chunkBegin; i < chunkEnd; ++i)
      {
        m_ValenceOrder[chunkBegin + next[keyOf(i)]++] = static_cast<uint8_t>(i - chunkBegin);
      }
    }
  }
}

template <typename TMesh, typename TForceImage>
void
DeformableMeshFilter<TMesh, TForceImage>::OrientContours(std::vector<IndexType32> & segments)
{
  const SizeValueType numberOfPoints = this->GetNumberOfCachedPoints();
  const double *      x = this->GetCoordinates().data();
  // One segment per pair of points (the first one given keeps its direction).
  {
    std::vector<std::pair<uint64_t, SizeValueType>> keys;
    keys.reserve(segments.size() / 2);
    for (SizeValueType s = 0; s < segments.size() / 2; ++s)
    {
      const uint64_t a = segments[2 * s];
      const uint64_t b = segments[2 * s + 1];
      keys.emplace_back(std::min(a, b) << 32 | std::max(a, b), s);
    }
    std::sort(keys.begin(), keys.end());
    std::vector<IndexType32> unique;
    unique.reserve(segments.size());
    for (std::size_t k = 0; k < keys.size(); ++k)
    {
      if (k == 0 || keys[k].first != keys[k - 1].first)
      {
        unique.push_back(segments[2 * keys[k].second]);
        unique.push_back(segments[2 * keys[k].second + 1]);
      }
    }
    segments.swap(unique);
  }
  const SizeValueType numberOfSegments = segments.size() / 2;
  // The segments of each point (CSR).
  std::vector<IndexType32> offsets(numberOfPoints + 1, 0);
  for (const IndexType32 v : segments)
  {
    ++offsets[v + 1];
  }
  for (SizeValueType i = 0; i < numberOfPoints; ++i)
  {
    offsets[i + 1] += offsets[i];
  }
  std::vector<IndexType32> incident(offsets[numberOfPoints]);
  {
    std::vector<IndexType32> fill(offsets.begin(), offsets.end() - 1);
    for (SizeValueType s = 0; s < numberOfSegments; ++s)
    {
      incident[fill[segments[2 * s]]++] = static_cast<IndexType32>(s);
      incident[fill[segments[2 * s + 1]]++] = static_cast<IndexType32>(s);
    }
  }
  const auto               degree = [&](SizeValueType i) { return offsets[i + 1] - offsets[i]; };
  std::vector<uint8_t>     visited(numberOfSegments, 0);
  std::vector<IndexType32> walk;
  // Walks from point \a start along segment \a first while the points have
  // two segments; orients the segments along the walk. Returns whether it
  // came back to \a start (a closed contour).
  const auto follow = [&](IndexType32 start, IndexType32 first) {
    walk.clear();
    IndexType32 point = start;
    IndexType32 segment = first;
    while (true)
    {
      visited[segment] = 1;
      walk.push_back(segment);
      IndexType32 * ends = segments.data() + 2 * static_cast<SizeValueType>(segment);
      if (ends[0] != point)
      {
        std::swap(ends[0], ends[1]);
      }
      point = ends[1];
      if (point == start || degree(point) != 2)
      {
        return point == start;
      }
      const IndexType32 * mine = incident.data() + offsets[point];
      segment = mine[0] == segment ? mine[1] : mine[0];
      if (visited[segment])
      {
        return false;
      }
    }
  };
  const auto reverseWalk = [&]() {
    for (const IndexType32 segment : walk)
    {
      std::swap(segments[2 * static_cast<SizeValueType>(segment)],
                segments[2 * static_cast<SizeValueType>(segment) + 1]);
    }
  };
  m_NumberOfOpenContours = 0;
  m_NumberOfClosedContours = 0;
  m_FirstContourEnd = -1;
  // Open contours from their ends, in the direction of the end's segment as
  // given (so that a chain given in one direction keeps it).
  for (SizeValueType i = 0; i < numberOfPoints; ++i)
  {
    if (degree(i) != 1 || visited[incident[offsets[i]]])
    {
      continue;
    }
    const IndexType32 first = incident[offsets[i]];
    const bool        leaving = segments[2 * static_cast<SizeValueType>(first)] == i;
    follow(static_cast<IndexType32>(i), first);
    if (!leaving)
    {
      reverseWalk();
    }
    ++m_NumberOfOpenContours;
    if (m_FirstContourEnd < 0)
    {
      m_FirstContourEnd = static_cast<int64_t>(i);
    }
  }
  // Closed contours: counter-clockwise (positive signed area).
  for (SizeValueType i = 0; i < numberOfPoints; ++i)
  {
    if (degree(i) != 2 || visited[incident[offsets[i]]])
    {
      continue;
    }
    const IndexType32 first = incident[offsets[i]];
    if (!follow(static_cast<IndexType32>(i), first))
    {
      continue; // a chain between branch points: as given
    }
    double area = 0.0;
    for (const IndexType32 segment : walk)
    {
      const double * a = x + 3 * static_cast<SizeValueType>(segments[2 * static_cast<SizeValueType>(segment)]);
      const double * b = x + 3 * static_cast<SizeValueType>(segments[2 * static_cast<SizeValueType>(segment) + 1]);
      area += a[0] * b[1] - a[1] * b[0];
    }
    if (walk.size() < 3)
    {
      itkExceptionMacro("A closed contour through point #" << i << " has " << walk.size()
                                                           << " point(s): a closed contour needs at least 3.");
    }
    if (area < 0.0)
    {
      reverseWalk();
    }
    ++m_NumberOfClosedContours;
  }
}

template <typename TMesh, typename TForceImage>
void
DeformableMeshFilter<TMesh, TForceImage>::FindBoundaryVertices(const std::vector<IndexType32> & triangles)
{
  using namespace DeformableMeshFilterDetail;
  const SizeValueType numberOfPoints = this->GetNumberOfCachedPoints();
  m_BoundaryVertices.clear();
  const auto neighbourCount = [this](SizeValueType i) { return m_NeighbourOffsets[i + 1] - m_NeighbourOffsets[i]; };
  m_ClosedFans = false;
  if (PointDimension == 2)
  {
    // The ends of open contours.
    for (SizeValueType i = 0; i < numberOfPoints; ++i)
    {
      if (neighbourCount(i) == 1)
      {
        m_BoundaryVertices.push_back(static_cast<IndexType32>(i));
      }
    }
    return;
  }
  // A closed manifold surface (every vertex in one closed fan, or isolated)
  // has no boundary: nothing to sort.
  bool anyOpen = false;
  for (SizeValueType i = 0; i < numberOfPoints && !anyOpen; ++i)
  {
    anyOpen = m_RingKinds[i] != ClosedRing;
  }
  if (!anyOpen)
  {
    // Every ring is a closed fan of the triangles (BuildTopology(),
    // BuildTopologyFromRemesher()).
    m_ClosedFans = true;
    return;
  }
  // The edges of one triangle only, and the ends of lines (one neighbour,
  // in no triangle).
  std::vector<uint8_t>  boundary(numberOfPoints, 0);
  std::vector<uint8_t>  inTriangle(numberOfPoints, 0);
  std::vector<uint64_t> edges;
  edges.reserve(triangles.size());
  for (SizeValueType t = 0; t < triangles.size() / 3; ++t)
  {
    for (unsigned int k = 0; k < 3; ++k)
    {
      const uint64_t a = triangles[3 * t + k];
      const uint64_t b = triangles[3 * t + (k + 1) % 3];
      edges.push_back(std::min(a, b) << 32 | std::max(a, b));
      inTriangle[a] = 1;
    }
  }
  DeformableMeshFilterDetail::SortEdgeKeys(edges, numberOfPoints);
  for (std::size_t k = 0; k < edges.size();)
  {
    std::size_t end = k + 1;
    while (end < edges.size() && edges[end] == edges[k])
    {
      ++end;
    }
    if (end - k == 1)
    {
      boundary[edges[k] >> 32] = 1;
      boundary[edges[k] & 0xffffffffULL] = 1;
    }
    k = end;
  }
  for (SizeValueType i = 0; i < numberOfPoints; ++i)
  {
    if (boundary[i] || (!inTriangle[i] && neighbourCount(i) == 1))
    {
      m_BoundaryVertices.push_back(static_cast<IndexType32>(i));
    }
  }
}

template <typename TMesh, typename TForceImage>
void
DeformableMeshFilter<TMesh, TForceImage>::HoldBoundary(const double *        start,
                                                       std::vector<double> * blockMaximum,
                                                       bool                  diagnose)
{
  using DeformableMeshFilterDetail::BlockSize;
  double * next = m_NextCoordinates.data();
  for (const IndexType32 i : m_BoundaryVertices)
  {
    std::copy(start + 3 * static_cast<SizeValueType>(i),
              start + 3 * static_cast<SizeValueType>(i) + 3,
              next + 3 * static_cast<SizeValueType>(i));
    if (diagnose)
    {
      m_DisplacementMagnitudes[i] = 0.0f;
    }
  }
  if (blockMaximum == nullptr)
  {
    return;
  }
  // The largest displacement of the blocks that hold a boundary vertex.
  const SizeValueType numberOfPoints = this->GetNumberOfCachedPoints();
  SizeValueType       lastBlock = std::numeric_limits<SizeValueType>::max();
  for (const IndexType32 i : m_BoundaryVertices)
  {
    const SizeValueType block = i / BlockSize;
    if (block == lastBlock)
    {
      continue;
    }
    lastBlock = block;
    double largest = 0.0;
    for (SizeValueType j = block * BlockSize; j < std::min(numberOfPoints, (block + 1) * BlockSize); ++j)
    {
      const double dx = next[3 * j] - start[3 * j];
      const double dy = next[3 * j + 1] - start[3 * j + 1];
      const double dz = next[3 * j + 2] - start[3 * j + 2];
      largest = std::max(largest, dx * dx + dy * dy + dz * dz);
    }
    (*blockMaximum)[block] = std::sqrt(largest);
  }
}

template <typename TMesh, typename TForceImage>
void
DeformableMeshFilter<TMesh, TForceImage>::Reset()
{
  std::vector<IndexType32> triangles;
  std::vector<uint64_t>    edges;
  bool                     onlyTriangles = true;
  this->GatherInputCells(triangles, edges, onlyTriangles);
  if (m_RemeshingEdgeLength > 0.0 && !onlyTriangles)
  {
    itkExceptionMacro("RemeshingEdgeLength is " << m_RemeshingEdgeLength
                                                << ", but the input mesh has cells other than triangles (lines, "
                                                   "polygons, vertices): remeshing works on triangle meshes only. "
                                                   "Triangulate the mesh or set RemeshingEdgeLength to 0.");
  }
  if (PointDimension == 2)
  {
    this->OrientContours(triangles);
  }
  else
  {
    m_NumberOfOpenContours = 0;
    m_NumberOfClosedContours = 0;
    m_FirstContourEnd = -1;
  }
  this->RenumberForLocality(triangles, edges);
  this->BuildTopology(triangles, edges);
  this->FindBoundaryVertices(triangles);
  // The collision test takes the triangles in the cache's numbering when
  // the points were renumbered (the input's cells otherwise, which also
  // name the cells of an intersecting pair).
  std::vector<IndexType32> renumberedTriangles;
  if (m_Renumbered && PointDimension == 3)
  {
    renumberedTriangles = triangles;
  }
  m_CollisionTrianglesAreMeshTriangles = false;
  if (m_RemeshingEdgeLength > 0.0 && PointDimension == 3)
  {
    m_Triangles.swap(triangles);
  }
  else
  {
    std::vector<IndexType32>().swap(m_Triangles);
  }
  m_NumberOfRemeshings = 0;
  m_OperationsSinceRenumbering = 0;
  m_NumberOfLocalityRenumberings = 0;
  m_RemeshingStatistics = RemeshingStatisticsType{};
  m_NumberOfPointsLockedByRemeshing = 0;
  m_Remesher.ForgetTable();
  std::vector<double>().swap(m_RemeshInputCoordinates);
  std::vector<IndexType32>().swap(m_RemeshInputTriangles);
  std::vector<IndexType32>().swap(m_SpareNeighbours);
  const SizeValueType numberOfPoints = this->GetNumberOfCachedPoints();
  // The kernels load 4 doubles from a point's 3 coordinates: both arrays
  // of coordinates, swapped at each step, end with a guard value.
  this->GetCoordinates().resize(3 * numberOfPoints + 1, 0.0);
  m_NextCoordinates.assign(3 * numberOfPoints + 1, 0.0);
  std::vector<float>().swap(m_Umbrella);
  std::vector<float>().swap(m_Normals);
  m_BalloonReleased.clear();
  m_DisplacementMagnitudes.clear();
  m_ExternalForceMagnitudes.clear();
  m_InternalForceMagnitudes.clear();
  m_Converged = false;
  m_QuietIterations = 0;
  m_LastMaximumDisplacement = 0.0;
  m_OscillationState.clear();
  m_NumberOfDampedVertices = 0;
  m_ContactFactors.clear();
  m_HeldPoints.clear();
  m_NormalSpeeds.clear();
  m_EdgeHits.clear();
  m_NumberOfEdgeHits = 0;
  if (this->UsesImageTerms())
  {
    this->EstimateImageTermModel();
  }
  this->ResetCollision(m_Renumbered ? &renumberedTriangles : nullptr, true);
}

template <typename TMesh, typename TForceImage>
void
DeformableMeshFilter<TMesh, TForceImage>::ResetCollision(const std::vector<uint32_t> * triangles, bool check)
{
  m_NumberOfCollisionsPrevented = 0;
  m_NumberOfConstrainedVertices = 0;
  if (check)
  {
    m_TotalNumberOfCollisionsPrevented = 0;
  }
  if (triangles == &m_Triangles)
  {
    // The remeshed triangles: kept in m_Triangles, not copied.
    std::vector<uint32_t>().swap(m_CollisionTriangles);
    m_CollisionTrianglesAreMeshTriangles = true;
  }
  else if (triangles == nullptr)
  {
    m_CollisionTriangles.clear();
    m_CollisionTrianglesAreMeshTriangles = false;
  }
  else if (triangles != &m_CollisionTriangles)
  {
    m_CollisionTriangles = *triangles;
    m_CollisionTrianglesAreMeshTriangles = false;
  }
  if (!m_PreventSelfIntersections)
  {
    m_Collision.Clear();
    return;
  }
  std::vector<uint32_t>      extracted;
  std::vector<SizeValueType> cells;
  if (triangles == nullptr)
  {
    SurfaceCollision::ExtractTriangles(this->GetInput(), extracted, &cells);
    triangles = &extracted;
  }
  const SizeValueType numberOfTriangles = triangles->size() / 3;
  m_Collision.SetSurface(this->GetNumberOfCachedPoints(),
                         triangles->data(),
                         numberOfTriangles,
                         this->GetMultiThreader(),
                         this->GetNumberOfWorkUnits());
  if (!check ||
      m_Collision.IsStarShaped(this->GetCoordinates().data(), this->GetMultiThreader(), this->GetNumberOfWorkUnits()))
  {
    return; // a star-shaped closed surface has no intersecting pair
  }
  std::pair<SizeValueType, SizeValueType> first;
  const SizeValueType count = SurfaceCollision::CountSelfIntersections(this->GetCoordinates().data(),
                                                                       triangles->data(),
                                                                       numberOfTriangles,
                                                                       &first,
                                                                       this->GetMultiThreader(),
                                                                       this->GetNumberOfWorkUnits());
  if (count > 0)
  {
    m_Collision.Clear();
    std::ostringstream cellText;
    if (!cells.empty())
    {
      cellText << " (cells " << cells[first.first] << " and " << cells[first.second] << ")";
    }
    itkExceptionMacro("PreventSelfIntersections is on and the mesh intersects itself: "
                      << count << " pair(s) of triangles sharing no vertex intersect, the first triangles "
                      << first.first << " and " << first.second << cellText.str()
                      << ". Repair the input mesh or turn PreventSelfIntersections off.");
  }
}

template <typename TMesh, typename TForceImage>
void
DeformableMeshFilter<TMesh, TForceImage>::ConstrainSelfIntersections(std::vector<double> & blockMaximum,
                                                                     bool                  diagnose,
                                                                     double &              largestNormal)
{
  using DeformableMeshFilterDetail::BlockSize;
  if (!m_Collision.HasSurface())
  {
    // Turned on after the last reset: set up (and check) now.
    this->ResetCollision(m_CollisionTrianglesAreMeshTriangles
                           ? &m_Triangles
                           : (m_CollisionTriangles.empty() ? nullptr : &m_CollisionTriangles),
                         true);
  }
  if (m_Collision.GetNumberOfPoints() != this->GetNumberOfCachedPoints())
  {
    itkExceptionMacro("PreventSelfIntersections: the collision tables describe "
                      << m_Collision.GetNumberOfPoints() << " points but the mesh has "
                      << this->GetNumberOfCachedPoints()
                      << " (a change of the mesh without ResetCollision(): an internal error).");
  }
  // The state the iteration started from, free of intersections: the
  // coordinates, or with internal sub-steps (ReferenceEdgeLength) the copy
  // taken before them. Reduced displacements are measured from it.
  const std::vector<double> & start = m_NumberOfSubSteps > 1 ? m_IterationStart : this->GetCoordinates();
  // A closed surface's fans, built from the collision test's own
  // triangles (the remeshed m_Triangles): a carried certificate visits the
  // triangles of the points that moved beyond its margin through them. Lent
  // for this call only (also when it throws).
  struct LentFans
  {
    SurfaceCollision & collision;
    ~LentFans() { collision.SetPointFans(nullptr, nullptr); }
  } lent{ m_Collision };
  if (m_ClosedFans && m_CollisionTrianglesAreMeshTriangles)
  {
    m_Collision.SetPointFans(m_NeighbourOffsets.data(), m_Neighbours.data());
  }
  const SizeValueType numberOfPoints = this->GetNumberOfCachedPoints();
  // Contact memory: a vertex that a contact held back moves by a fraction of
  // its proposal at the next iterations (its factor, doubled at each
  // iteration it is not held again, from 1/8 when it was zeroed, until 1).
  // A front resting against another then proposes little into it, and the
  // test's halving rounds do not spread over the whole contact again at
  // every iteration. The test below still decides; the held vertices'
  // proposals are kept for the convergence counts.
  if (!m_RememberContacts)
  {
    m_ContactFactors.clear();
    m_HeldPoints.clear();
  }
  else if (m_ContactFactors.size() != numberOfPoints)
  {
    m_ContactFactors.assign(numberOfPoints, 1.0f);
    m_HeldPoints.clear();
  }
  m_HeldProposals.resize(3 * m_HeldPoints.size());
  for (SizeValueType k = 0; k < m_HeldPoints.size(); ++k)
  {
    const SizeValueType i = m_HeldPoints[k];
    const double        f = m_ContactFactors[i];
    for (unsigned int c = 0; c < 3; ++c)
    {
      double & q = m_NextCoordinates[3 * i + c];
      m_HeldProposals[3 * k + c] = q;
      q = start[3 * i + c] + f * (q - start[3 * i + c]);
    }
  }
  // blockMaximum: the step's largest displacement per block (the held
  // proposals, scaled down, are within it).
  const auto result =
    m_Collision.Constrain(start.data(),
                          m_NextCoordinates.data(),
                          m_MinimumDistance,
                          this->GetMultiThreader(),
                          this->GetNumberOfWorkUnits(),
                          blockMaximum.empty() ? -1.0 : *std::max_element(blockMaximum.begin(), blockMaximum.end()));
  m_NumberOfCollisionsPrevented = result.violations;
  m_TotalNumberOfCollisionsPrevented += result.violations;
  m_NumberOfConstrainedVertices = result.constrained;
  if (result.constrained == 0 && m_HeldPoints.empty())
  {
    return;
  }
  const auto squaredLength = [&](SizeValueType i, const double * p) {
    const double dx = p[0] - start[3 * i];
    const double dy = p[1] - start[3 * i + 1];
    const double dz = p[2] - start[3 * i + 2];
    return dx * dx + dy * dy + dz * dz;
  };
  const auto length = [&](SizeValueType i) { return std::sqrt(squaredLength(i, m_NextCoordinates.data() + 3 * i)); };
  // The proposal of the step (before the contact memory and the test) of a
  // vertex the test held back.
  const auto &             constrainedPoints = m_Collision.GetConstrainedPoints();
  const auto &             constrainedProposals = m_Collision.GetConstrainedProposals();
  std::vector<IndexType32> previous;
  previous.swap(m_HeldPoints);
  // The factors of the next iteration: the vertices held now keep the part
  // of their proposal the test let them move; the others recover.
  std::vector<IndexType32> constrainedSorted(constrainedPoints.begin(), constrainedPoints.end());
  std::sort(constrainedSorted.begin(), constrainedSorted.end());
  const auto constrainedNow = [&constrainedSorted](IndexType32 i) {
    return std::binary_search(constrainedSorted.begin(), constrainedSorted.end(), i);
  };
  SizeValueType reduced = constrainedSorted.size();
  for (const IndexType32 i : previous)
  {
    reduced += !constrainedNow(i);
  }
  m_NumberOfConstrainedVertices = reduced;
  if (m_RememberContacts)
  {
    std::vector<IndexType32> nowHeld;
    nowHeld.reserve(constrainedPoints.size() + previous.size());
    for (SizeValueType k = 0; k < constrainedPoints.size(); ++k)
    {
      const SizeValueType i = constrainedPoints[k];
      const double        proposed = squaredLength(i, constrainedProposals.data() + 3 * k);
      const double        kept = squaredLength(i, m_NextCoordinates.data() + 3 * i);
      const double        ratio = proposed > 0.0 ? std::sqrt(kept / proposed) : 1.0;
      m_ContactFactors[i] = static_cast<float>(m_ContactFactors[i] * std::min(1.0, ratio));
      if (m_ContactFactors[i] < 1.0f)
      {
        nowHeld.push_back(static_cast<IndexType32>(i));
      }
    }
    for (const IndexType32 i : previous)
    {
      if (constrainedNow(i))
      {
        continue;
      }
      float & f = m_ContactFactors[i];
      f = f < 0.125f ? 0.125f : 2.0f * f;
      if (f >= 1.0f)
      {
        f = 1.0f;
      }
      else
      {
        nowHeld.push_back(i);
      }
    }
    std::sort(nowHeld.begin(), nowHeld.end());
    m_HeldPoints.swap(nowHeld);
  }
  // The displacements of the held and constrained vertices changed: their
  // diagnostics, and the largest displacement (a pass over the vertices, in
  // the iterations that hold some only).
  if (diagnose)
  {
    for (const auto i : constrainedPoints)
    {
      m_DisplacementMagnitudes[i] = static_cast<float>(length(i));
    }
    for (const auto i : previous)
    {
      m_DisplacementMagnitudes[i] = static_cast<float>(length(i));
    }
  }
  for (SizeValueType block = 0; block < blockMaximum.size(); ++block)
  {
    double largest = 0.0;
    for (SizeValueType i = block * BlockSize; i < std::min(numberOfPoints, (block + 1) * BlockSize); ++i)
    {
      largest = std::max(largest, length(i));
    }
    blockMaximum[block] = largest;
  }
  // FinishStep() counted the active vertices and the largest displacement
  // along the normals on the proposed positions: a vertex held against a
  // contact moves less (or not at all), and the convergence test must see
  // that, or a surface resting against itself never converges.
  if (!(m_DampOscillations || m_ConvergenceFraction > 0.0 || m_ConvergenceAlongNormals))
  {
    return;
  }
  const float * normals = m_ConvergenceAlongNormals ? m_Normals.data() : nullptr;
  const auto    measured = [&](SizeValueType i, const double * p) {
    const double d[3] = { p[0] - start[3 * i], p[1] - start[3 * i + 1], p[2] - start[3 * i + 2] };
    if (normals == nullptr)
    {
      return d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
    }
    const double along = d[0] * normals[4 * i] + d[1] * normals[4 * i + 1] + d[2] * normals[4 * i + 2];
    return along * along;
  };
  const double squaredTolerance = m_ConvergenceTolerance * m_ConvergenceTolerance;
  // Each vertex whose displacement changed once: from its proposal (before
  // the contact memory) to where it goes.
  const auto recount = [&](SizeValueType i, const double * proposal) {
    const bool was = measured(i, proposal) >= squaredTolerance;
    const bool is = measured(i, m_NextCoordinates.data() + 3 * i) >= squaredTolerance;
    if (was && !is && m_NumberOfActiveVertices > 0)
    {
      --m_NumberOfActiveVertices;
    }
  };
  for (SizeValueType k = 0; k < previous.size(); ++k)
  {
    recount(previous[k], m_HeldProposals.data() + 3 * k);
  }
  for (SizeValueType k = 0; k < constrainedPoints.size(); ++k)
  {
    const SizeValueType i = constrainedPoints[k];
    if (!std::binary_search(previous.begin(), previous.end(), static_cast<IndexType32>(i)))
    {
      recount(i, constrainedProposals.data() + 3 * k);
    }
  }
  if (normals != nullptr)
  {
    double largest = 0.0;
    for (SizeValueType i = 0; i < numberOfPoints; ++i)
    {
      largest = std::max(largest, measured(i, m_NextCoordinates.data() + 3 * i));
    }
    largestNormal = std::sqrt(largest);
  }
}

template <typename TMesh, typename TForceImage>
void
DeformableMeshFilter<TMesh, TForceImage>::FinishStep(const double *        start,
                                                     std::vector<double> & blockMaximum,
                                                     bool                  diagnose,
                                                     double &              largestNormal)
{
  using namespace DeformableMeshFilterDetail;
  const SizeValueType numberOfPoints = this->GetNumberOfCachedPoints();
  if (m_DampOscillations && m_OscillationState.size() != numberOfPoints)
  {
    m_OscillationState.assign(numberOfPoints, { { 0.0f, 0.0f, 0.0f, 1.0f } });
  }
  const SizeValueType        numberOfBlocks = blockMaximum.size();
  std::vector<SizeValueType> blockDamped(numberOfBlocks, 0);
  std::vector<SizeValueType> blockActive(numberOfBlocks, 0);
  std::vector<double>        blockNormal(numberOfBlocks, 0.0);
  const bool                 damp = m_DampOscillations;
  const double               squaredTolerance = m_ConvergenceTolerance * m_ConvergenceTolerance;
  double *                   next = m_NextCoordinates.data();
  // Along the normals: the squared component of d along the vertex's unit
  // normal (stored by the geometry pass at the start of the iteration).
  const float * normals = m_ConvergenceAlongNormals ? m_Normals.data() : nullptr;
  const auto    measured = [normals](SizeValueType i, const double * d, double squared) {
    if (normals == nullptr)
    {
      return squared;
    }
    const double along = d[0] * normals[4 * i] + d[1] * normals[4 * i + 1] + d[2] * normals[4 * i + 2];
    return along * along;
  };
  MultiThreaderBase * threader = this->GetMultiThreader();
  threader->ParallelizeArray(
    0,
    numberOfBlocks,
    [&](SizeValueType block) {
      const SizeValueType begin = block * BlockSize;
      const SizeValueType end = std::min(numberOfPoints, begin + BlockSize);
      double              largest = 0.0;
      double              largestAlong = 0.0;
      SizeValueType       damped = 0;
      SizeValueType       active = 0;
      for (SizeValueType i = begin; i < end; ++i)
      {
        if (!damp)
        {
          const double d[3] = { next[3 * i] - start[3 * i],
                                next[3 * i + 1] - start[3 * i + 1],
                                next[3 * i + 2] - start[3 * i + 2] };
          const double m = measured(i, d, d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
          largestAlong = std::max(largestAlong, m);
          active += m >= squaredTolerance;
          continue;
        }
        std::array<float, 4> & state = m_OscillationState[i];
        double                 d[3] = { next[3 * i] - start[3 * i],
                                        next[3 * i + 1] - start[3 * i + 1],
                                        next[3 * i + 2] - start[3 * i + 2] };
        const double           dd = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
        const double pp = double{ state[0] } * state[0] + double{ state[1] } * state[1] + double{ state[2] } * state[2];
        const double dp = d[0] * state[0] + d[1] * state[1] + d[2] * state[2];
        // Reversal: the angle between the two displacements above 120 degrees.
        if (dp < 0.0 && 4.0 * dp * dp > dd * pp)
        {
          state[3] = std::max(state[3] * 0.5f, 1.0f / 1024.0f);
          ++damped;
        }
        else
        {
          state[3] = std::min(state[3] * 1.25f, 1.0f);
        }
        const double factor = state[3];
        if (factor < 1.0)
        {
          for (unsigned int k = 0; k < 3; ++k)
          {
            d[k] *= factor;
            next[3 * i + k] = start[3 * i + k] + d[k];
          }
        }
        if (dd > 0.0)
        {
          // The previous displacement keeps its direction while the vertex
          // stands still.
          state[0] = static_cast<float>(d[0]);
          state[1] = static_cast<float>(d[1]);
          state[2] = static_cast<float>(d[2]);
        }
        const double squared = factor * factor * dd;
        largest = std::max(largest, squared);
        const double m = measured(i, d, squared);
        largestAlong = std::max(largestAlong, m);
        active += m >= squaredTolerance;
        if (diagnose)
        {
          m_DisplacementMagnitudes[i] = static_cast<float>(std::sqrt(squared));
        }
      }
      if (damp)
      {
        blockMaximum[block] = std::sqrt(largest);
      }
      blockDamped[block] = damped;
      blockActive[block] = active;
      blockNormal[block] = largestAlong;
    },
    nullptr);
  largestNormal = 0.0;
  for (SizeValueType block = 0; block < numberOfBlocks; ++block)
  {
    m_NumberOfDampedVertices += blockDamped[block];
    m_NumberOfActiveVertices += blockActive[block];
    largestNormal = std::max(largestNormal, blockNormal[block]);
  }
  largestNormal = std::sqrt(largestNormal);
}

template <typename TMesh, typename TForceImage>
void
DeformableMeshFilter<TMesh, TForceImage>::Iterate()
{
  using namespace DeformableMeshFilterDetail;
  std::vector<double> & coordinates = this->GetCoordinates();
  const SizeValueType   numberOfPoints = this->GetNumberOfCachedPoints();

  const bool useElasticity = m_Elasticity > 0.0;
  // Image terms (region force, edge search) need the current unit normals
  // before the step: the geometry pass stores them, as for rigidity. With a
  // reference edge length the geometry pass also gives the edge weights.
  const bool useImageTerms = this->UsesImageTerms();
  const bool scaled = m_ReferenceEdgeLength > 0.0 && (useElasticity || m_Rigidity > 0.0);
  // Suppressing the tangential drift needs the normals and the mesh's edge length:
  // the geometry pass gives both.
  const bool suppressDrift = this->GetSuppressTangentialDrift() && m_ScaleFactor != 0.0;
  const bool useRigidity = m_Rigidity > 0.0 || useImageTerms || scaled || m_ConvergenceAlongNormals || suppressDrift;
  const bool useNormal = m_Balloon != 0.0 || (useElasticity && m_TangentialElasticity) || useImageTerms ||
                         m_ConvergenceAlongNormals || suppressDrift;
  if (m_FirstContourEnd >= 0 && (m_Balloon != 0.0 || m_RegionWeight > 0.0))
  {
    // Outward is the side away from the region a closed contour encloses;
    // an open contour encloses none.
    const std::string parameter = m_Balloon != 0.0 ? "Balloon" : "RegionWeight";
    const double      value = m_Balloon != 0.0 ? m_Balloon : m_RegionWeight;
    itkExceptionMacro(<< parameter << " is " << value << ", but the mesh has " << m_NumberOfOpenContours
                      << " open contour(s) (point #" << m_FirstContourEnd
                      << " is an end): outward is undefined for an open contour. Close the contour(s) or set "
                      << parameter << " to 0.");
  }

  if (m_DisplacementMagnitudes.size() != numberOfPoints)
  {
    m_DisplacementMagnitudes.assign(numberOfPoints, 0.0f);
    m_ExternalForceMagnitudes.assign(numberOfPoints, 0.0f);
    m_InternalForceMagnitudes.assign(numberOfPoints, 0.0f);
  }
  if (m_BalloonReleased.size() != numberOfPoints)
  {
    m_BalloonReleased.assign(numberOfPoints, 0);
  }
  // The diagnostics describe the last iteration of an update: they are
  // computed when this iteration may be the last (the last one scheduled, or
  // one that can complete convergence) and at every iteration when an
  // observer may look at them or stop the update (IterationEvent,
  // ProgressEvent). Elsewhere they would cost about a tenth of the step.
  const bool diagnose = this->GetCurrentIteration() + 1 >= this->GetNumberOfIterations() ||
                        (m_ConvergenceTolerance > 0.0 && m_QuietIterations + 1 >= m_ConvergenceWindow) ||
                        this->HasObserver(IterationEvent()) || this->HasObserver(ProgressEvent());

  const bool          ordered = !m_ValenceOrder.empty();
  const SizeValueType numberOfBlocks = (numberOfPoints + BlockSize - 1) / BlockSize;
  MultiThreaderBase * threader = this->GetMultiThreader();
  threader->SetNumberOfWorkUnits(this->GetNumberOfWorkUnits());
  const KernelPath path = GetKernelPath();

  // With rigidity, a first pass stores the umbrella vectors (and normals) of
  // all vertices: the rigidity force is the umbrella of the umbrella field.
  // They are stored in single precision (16 bytes a vector): the pass is
  // limited by memory traffic, and they enter the step as forces, not as
  // positions (relative error 6e-8 of the step).
  if (useRigidity)
  {
    if (m_Umbrella.size() != 4 * numberOfPoints)
    {
      m_Umbrella.assign(4 * numberOfPoints, 0.0f);
    }
    if (useNormal && m_Normals.size() != 4 * numberOfPoints)
    {
      m_Normals.assign(4 * numberOfPoints, 0.0f);
    }
  }
  const MeshTables    mesh{ m_NeighbourOffsets.data(), m_Neighbours.data(),
                         m_RingKinds.data(),        m_GeneralVertices.data(),
                         m_GeneralVertices.size(),  m_GeneralPairOffsets.data(),
                         m_GeneralPairs.data(),     ordered ? m_ValenceOrder.data() : nullptr,
                         PointDimension == 2 };
  StepArrays          arrays{ coordinates.data(),
                     m_NextCoordinates.data(),
                     m_Umbrella.data(),
                     m_Normals.data(),
                     m_BalloonReleased.data(),
                     nullptr,
                     m_DisplacementMagnitudes.data(),
                     m_ExternalForceMagnitudes.data(),
                     m_InternalForceMagnitudes.data() };
  std::vector<double> blockMaximum(numberOfBlocks, 0.0);
  // The geometry pass; returns the mean squared edge length of the vertices
  // that have neighbours when scaled, else 0.
  // The vertices with neighbours are counted in the blocks' pass too (a
  // serial pass over the offsets cost about half a millisecond an iteration
  // at a million points).
  std::vector<SizeValueType> blockConnected;
  const auto                 geometryPass = [&](bool needLengths) {
    const double orientationSign = m_OrientationSign;
    if (needLengths)
    {
      blockConnected.assign(numberOfBlocks, 0);
    }
    threader->ParallelizeArray(
      0,
      numberOfBlocks,
      [&](SizeValueType block) {
        const SizeValueType begin = block * BlockSize;
        const SizeValueType end = std::min(numberOfPoints, begin + BlockSize);
        blockMaximum[block] =
          RunGeometryBlock(path, useNormal, ordered, needLengths, mesh, arrays, orientationSign, begin, end);
        if (needLengths)
        {
          SizeValueType connected = 0;
          for (SizeValueType i = begin; i < end; ++i)
          {
            connected += m_NeighbourOffsets[i + 1] > m_NeighbourOffsets[i];
          }
          blockConnected[block] = connected;
        }
      },
      nullptr);
    if (!needLengths)
    {
      return 0.0;
    }
    double        sum = 0.0;
    SizeValueType connected = 0;
    for (SizeValueType block = 0; block < numberOfBlocks; ++block)
    {
      sum += blockMaximum[block];
      connected += blockConnected[block];
    }
    return connected > 0 ? sum / static_cast<double>(connected) : 0.0;
  };
  const auto stepPass = [&](const StepTerms & terms, bool diagnoseStep) {
    threader->ParallelizeArray(
      0,
      numberOfBlocks,
      [&](SizeValueType block) {
        const SizeValueType begin = block * BlockSize;
        blockMaximum[block] = RunStepBlock(path,
                                           useRigidity,
                                           useNormal,
                                           ordered,
                                           m_Sampler,
                                           mesh,
                                           terms,
                                           arrays,
                                           begin,
                                           std::min(numberOfPoints, begin + BlockSize),
                                           diagnoseStep);
      },
      nullptr);
  };

  // Stability of the explicit internal update: without a reference edge
  // length a + 2b <= 1, larger sums scaled; with one, the weights a w and
  // b w^2 (w the edge weight of the mesh at the start of the iteration) in as
  // many sub-steps of the internal forces as a w + 2 b w^2 <= 1 needs
  // (DeformableMeshUpdateRule::FromParameters()).
  double edgeWeight = 0.0;
  double driftThreshold = 0.0;
  if (useRigidity)
  {
    const double meanSquaredEdgeLength = geometryPass(scaled || suppressDrift);
    edgeWeight = DeformableMeshUpdateRule::EdgeWeight(scaled ? m_ReferenceEdgeLength : 0.0, meanSquaredEdgeLength);
    if (suppressDrift)
    {
      driftThreshold = 0.125 * std::sqrt(meanSquaredEdgeLength);
    }
  }
  const DeformableMeshUpdateRule rule = DeformableMeshUpdateRule::FromParameters(
    m_ScaleFactor, m_Elasticity, m_Rigidity, m_TangentialElasticity, m_Balloon, m_MaximumStepLength, edgeWeight);
  m_EdgeWeight = scaled ? edgeWeight : 1.0;
  if (rule.subSteps > m_MaximumNumberOfSubSteps)
  {
    itkExceptionMacro("ReferenceEdgeLength " << m_ReferenceEdgeLength << " mm with Elasticity " << m_Elasticity
                                             << " and Rigidity " << m_Rigidity << " needs " << rule.subSteps
                                             << " sub-steps per iteration on this mesh (root mean square edge length "
                                             << m_ReferenceEdgeLength / std::sqrt(edgeWeight)
                                             << " mm), more than MaximumNumberOfSubSteps (" << m_MaximumNumberOfSubSteps
                                             << "): lower ReferenceEdgeLength, Elasticity or Rigidity, or use a "
                                                "coarser mesh.");
  }
  m_NumberOfSubSteps = static_cast<unsigned int>(rule.subSteps);
  if (m_NumberOfSubSteps > 1)
  {
    // The internal forces alone for all sub-steps but the last; the
    // displacement of the iteration is measured from where it started.
    m_IterationStart.assign(coordinates.begin(), coordinates.end());
    const DeformableMeshUpdateRule internal = rule.InternalOnly();
    const StepTerms                internalTerms{ internal.scaleFactor, internal.elasticity,
                                   internal.rigidity,    internal.tangential,
                                   internal.balloon,     internal.maximumStepLength,
                                   m_OrientationSign,    0.0 };
    for (unsigned int k = 1; k < m_NumberOfSubSteps; ++k)
    {
      stepPass(internalTerms, false);
      if (m_FixedBoundary)
      {
        this->HoldBoundary(coordinates.data(), nullptr, false);
      }
      coordinates.swap(m_NextCoordinates);
      arrays.coordinates = coordinates.data();
      arrays.next = m_NextCoordinates.data();
      geometryPass(false);
    }
  }
  else
  {
    std::vector<double>().swap(m_IterationStart);
  }
  if (useImageTerms)
  {
    this->UpdateNormalSpeeds();
    arrays.normalSpeeds = m_NormalSpeeds.data();
  }
  else
  {
    m_NormalSpeeds.clear();
  }

  const StepTerms terms{ rule.scaleFactor, rule.elasticity,        rule.rigidity,     rule.tangential,
                         rule.balloon,     rule.maximumStepLength, m_OrientationSign, driftThreshold };
  stepPass(terms, diagnose);
  if (m_FixedBoundary && !m_BoundaryVertices.empty())
  {
    this->HoldBoundary(coordinates.data(), &blockMaximum, diagnose);
  }
  if (m_NumberOfSubSteps > 1)
  {
    // The displacement of the whole iteration; the internal force of the
    // last sub-step as a force per iteration (times the number of sub-steps).
    const double * start = m_IterationStart.data();
    const double * end = m_NextCoordinates.data();
    double         largest = 0.0;
    for (SizeValueType i = 0; i < numberOfPoints; ++i)
    {
      const double d[3] = { end[3 * i] - start[3 * i],
                            end[3 * i + 1] - start[3 * i + 1],
                            end[3 * i + 2] - start[3 * i + 2] };
      const double squared = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
      largest = std::max(largest, squared);
      if (diagnose)
      {
        m_DisplacementMagnitudes[i] = static_cast<float>(std::sqrt(squared));
        m_InternalForceMagnitudes[i] *= static_cast<float>(m_NumberOfSubSteps);
      }
    }
    std::fill(blockMaximum.begin(), blockMaximum.end(), 0.0);
    if (numberOfBlocks > 0)
    {
      blockMaximum[0] = std::sqrt(largest);
    }
  }

  m_NumberOfDampedVertices = 0;
  m_NumberOfActiveVertices = 0;
  double largestNormal = 0.0;
  if (m_DampOscillations || m_ConvergenceFraction > 0.0 || m_ConvergenceAlongNormals)
  {
    this->FinishStep(
      m_NumberOfSubSteps > 1 ? m_IterationStart.data() : coordinates.data(), blockMaximum, diagnose, largestNormal);
  }
  if (m_PreventSelfIntersections)
  {
    this->ConstrainSelfIntersections(blockMaximum, diagnose, largestNormal);
  }
  coordinates.swap(m_NextCoordinates);

  m_LastMaximumDisplacement = *std::max_element(blockMaximum.begin(), blockMaximum.end());
  // Quiet: the largest displacement below the tolerance, or with
  // ConvergenceFraction > 0, at most that fraction of the vertices moving by
  // the tolerance or more (along their normals with ConvergenceAlongNormals).
  const double largestMeasured = m_ConvergenceAlongNormals ? largestNormal : m_LastMaximumDisplacement;
  const bool   quiet = m_ConvergenceFraction > 0.0 ? static_cast<double>(m_NumberOfActiveVertices) <=
                                                     m_ConvergenceFraction * static_cast<double>(numberOfPoints)
                                                   : largestMeasured < m_ConvergenceTolerance;
  if (m_ConvergenceTolerance > 0.0 && quiet)
  {
    m_Converged = ++m_QuietIterations >= m_ConvergenceWindow;
  }
  else
  {
    m_QuietIterations = 0;
  }

  // Remeshing after the step of every RemeshingInterval-th iteration: the
  // output of such an iteration is the remeshed surface.
  if (m_RemeshingEdgeLength > 0.0 && (this->GetCurrentIteration() + 1) % m_RemeshingInterval == 0)
  {
    this->Remesh();
  }
  if (diagnose)
  {
    this->PublishDiagnostics();
  }
}

template <typename TMesh, typename TForceImage>
void
DeformableMeshFilter<TMesh, TForceImage>::PublishDiagnostics()
{
  // Indexed by output point identifier: the internal order scattered back
  // when the filter renumbered the input's points.
  const std::vector<uint32_t> & ids = this->GetOutputPointIdentifiers();
  if (ids.empty() || ids.size() != m_DisplacementMagnitudes.size())
  {
    std::vector<float>().swap(m_PublicDisplacementMagnitudes);
    std::vector<float>().swap(m_PublicExternalForceMagnitudes);
    std::vector<float>().swap(m_PublicInternalForceMagnitudes);
    return;
  }
  const std::size_t n = ids.size();
  m_PublicDisplacementMagnitudes.resize(n);
  m_PublicExternalForceMagnitudes.resize(n);
  m_PublicInternalForceMagnitudes.resize(n);
  for (std::size_t i = 0; i < n; ++i)
  {
    m_PublicDisplacementMagnitudes[ids[i]] = m_DisplacementMagnitudes[i];
    m_PublicExternalForceMagnitudes[ids[i]] = m_ExternalForceMagnitudes[i];
    m_PublicInternalForceMagnitudes[ids[i]] = m_InternalForceMagnitudes[i];
  }
}

template <typename TMesh, typename TForceImage>
void
DeformableMeshFilter<TMesh, TForceImage>::RenumberForLocality(std::vector<IndexType32> & triangles,
                                                              std::vector<uint64_t> &    edges)
{
  // The step reads the coordinates of each vertex's neighbours: when many
  // edges join vertices numbered far apart (more than 2048 apart, 48 kB of
  // coordinates), those reads miss the caches. Such a numbering is replaced
  // by the Morton order of the positions; a local one is kept as it is (the
  // output bit for bit as without renumbering).
  const SizeValueType numberOfPoints = this->GetNumberOfCachedPoints();
  std::size_t         far = 0;
  for (const uint64_t e : edges)
  {
    far += (e & 0xffffffffULL) - (e >> 32) > RenumberingWindow;
  }
  const bool renumber = m_RenumberForLocality && numberOfPoints > RenumberingWindow && !edges.empty() &&
                        static_cast<double>(far) > RenumberingFarEdgeFraction * static_cast<double>(edges.size());
  m_FarEdgeFraction = edges.empty() ? 0.0 : static_cast<double>(far) / static_cast<double>(edges.size());
  m_Renumbered = renumber;
  if (!renumber)
  {
    return;
  }
  std::vector<double> &          x = this->GetCoordinates();
  const std::vector<IndexType32> order = DeformableMeshRemesher::BreadthFirstOrder(x.data(), numberOfPoints, edges);
  const std::vector<IndexType32> rank = this->ApplyOrder(x, order);
  for (IndexType32 & v : triangles)
  {
    v = rank[v];
  }
  for (uint64_t & e : edges)
  {
    const uint64_t a = rank[e >> 32];
    const uint64_t b = rank[e & 0xffffffffULL];
    e = std::min(a, b) << 32 | std::max(a, b);
  }
  this->SetOutputPointIdentifiers(std::vector<uint32_t>(order.begin(), order.end()));
}

template <typename TMesh, typename TForceImage>
void
DeformableMeshFilter<TMesh, TForceImage>::Remesh()
{
  std::vector<double> & x = this->GetCoordinates();
  const SizeValueType   numberOfPoints = this->GetNumberOfCachedPoints();
  x.resize(3 * numberOfPoints); // the guard value goes
  m_Remesher.SetTargetEdgeLength(m_RemeshingEdgeLength);
  m_Remesher.SetMultiThreader(this->GetMultiThreader(), this->GetNumberOfWorkUnits());
  m_Remesher.SetIncremental(true);
  m_NumberOfPointsLockedByRemeshing = 0;
  if (m_PreventSelfIntersections)
  {
    // The input is kept for RemeshWithoutContacts(), which may remesh it
    // again: it moves (a swap) to m_RemeshInput*, and the remesher writes
    // its output into the filter's arrays, whose memory the last remeshing
    // left there (two copies and 48 MB of new pages at a million points,
    // before).
    m_RemeshInputCoordinates.swap(x);
    m_RemeshInputTriangles.swap(m_Triangles);
    const std::vector<double> &      before = m_RemeshInputCoordinates;
    const std::vector<IndexType32> & beforeTriangles = m_RemeshInputTriangles;
    m_Remesher.Remesh(before, numberOfPoints, beforeTriangles, x, m_Triangles);
    const SizeValueType operations = m_OperationsSinceRenumbering;
    const SizeValueType renumberings = m_NumberOfLocalityRenumberings;
    this->RenumberRemeshed(x);
    this->RemeshWithoutContacts(before, beforeTriangles);
    if (m_NumberOfPointsLockedByRemeshing > 0)
    {
      // Remeshed again from the input, with points locked: not renumbered.
      const RemeshingStatisticsType & again = m_Remesher.GetStatistics();
      m_OperationsSinceRenumbering = operations + again.splits + again.collapses;
      m_NumberOfLocalityRenumberings = renumberings;
    }
  }
  else
  {
    m_Remesher.Remesh(x, numberOfPoints, m_Triangles);
    this->RenumberRemeshed(x);
  }
  const RemeshingStatisticsType & last = m_Remesher.GetStatistics();
  m_RemeshingStatistics.splits += last.splits;
  m_RemeshingStatistics.collapses += last.collapses;
  m_RemeshingStatistics.flips += last.flips;
  m_RemeshingStatistics.relaxed += last.relaxed;
  if (!m_Remesher.GetTopologyChanged() && x.size() == 3 * numberOfPoints)
  {
    // Only positions moved (relaxation): the numbering, the cells, the
    // topology and the per-vertex state stay.
    x.push_back(0.0);
    ++m_NumberOfRemeshings;
    m_NumberOfCollisionsPrevented = 0;
    m_NumberOfConstrainedVertices = 0;
    if (!m_PreventSelfIntersections)
    {
      m_Collision.Invalidate();
    }
    return; // with PreventSelfIntersections the index was built at x
  }
  const std::vector<IndexType32> & parents = m_Remesher.Parents();
  const SizeValueType              newNumberOfPoints = parents.size();
  if (newNumberOfPoints >= std::numeric_limits<IndexType32>::max())
  {
    itkExceptionMacro("Remeshing made too many points (" << newNumberOfPoints << ").");
  }
  x.push_back(0.0);
  // The step writes every point's next position before anything reads it:
  // only the guard value is set (a fill cost 2 to 3 ms a remeshing at a
  // million points).
  m_NextCoordinates.resize(3 * newNumberOfPoints + 1);
  m_NextCoordinates.back() = 0.0;

  // Per-vertex state carried from each new vertex's parent (itself, or an
  // end-point of the edge it was split from).
  // In parallel (a serial pass cost 8 ms a remeshing at a million points).
  MultiThreaderBase * threader = this->GetMultiThreader();
  const auto          remap = [&parents, newNumberOfPoints, threader, this](auto & values) {
    if (values.empty())
    {
      return;
    }
    std::remove_reference_t<decltype(values)> mapped(newNumberOfPoints);
    constexpr SizeValueType                   block = 16384;
    threader->SetNumberOfWorkUnits(this->GetNumberOfWorkUnits());
    threader->ParallelizeArray(
      0,
      (newNumberOfPoints + block - 1) / block,
      [&](SizeValueType b) {
        for (SizeValueType i = b * block; i < std::min(newNumberOfPoints, (b + 1) * block); ++i)
        {
          mapped[i] = values[parents[i]];
        }
      },
      nullptr);
    values.swap(mapped);
  };
  remap(m_BalloonReleased);
  remap(m_OscillationState);
  // The contact memory follows the parents too (a new vertex of a held
  // edge is held as its parent).
  if (!m_ContactFactors.empty())
  {
    remap(m_ContactFactors);
    m_HeldPoints.clear();
    for (SizeValueType i = 0; i < newNumberOfPoints; ++i)
    {
      if (m_ContactFactors[i] < 1.0f)
      {
        m_HeldPoints.push_back(static_cast<IndexType32>(i));
      }
    }
  }
  remap(m_DisplacementMagnitudes);
  remap(m_ExternalForceMagnitudes);
  remap(m_InternalForceMagnitudes);
  // Sized again (and filled) at the next iteration; their memory is kept:
  // freed here, it came back as new pages to fault in and clear at every
  // remeshing (32 MB at a million points).
  m_Umbrella.clear();
  m_Normals.clear();
  m_NormalSpeeds.clear();
  m_EdgeHits.clear();

  this->SetCachedTriangles(newNumberOfPoints, m_Triangles);
  if (!this->BuildTopologyFromRemesher())
  {
    std::vector<uint64_t> edges;
    const bool            unique = m_Remesher.Edges(edges);
    this->BuildTopology(m_Triangles, edges, unique, false);
  }
  ++m_NumberOfRemeshings;
  // The remesher never moves a boundary vertex and splits boundary edges at
  // their midpoints: the new boundary vertices lie on the boundary curve and
  // are held from now on.
  this->FindBoundaryVertices(m_Triangles);
  // The collision test's tables for the new mesh (no check: see
  // ResetCollision()); with PreventSelfIntersections RemeshWithoutContacts()
  // has set them and built the index at these positions (or certified the
  // surface without one: SurfaceCollision::IsStarShaped()).
  if (m_PreventSelfIntersections && m_Collision.HasSurface() && m_Collision.GetNumberOfPoints() == newNumberOfPoints)
  {
    std::vector<uint32_t>().swap(m_CollisionTriangles);
    m_CollisionTrianglesAreMeshTriangles = true;
    m_NumberOfCollisionsPrevented = 0;
    m_NumberOfConstrainedVertices = 0;
  }
  else
  {
    this->ResetCollision(&m_Triangles, false);
  }
}

template <typename TMesh, typename TForceImage>
std::vector<typename DeformableMeshFilter<TMesh, TForceImage>::IndexType32>
DeformableMeshFilter<TMesh, TForceImage>::ApplyOrder(std::vector<double> & x, const std::vector<IndexType32> & order)
{
  const SizeValueType      numberOfPoints = order.size();
  std::vector<IndexType32> rank(numberOfPoints);
  std::vector<double>      permuted(3 * numberOfPoints);
  // In parallel (order is a permutation: each k writes its own entries).
  constexpr SizeValueType block = 16384;
  MultiThreaderBase *     threader = this->GetMultiThreader();
  threader->SetNumberOfWorkUnits(this->GetNumberOfWorkUnits());
  threader->ParallelizeArray(
    0,
    (numberOfPoints + block - 1) / block,
    [&](SizeValueType b) {
      for (SizeValueType k = b * block; k < std::min(numberOfPoints, (b + 1) * block); ++k)
      {
        rank[order[k]] = static_cast<IndexType32>(k);
        std::copy(x.data() + 3 * static_cast<SizeValueType>(order[k]),
                  x.data() + 3 * static_cast<SizeValueType>(order[k]) + 3,
                  permuted.data() + 3 * k);
      }
    },
    nullptr);
  std::copy(permuted.begin(), permuted.end(), x.begin());
  return rank;
}

template <typename TMesh, typename TForceImage>
void
DeformableMeshFilter<TMesh, TForceImage>::RenumberRemeshed(std::vector<double> & x)
{
  // After many operations, once a remeshing changes few points (or after
  // very many operations), the breadth-first numbering (see the class
  // documentation), the remesher's table renumbered with the points, so that
  // what follows (the contact check, the per-vertex state carried from
  // Parents(), the step's tables from the remesher's fans) sees a remeshing
  // whose output is numbered so, and the next remeshing stays incremental.
  const RemeshingStatisticsType & last = m_Remesher.GetStatistics();
  m_OperationsSinceRenumbering += last.splits + last.collapses;
  const SizeValueType numberOfPoints = m_Remesher.Parents().size();
  const auto          operations = static_cast<double>(m_OperationsSinceRenumbering);
  const auto          points = static_cast<double>(numberOfPoints);
  const bool          calm = static_cast<double>(last.splits + last.collapses) <= RenumberingCalmFraction * points;
  if (!m_RenumberForLocality || !m_Remesher.GetTopologyChanged() || numberOfPoints <= RenumberingWindow ||
      x.size() != 3 * numberOfPoints || operations <= RenumberingOperationFraction * points ||
      (!calm && operations <= RenumberingOperationLimit * points))
  {
    return;
  }
  const std::vector<IndexType32> order = m_Remesher.OutputBreadthFirstOrder(x.data());
  // The triangles renumbered and reordered with the remesher's table.
  if (order.size() != numberOfPoints || !m_Remesher.RenumberOutput(order, m_Triangles))
  {
    return;
  }
  this->ApplyOrder(x, order);
  m_OperationsSinceRenumbering = 0;
  ++m_NumberOfLocalityRenumberings;
}

template <typename TMesh, typename TForceImage>
void
DeformableMeshFilter<TMesh, TForceImage>::RemeshWithoutContacts(const std::vector<double> &      before,
                                                                const std::vector<IndexType32> & beforeTriangles)
{
  std::vector<double> & x = this->GetCoordinates();
  const SizeValueType   numberOfPoints = before.size() / 3;
  // Triangles as sorted triples of point indices (of the input's points).
  using Triple = std::array<IndexType32, 3>;
  const auto sorted = [](IndexType32 a, IndexType32 b, IndexType32 c) {
    Triple t{ { a, b, c } };
    std::sort(t.begin(), t.end());
    return t;
  };
  std::vector<std::pair<Triple, SizeValueType>> candidates;
  std::vector<uint8_t>                          candidatePoint;

  std::vector<uint8_t> locked(numberOfPoints, 0);
  std::vector<uint8_t> changed;
  std::vector<uint8_t> pointMoved;
  std::vector<uint8_t> contacts;
  std::vector<uint8_t> seeds;
  for (;;)
  {
    const std::vector<IndexType32> & parents = m_Remesher.Parents();
    const SizeValueType              remeshedTriangles = m_Triangles.size() / 3;
    // The collision test's surface and index for the remeshed mesh, built
    // at its positions: the next step keeps the index. A surface that the
    // star-shaped certificate accepts has no contact: the flags below, which
    // say which pairs count, are then not needed.
    m_Collision.SetSurface(parents.size(),
                           m_Triangles.data(),
                           remeshedTriangles,
                           this->GetMultiThreader(),
                           this->GetNumberOfWorkUnits(),
                           m_Remesher.IsOutputClosed());
    if (m_Collision.CertifyContacts(
          x.data(), m_MinimumDistance, this->GetMultiThreader(), this->GetNumberOfWorkUnits()))
    {
      break;
    }
    const auto moved = [&](IndexType32 v) {
      const IndexType32 p = parents[v];
      return x[3 * v] != before[3 * p] || x[3 * v + 1] != before[3 * p + 1] || x[3 * v + 2] != before[3 * p + 2];
    };
    // In parallel, whether each point moved, then whether a triangle's
    // points did. A triangle whose points did not move and around none of
    // which the remesher changed the triangles is the input's (0); 2: its
    // points did not move but one's triangles changed, the input's
    // triangles decide, below, for the blocks that have such triangles
    // (blockUnmoved).
    const SizeValueType     remeshedPoints = parents.size();
    constexpr SizeValueType block = 16384;
    MultiThreaderBase *     threader = this->GetMultiThreader();
    threader->SetNumberOfWorkUnits(this->GetNumberOfWorkUnits());
    pointMoved.resize(remeshedPoints);
    threader->ParallelizeArray(
      0,
      (remeshedPoints + block - 1) / block,
      [&](SizeValueType b) {
        for (SizeValueType i = b * block; i < std::min(remeshedPoints, (b + 1) * block); ++i)
        {
          pointMoved[i] = moved(static_cast<IndexType32>(i)) ? 1 : 0;
        }
      },
      nullptr);
    const SizeValueType  triangleBlocks = (remeshedTriangles + block - 1) / block;
    std::vector<uint8_t> blockUnmoved(triangleBlocks, 0);
    changed.resize(remeshedTriangles);
    threader->ParallelizeArray(
      0,
      triangleBlocks,
      [&](SizeValueType b) {
        uint8_t unmoved = 0;
        for (SizeValueType t = b * block; t < std::min(remeshedTriangles, (b + 1) * block); ++t)
        {
          const IndexType32 * v = m_Triangles.data() + 3 * t;
          if ((pointMoved[v[0]] | pointMoved[v[1]] | pointMoved[v[2]]) != 0)
          {
            changed[t] = 1;
          }
          else
          {
            changed[t] = m_Remesher.OutputPointChanged(v[0]) || m_Remesher.OutputPointChanged(v[1]) ||
                             m_Remesher.OutputPointChanged(v[2])
                           ? 2
                           : 0;
          }
          unmoved |= changed[t] == 2 ? 1 : 0;
        }
        blockUnmoved[b] = unmoved;
      },
      nullptr);
    // The remeshed triangles marked 2, as triples of their points' parents,
    // looked up among the input's triangles in one pass over them (those all
    // of whose points are parents of a candidate's); both in parallel.
    std::vector<std::vector<std::pair<Triple, SizeValueType>>> blockCandidates(triangleBlocks);
    threader->ParallelizeArray(
      0,
      triangleBlocks,
      [&](SizeValueType b) {
        for (SizeValueType t = b * block; blockUnmoved[b] != 0 && t < std::min(remeshedTriangles, (b + 1) * block); ++t)
        {
          if (changed[t] == 2)
          {
            const IndexType32 * v = m_Triangles.data() + 3 * t;
            blockCandidates[b].emplace_back(sorted(parents[v[0]], parents[v[1]], parents[v[2]]), t);
            changed[t] = 1;
          }
        }
      },
      nullptr);
    candidates.clear();
    for (const auto & found : blockCandidates)
    {
      candidates.insert(candidates.end(), found.begin(), found.end());
    }
    if (!candidates.empty())
    {
      std::sort(candidates.begin(), candidates.end());
      candidatePoint.assign(numberOfPoints, 0);
      for (const auto & candidate : candidates)
      {
        for (const IndexType32 p : candidate.first)
        {
          candidatePoint[p] = 1;
        }
      }
      const SizeValueType                     inputTriangles = beforeTriangles.size() / 3;
      const SizeValueType                     inputBlocks = (inputTriangles + block - 1) / block;
      std::vector<std::vector<SizeValueType>> matched(inputBlocks);
      threader->ParallelizeArray(
        0,
        inputBlocks,
        [&](SizeValueType b) {
          for (SizeValueType t = b * block; t < std::min(inputTriangles, (b + 1) * block); ++t)
          {
            const IndexType32 * v = beforeTriangles.data() + 3 * t;
            if ((candidatePoint[v[0]] & candidatePoint[v[1]] & candidatePoint[v[2]]) == 0)
            {
              continue;
            }
            const Triple triple = sorted(v[0], v[1], v[2]);
            auto         it =
              std::lower_bound(candidates.begin(), candidates.end(), triple, [](const auto & c, const Triple & k) {
                return c.first < k;
              });
            for (; it != candidates.end() && it->first == triple; ++it)
            {
              matched[b].push_back(it->second);
            }
          }
        },
        nullptr);
      for (const auto & found : matched)
      {
        for (const SizeValueType t : found)
        {
          changed[t] = 0; // the input's triangle, its points unmoved
        }
      }
    }
    const SizeValueType found = m_Collision.FindContacts(x.data(),
                                                         changed.data(),
                                                         m_MinimumDistance,
                                                         contacts,
                                                         this->GetMultiThreader(),
                                                         this->GetNumberOfWorkUnits(),
                                                         false);
    if (found == 0)
    {
      break;
    }
    // Lock the input points of the triangles in contact and their
    // neighbours (the input's triangles around them), then remesh the input
    // again.
    seeds.assign(numberOfPoints, 0);
    for (SizeValueType t = 0; t < remeshedTriangles; ++t)
    {
      if (contacts[t] != 0)
      {
        for (unsigned int k = 0; k < 3; ++k)
        {
          seeds[parents[m_Triangles[3 * t + k]]] = 1;
        }
      }
    }
    bool grew = false;
    for (SizeValueType t = 0; t < beforeTriangles.size() / 3; ++t)
    {
      const IndexType32 * v = beforeTriangles.data() + 3 * t;
      if (seeds[v[0]] != 0 || seeds[v[1]] != 0 || seeds[v[2]] != 0)
      {
        for (unsigned int k = 0; k < 3; ++k)
        {
          grew = grew || locked[v[k]] == 0;
          locked[v[k]] = 1;
        }
      }
    }
    if (!grew)
    {
      // Every triangle in contact was the input's (cannot happen: a changed
      // triangle has a point that was not locked); keep the input.
      std::fill(locked.begin(), locked.end(), uint8_t{ 1 });
    }
    m_Remesher.SetLockedVertices(locked);
    m_Remesher.Remesh(before, numberOfPoints, beforeTriangles, x, m_Triangles);
    m_NumberOfPointsLockedByRemeshing =
      static_cast<SizeValueType>(std::count(locked.begin(), locked.end(), uint8_t{ 1 }));
    if (!grew)
    {
      // The collision test's surface for this output; the next step builds
      // its index.
      m_Collision.SetSurface(m_Remesher.Parents().size(),
                             m_Triangles.data(),
                             m_Triangles.size() / 3,
                             this->GetMultiThreader(),
                             this->GetNumberOfWorkUnits(),
                             m_Remesher.IsOutputClosed());
      break;
    }
  }
}

template <typename TMesh, typename TForceImage>
void
DeformableMeshFilter<TMesh, TForceImage>::PrintSelf(std::ostream & os, Indent indent) const
{
  Superclass::PrintSelf(os, indent);
  os << indent << "ScaleFactor: " << m_ScaleFactor << std::endl;
  os << indent << "Elasticity: " << m_Elasticity << std::endl;
  os << indent << "TangentialElasticity: " << (m_TangentialElasticity ? "On" : "Off") << std::endl;
  os << indent << "TangentialDrift: " << m_TangentialDrift
     << (this->GetSuppressTangentialDrift() ? " (suppressed)" : " (kept)") << std::endl;
  os << indent << "Rigidity: " << m_Rigidity << std::endl;
  os << indent << "Balloon: " << m_Balloon << std::endl;
  os << indent << "RegionWeight: " << m_RegionWeight << std::endl;
  os << indent << "RegionSigma: " << m_RegionSigma << std::endl;
  os << indent << "EdgeSearchWeight: " << m_EdgeSearchWeight << std::endl;
  os << indent << "EdgeSearchDistance: " << m_EdgeSearchDistance << std::endl;
  os << indent << "EdgePolarity: " << m_EdgePolarity << std::endl;
  os << indent << "NumberOfEdgeHits: " << m_NumberOfEdgeHits << std::endl;
  os << indent << "IntensityTolerance: " << m_IntensityTolerance << std::endl;
  os << indent << "EstimateObjectIntensityRange: " << m_EstimateObjectIntensityRange << std::endl;
  os << indent << "ObjectIntensityRange: [" << m_ObjectIntensityLower << ", " << m_ObjectIntensityUpper << "], width "
     << m_ObjectIntensityWidth << std::endl;
  os << indent << "ReferenceEdgeLength: " << m_ReferenceEdgeLength << std::endl;
  os << indent << "MaximumNumberOfSubSteps: " << m_MaximumNumberOfSubSteps << std::endl;
  os << indent << "NumberOfSubSteps: " << m_NumberOfSubSteps << std::endl;
  os << indent << "EdgeWeight: " << m_EdgeWeight << std::endl;
  os << indent << "ObjectIntensityStatistics: median " << m_ObjectIntensityMedian << ", spread "
     << m_ObjectIntensitySpread << (m_ObjectIntensityStatisticsGiven ? " (given)" : "") << std::endl;
  os << indent << "EstimateBackgroundIntensity: " << m_EstimateBackgroundIntensity << std::endl;
  os << indent << "BackgroundUpdateInterval: " << m_BackgroundUpdateInterval << std::endl;
  os << indent << "MaximumStepLength: " << m_MaximumStepLength << std::endl;
  os << indent << "ConvergenceTolerance: " << m_ConvergenceTolerance << std::endl;
  os << indent << "ConvergenceWindow: " << m_ConvergenceWindow << std::endl;
  os << indent << "ConvergenceFraction: " << m_ConvergenceFraction << std::endl;
  os << indent << "ConvergenceAlongNormals: " << (m_ConvergenceAlongNormals ? "On" : "Off") << std::endl;
  os << indent << "NumberOfActiveVertices: " << m_NumberOfActiveVertices << std::endl;
  os << indent << "DampOscillations: " << (m_DampOscillations ? "On" : "Off") << std::endl;
  os << indent << "NumberOfDampedVertices: " << m_NumberOfDampedVertices << std::endl;
  os << indent << "FixedBoundary: " << (m_FixedBoundary ? "On" : "Off") << " (" << m_BoundaryVertices.size()
     << " boundary vertices)" << std::endl;
  os << indent << "Contours: " << m_NumberOfClosedContours << " closed, " << m_NumberOfOpenContours << " open"
     << " (first end " << m_FirstContourEnd << ")" << std::endl;
  os << indent << "PreventSelfIntersections: " << (m_PreventSelfIntersections ? "On" : "Off") << std::endl;
  os << indent << "MinimumDistance: " << m_MinimumDistance << std::endl;
  os << indent << "RememberContacts: " << (m_RememberContacts ? "On" : "Off") << std::endl;
  os << indent << "NumberOfCollisionsPrevented: " << m_NumberOfCollisionsPrevented << " (total "
     << m_TotalNumberOfCollisionsPrevented << "), constrained vertices: " << m_NumberOfConstrainedVertices
     << ", collision index rebuilds: " << m_Collision.GetNumberOfRebuilds() << std::endl;
  os << indent << "Converged: " << (m_Converged ? "true" : "false") << std::endl;
  os << indent << "QuietIterations: " << m_QuietIterations << std::endl;
  os << indent << "LastMaximumDisplacement: " << m_LastMaximumDisplacement << std::endl;
  os << indent << "OrientationSign: " << m_OrientationSign << std::endl;
  os << indent << "Neighbours: " << m_Neighbours.size() << " entries, Triangles: " << m_NumberOfTriangles
     << ", vertices outside a single fan: " << m_GeneralVertices.size() << std::endl;
  os << indent << "OrderedByValence: " << (m_ValenceOrder.empty() ? "Off" : "On") << std::endl;
  os << indent << "RemeshingEdgeLength: " << m_RemeshingEdgeLength << std::endl;
  os << indent << "RemeshingInterval: " << m_RemeshingInterval << std::endl;
  os << indent << "NumberOfRemeshings: " << m_NumberOfRemeshings << std::endl;
  os << indent << "RemeshingStatistics: " << m_RemeshingStatistics.splits << " splits, "
     << m_RemeshingStatistics.collapses << " collapses, " << m_RemeshingStatistics.flips << " flips, "
     << m_RemeshingStatistics.relaxed << " relaxed" << std::endl;
  os << indent << "NumberOfPointsLockedByRemeshing: " << m_NumberOfPointsLockedByRemeshing << std::endl;
  os << indent << "RenumberForLocality: " << (m_RenumberForLocality ? "On" : "Off") << std::endl;
  os << indent << "Renumbered: " << (m_Renumbered ? "true" : "false") << " (far edge fraction " << m_FarEdgeFraction
     << ")" << std::endl;
  os << indent << "NumberOfLocalityRenumberings: " << m_NumberOfLocalityRenumberings << " ("
     << m_OperationsSinceRenumbering << " remeshing operations since the last)" << std::endl;
  os << indent << "ForceBuffer: " << m_ForceBuffer << std::endl;
  os << indent << "PhysicalToIndex: [" << m_PhysicalToIndex[0][0] << ' ' << m_PhysicalToIndex[0][1] << ' '
     << m_PhysicalToIndex[0][2] << "; " << m_PhysicalToIndex[1][0] << ' ' << m_PhysicalToIndex[1][1] << ' '
     << m_PhysicalToIndex[1][2] << "; " << m_PhysicalToIndex[2][0] << ' ' << m_PhysicalToIndex[2][1] << ' '
     << m_PhysicalToIndex[2][2] << ']' << std::endl;
  os << indent << "ForceOrigin: [" << m_ForceOrigin[0] << ' ' << m_ForceOrigin[1] << ' ' << m_ForceOrigin[2] << ']'
     << std::endl;
  os << indent << "BufferStart: [" << m_BufferStart[0] << ' ' << m_BufferStart[1] << ' ' << m_BufferStart[2] << ']'
     << std::endl;
  os << indent << "BufferSize: [" << m_BufferSize[0] << ' ' << m_BufferSize[1] << ' ' << m_BufferSize[2] << ']'
     << std::endl;
}

} // end namespace itk

#include "itkDeformableMeshFilterImageTerms.hxx"

#endif
