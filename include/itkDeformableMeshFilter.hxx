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
#include "itkMultiThreaderBase.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

namespace itk
{

template <typename TMesh, typename TForceImage>
DeformableMeshFilter<TMesh, TForceImage>::DeformableMeshFilter()
{
  // The force image is checked in VerifyPreconditions() with a clearer message
  // than the generic one of a required input.
  this->SetNumberOfRequiredInputs(1);
}

template <typename TMesh, typename TForceImage>
void
DeformableMeshFilter<TMesh, TForceImage>::VerifyPreconditions() ITKv5_CONST
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
  if (!(m_MaximumStepLength >= 0.0 && std::isfinite(m_MaximumStepLength)))
  {
    itkExceptionMacro("MaximumStepLength must be finite and non-negative; it is " << m_MaximumStepLength << ".");
  }
  if (!(m_ConvergenceTolerance >= 0.0 && std::isfinite(m_ConvergenceTolerance)))
  {
    itkExceptionMacro("ConvergenceTolerance must be finite and non-negative; it is " << m_ConvergenceTolerance << ".");
  }
}

template <typename TMesh, typename TForceImage>
void
DeformableMeshFilter<TMesh, TForceImage>::GenerateData()
{
  this->PrepareForceSampler();
  m_ForceImageCheck.Verify(this->GetForceImage(), m_ScaleFactor, m_Balloon, m_MaximumStepLength);
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
  m_ForceBuffer = image->GetBufferPointer();

  using MatrixType = Matrix<double, 3, 3>;
  MatrixType indexToPhysical;
  for (unsigned int r = 0; r < 3; ++r)
  {
    for (unsigned int c = 0; c < 3; ++c)
    {
      indexToPhysical(r, c) = image->GetDirection()(r, c) * image->GetSpacing()[c];
    }
  }
  const vnl_matrix<double> physicalToIndex = indexToPhysical.GetInverse().as_matrix();
  for (unsigned int r = 0; r < 3; ++r)
  {
    for (unsigned int c = 0; c < 3; ++c)
    {
      m_PhysicalToIndex[r][c] = physicalToIndex(r, c);
    }
    m_ForceOrigin[r] = image->GetOrigin()[r];
    m_BufferStart[r] = static_cast<double>(region.GetIndex()[r]);
    m_BufferSize[r] = static_cast<int64_t>(region.GetSize()[r]);
  }
  // Continuous index c = M (x - origin) - start = M x - (M origin + start).
  ForceSampler & sampler = m_Sampler;
  for (unsigned int c = 0; c < 3; ++c)
  {
    sampler.columns[c] = Vec4{ m_PhysicalToIndex[0][c], m_PhysicalToIndex[1][c], m_PhysicalToIndex[2][c], 0.0 };
  }
  double offset[3];
  for (unsigned int r = 0; r < 3; ++r)
  {
    offset[r] = m_PhysicalToIndex[r][0] * m_ForceOrigin[0] + m_PhysicalToIndex[r][1] * m_ForceOrigin[1] +
                m_PhysicalToIndex[r][2] * m_ForceOrigin[2] + m_BufferStart[r];
  }
  sampler.offset = Vec4{ offset[0], offset[1], offset[2], 0.0 };
  // Same inside test as itk::LinearInterpolateImageFunction: half a voxel
  // beyond the first and last voxel centres, values clamped at the border.
  constexpr double infinity = std::numeric_limits<double>::infinity();
  sampler.lower = Vec4{ -0.5, -0.5, -0.5, -infinity };
  sampler.upper = Vec4{ static_cast<double>(m_BufferSize[0]) - 0.5,
                        static_cast<double>(m_BufferSize[1]) - 0.5,
                        static_cast<double>(m_BufferSize[2]) - 0.5,
                        infinity };
  sampler.buffer = m_ForceBuffer;
  sampler.lastX = m_BufferSize[0] - 1;
  sampler.lastY = m_BufferSize[1] - 1;
  sampler.lastZ = m_BufferSize[2] - 1;
  sampler.strideY = m_BufferSize[0];
  sampler.strideZ = m_BufferSize[0] * m_BufferSize[1];
  sampler.lastPixel = m_BufferSize[0] * m_BufferSize[1] * m_BufferSize[2] - 1;
  sampler.last = Vec4{
    static_cast<double>(sampler.lastX), static_cast<double>(sampler.lastY), static_cast<double>(sampler.lastZ), 0.0
  };
  constexpr double pixelBytes = sizeof(ForcePixelType);
  sampler.byteStrides = Vec4{ pixelBytes,
                              pixelBytes * static_cast<double>(sampler.strideY),
                              pixelBytes * static_cast<double>(sampler.strideZ),
                              0.0 };
  sampler.smallBuffer = (sampler.lastPixel + 1) * static_cast<int64_t>(sizeof(ForcePixelType)) <
                        static_cast<int64_t>(std::numeric_limits<int32_t>::max());
}

template <typename TMesh, typename TForceImage>
EDM_ALWAYS_INLINE auto
DeformableMeshFilter<TMesh, TForceImage>::SampleForce(const ForceSampler & sampler, const Vec4 & xi) -> Vec4
{
  using namespace DeformableMeshFilterDetail;
  const Vec4 c = sampler.columns[0] * Splat(xi[0]) + sampler.columns[1] * Splat(xi[1]) +
                 sampler.columns[2] * Splat(xi[2]) - sampler.offset;
  if (!InsideBox(c, sampler.lower, sampler.upper))
  {
    return Vec4{};
  }
  // c >= -0.5, so truncating c + 1 gives floor(c) + 1.
  const auto    fx = static_cast<int64_t>(c[0] + 1.0) - 1;
  const auto    fy = static_cast<int64_t>(c[1] + 1.0) - 1;
  const auto    fz = static_cast<int64_t>(c[2] + 1.0) - 1;
  const int64_t x0 = std::max<int64_t>(fx, 0);
  const int64_t x1 = std::min<int64_t>(fx + 1, sampler.lastX);
  const int64_t y0 = std::max<int64_t>(fy, 0) * sampler.strideY;
  const int64_t y1 = std::min<int64_t>(fy + 1, sampler.lastY) * sampler.strideY;
  const int64_t z0 = std::max<int64_t>(fz, 0) * sampler.strideZ;
  const int64_t z1 = std::min<int64_t>(fz + 1, sampler.lastZ) * sampler.strideZ;
  const int64_t corners[8] = { z0 + y0 + x0, z0 + y0 + x1, z0 + y1 + x0, z0 + y1 + x1,
                               z1 + y0 + x0, z1 + y0 + x1, z1 + y1 + x0, z1 + y1 + x1 };
  Vec4          p[8];
  // A padded load reads past the pixel: not at the last pixel of the buffer.
  if (corners[7] < sampler.lastPixel)
  {
    for (unsigned int k = 0; k < 8; ++k)
    {
      p[k] = PixelLoader<ForcePixelType, true>::Load(sampler.buffer[corners[k]]);
    }
  }
  else
  {
    for (unsigned int k = 0; k < 8; ++k)
    {
      p[k] = PixelLoader<ForcePixelType, false>::Load(sampler.buffer[corners[k]]);
    }
  }
  return Trilinear(p, c[0] - static_cast<double>(fx), c[1] - static_cast<double>(fy), c[2] - static_cast<double>(fz));
}

template <typename TMesh, typename TForceImage>
EDM_ALWAYS_INLINE void
DeformableMeshFilter<TMesh, TForceImage>::SampleForces(const ForceSampler & sampler,
                                                       const double *       x,
                                                       SizeValueType        begin,
                                                       SizeValueType        end,
                                                       double               scale,
                                                       Vec4 *               forces)
{
  using namespace DeformableMeshFilterDetail;
#if EDM_AVX2_SAMPLER
  if (sampler.smallBuffer)
  {
    // Four vertices at a time: their coordinates as one register per axis,
    // then continuous indices, inside test, weights and the byte offsets of
    // the eight corners (clamped at the border) in the lanes of registers;
    // the corners are then loaded and blended vertex by vertex.
    const char *  bytes = reinterpret_cast<const char *>(sampler.buffer);
    const __m128i lastBytes = _mm_set1_epi32(static_cast<int32_t>(sampler.lastPixel * sizeof(ForcePixelType)));
    constexpr SizeValueType maximumCount = ChunkSize; // the runs of StepBlock()
    alignas(32) int32_t     corners[8][maximumCount];
    alignas(32) double      weights[3][maximumCount];
    uint32_t                insideBits = 0;
    uint32_t                paddedBits = 0;
    itkAssertInDebugAndIgnoreInReleaseMacro(end - begin <= maximumCount);
    double tail[12];
    for (SizeValueType j = begin; j < end; j += 4)
    {
      // The last group of a run may be short: its coordinates are copied,
      // the missing vertices repeating the last one.
      const SizeValueType count = std::min<SizeValueType>(4, end - j);
      const double *      xj = x + 3 * j;
      if (count < 4)
      {
        for (SizeValueType k = 0; k < 12; ++k)
        {
          tail[k] = xj[std::min(k, 3 * count - 3 + k % 3)];
        }
        xj = tail;
      }
      const __m256d a = _mm256_loadu_pd(xj);     // x0 y0 z0 x1
      const __m256d b = _mm256_loadu_pd(xj + 4); // y1 z1 x2 y2
      const __m256d c = _mm256_loadu_pd(xj + 8); // z2 x3 y3 z3
      const __m256d axis[3] = { _mm256_permute4x64_pd(_mm256_blend_pd(_mm256_blend_pd(a, c, 0x2), b, 0x4), 0x6C),
                                _mm256_permute4x64_pd(_mm256_blend_pd(_mm256_blend_pd(a, b, 0x9), c, 0x4), 0xB1),
                                _mm256_permute4x64_pd(_mm256_blend_pd(_mm256_blend_pd(a, b, 0x2), c, 0x9), 0xC6) };
      int           inside = 0xF;
      __m128i       low[3];
      __m128i       high[3];
      for (unsigned int k = 0; k < 3; ++k)
      {
        // The products and sums in the order GCC gives SampleForce() with FMA:
        // both paths give the same bits there (checked on 300-step runs).
        __m256d ck = _mm256_mul_pd(_mm256_set1_pd(sampler.columns[1][k]), axis[1]);
        ck = _mm256_fmadd_pd(_mm256_set1_pd(sampler.columns[0][k]), axis[0], ck);
        ck = _mm256_fmadd_pd(_mm256_set1_pd(sampler.columns[2][k]), axis[2], ck);
        ck = _mm256_sub_pd(ck, _mm256_set1_pd(sampler.offset[k]));
        inside &= _mm256_movemask_pd(_mm256_and_pd(_mm256_cmp_pd(ck, _mm256_set1_pd(sampler.lower[k]), _CMP_GE_OQ),
                                                   _mm256_cmp_pd(ck, _mm256_set1_pd(sampler.upper[k]), _CMP_LT_OQ)));
        const __m256d f = _mm256_floor_pd(ck);
        const __m256d stride = _mm256_set1_pd(sampler.byteStrides[k]);
        _mm256_store_pd(weights[k] + (j - begin), _mm256_sub_pd(ck, f));
        low[k] = _mm256_cvttpd_epi32(_mm256_mul_pd(_mm256_max_pd(f, _mm256_setzero_pd()), stride));
        high[k] = _mm256_cvttpd_epi32(
          _mm256_mul_pd(_mm256_min_pd(_mm256_add_pd(f, _mm256_set1_pd(1.0)), _mm256_set1_pd(sampler.last[k])), stride));
      }
      const __m128i yz[4] = { _mm_add_epi32(low[1], low[2]),
                              _mm_add_epi32(high[1], low[2]),
                              _mm_add_epi32(low[1], high[2]),
                              _mm_add_epi32(high[1], high[2]) };
      for (unsigned int k = 0; k < 4; ++k)
      {
        _mm_store_si128(reinterpret_cast<__m128i *>(corners[2 * k] + (j - begin)), _mm_add_epi32(yz[k], low[0]));
        _mm_store_si128(reinterpret_cast<__m128i *>(corners[2 * k + 1] + (j - begin)), _mm_add_epi32(yz[k], high[0]));
      }
      // A padded load reads past the pixel: not at the last pixel of the buffer.
      const int padded = _mm_movemask_ps(_mm_castsi128_ps(_mm_cmpgt_epi32(lastBytes, _mm_add_epi32(yz[3], high[0]))));
      insideBits |= static_cast<uint32_t>(inside) << (j - begin);
      paddedBits |= static_cast<uint32_t>(padded) << (j - begin);
    }
    // Then the loads and blends, which depend on nothing but the offsets
    // above: the loads of several vertices are in flight at once.
    for (SizeValueType l = 0; l < end - begin; ++l)
    {
      Vec4 force{};
      if (insideBits & (uint32_t{ 1 } << l))
      {
        Vec4 p[8];
        if (paddedBits & (uint32_t{ 1 } << l))
        {
          for (unsigned int k = 0; k < 8; ++k)
          {
            p[k] =
              PixelLoader<ForcePixelType, true>::Load(*reinterpret_cast<const ForcePixelType *>(bytes + corners[k][l]));
          }
        }
        else
        {
          for (unsigned int k = 0; k < 8; ++k)
          {
            p[k] = PixelLoader<ForcePixelType, false>::Load(
              *reinterpret_cast<const ForcePixelType *>(bytes + corners[k][l]));
          }
        }
        force = Splat(scale) * Trilinear(p, weights[0][l], weights[1][l], weights[2][l]);
      }
      forces[l] = force;
    }
    return;
  }
#endif
  for (SizeValueType j = begin; j < end; ++j)
  {
    forces[j - begin] = Splat(scale) * SampleForce(sampler, Load4(x + 3 * j));
  }
}

template <typename TMesh, typename TForceImage>
void
DeformableMeshFilter<TMesh, TForceImage>::BuildTopology()
{
  const MeshType *    input = this->GetInput();
  const SizeValueType numberOfPoints = this->GetNumberOfCachedPoints();
  if (numberOfPoints >= std::numeric_limits<IndexType32>::max())
  {
    itkExceptionMacro("The input mesh has too many points (" << numberOfPoints << ").");
  }

  std::vector<uint64_t> edges;
  // Triangles (polygons fan-triangulated), needed only to build the tables.
  std::vector<IndexType32> triangles;
  auto                     addEdge = [&](uint64_t a, uint64_t b) {
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

  std::sort(edges.begin(), edges.end());
  edges.erase(std::unique(edges.begin(), edges.end()), edges.end());

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
  const SizeValueType      numberOfTriangles = triangles.size() / 3;
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
      for (unsigned int k = 0; k < 3; ++k)
      {
        IndexType32 * pair = pairs.data() + 2 * static_cast<SizeValueType>(fill[triangles[3 * t + k]]++);
        pair[0] = triangles[3 * t + (k + 1) % 3];
        pair[1] = triangles[3 * t + (k + 2) % 3];
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
  std::vector<IndexType32>                         ring;
  std::vector<IndexType32>                         sortedRing;
  std::vector<IndexType32>                         sortedNeighbours;
  std::vector<std::pair<IndexType32, IndexType32>> fan;  // pairs sorted by b
  std::vector<IndexType32>                         ends; // the c of the pairs, sorted
  for (SizeValueType i = 0; i < numberOfPoints; ++i)
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
    else if (numberOfPairs > 0 && oneFanPossible)
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
      m_GeneralVertices.push_back(static_cast<IndexType32>(i));
      m_GeneralPairs.insert(m_GeneralPairs.end(), vertexPairs, vertexPairs + 2 * numberOfPairs);
      m_GeneralPairOffsets.push_back(static_cast<IndexType32>(m_GeneralPairs.size() / 2));
    }
  }

  // Outward orientation from the signed volume enclosed by the triangles.
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
DeformableMeshFilter<TMesh, TForceImage>::Reset()
{
  this->BuildTopology();
  const SizeValueType numberOfPoints = this->GetNumberOfCachedPoints();
  // As the cached coordinates: 3 per point and a guard value.
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
}

template <typename TMesh, typename TForceImage>
template <bool NeedNormal>
inline void
DeformableMeshFilter<TMesh, TForceImage>::ComputeGeometry(const double * x, SizeValueType i, Vec4 & u, Vec4 & n) const
{
  using namespace DeformableMeshFilterDetail;
  const uint8_t kind = m_RingKinds[i];
  if (kind == GeneralVertex)
  {
    // Through temporaries: u and n stay in registers on the other paths.
    Vec4 generalU;
    Vec4 generalN;
    this->ComputeGeneralGeometry(x, i, generalU, generalN);
    u = generalU;
    n = generalN;
    return;
  }
  const IndexType32   begin = m_NeighbourOffsets[i];
  const IndexType32   end = m_NeighbourOffsets[i + 1];
  const IndexType32 * ring = m_Neighbours.data();
  if (begin == end)
  {
    u = Vec4{};
    n = Vec4{};
    return;
  }
  // Relative to x_i, so that the cross products do not lose digits to the
  // distance from the origin. Lane 3 carries junk (the next coordinate in
  // memory) until cleared.
  const Vec4 xi = Load4(x + 3 * i);
  // Straight-line code for the usual valences.
  if (kind == ClosedRing && WithUsualValence(end - begin, [&](auto valence) {
        ClosedRingGeometry<decltype(valence)::value, NeedNormal>(x, ring + begin, xi, u, n);
      }))
  {
    return;
  }
  const Vec4 first = Load4(x + 3 * static_cast<SizeValueType>(ring[begin])) - xi;
  const Vec4 firstRotated = Rotate(first);
  Vec4       sum = first;
  Vec4       twisted{}; // sum of d_j * R(d_j+1) - R(d_j) * d_j+1; R(twisted) is sum of d_j x d_j+1
  Vec4       previous = first;
  Vec4       previousRotated = firstRotated;
#if defined(__GNUC__) && !defined(__clang__)
#  pragma GCC unroll 2
#endif
  for (IndexType32 k = begin + 1; k < end; ++k)
  {
    const Vec4 d = Load4(x + 3 * static_cast<SizeValueType>(ring[k])) - xi;
    sum += d;
    if (NeedNormal)
    {
      const Vec4 rotated = Rotate(d);
      twisted += previous * rotated - previousRotated * d;
      previous = d;
      previousRotated = rotated;
    }
  }
  u = ClearLane3(sum * Splat(InverseCount(end - begin)));
  if (NeedNormal)
  {
    if (kind == ClosedRing)
    {
      twisted += previous * firstRotated - previousRotated * first;
    }
    n = ClearLane3(Rotate(twisted));
  }
}

template <typename TMesh, typename TForceImage>
template <unsigned int K, bool NeedNormal>
EDM_ALWAYS_INLINE void
DeformableMeshFilter<TMesh, TForceImage>::ClosedRingGeometry(const double *      x,
                                                             const IndexType32 * ring,
                                                             const Vec4 &        xi,
                                                             Vec4 &              u,
                                                             Vec4 &              n)
{
  using namespace DeformableMeshFilterDetail;
  // As ComputeGeometry(), with the sums split in two (even and odd terms) to
  // shorten their dependency chains.
  Vec4 d[K];
  Vec4 r[K];
#if defined(__GNUC__) && !defined(__clang__)
#  pragma GCC unroll 8
#endif
  for (unsigned int k = 0; k < K; ++k)
  {
    d[k] = Load4(x + 3 * static_cast<SizeValueType>(ring[k])) - xi;
    r[k] = Rotate(d[k]);
  }
  Vec4 sum[2] = { d[0], d[1] };
#if defined(__GNUC__) && !defined(__clang__)
#  pragma GCC unroll 8
#endif
  for (unsigned int k = 2; k < K; ++k)
  {
    sum[k % 2] += d[k];
  }
  u = ClearLane3((sum[0] + sum[1]) * Splat(1.0 / static_cast<double>(K)));
  if (NeedNormal)
  {
    Vec4 twisted[2] = { d[0] * r[1] - r[0] * d[1], d[1] * r[2] - r[1] * d[2] };
#if defined(__GNUC__) && !defined(__clang__)
#  pragma GCC unroll 8
#endif
    for (unsigned int k = 2; k < K; ++k)
    {
      twisted[k % 2] += d[k] * r[(k + 1) % K] - r[k] * d[(k + 1) % K];
    }
    n = ClearLane3(Rotate(twisted[0] + twisted[1]));
  }
}

template <typename TMesh, typename TForceImage>
void
DeformableMeshFilter<TMesh, TForceImage>::ComputeGeneralGeometry(const double * x,
                                                                 SizeValueType  i,
                                                                 Vec4 &         u,
                                                                 Vec4 &         n) const
{
  using namespace DeformableMeshFilterDetail;
  const double * xi = x + 3 * i;
  double         s[3] = { 0.0, 0.0, 0.0 };
  const auto     begin = m_NeighbourOffsets[i];
  const auto     end = m_NeighbourOffsets[i + 1];
  for (IndexType32 k = begin; k < end; ++k)
  {
    const double * y = x + 3 * static_cast<SizeValueType>(m_Neighbours[k]);
    s[0] += y[0] - xi[0];
    s[1] += y[1] - xi[1];
    s[2] += y[2] - xi[2];
  }
  const double inverseCount = end > begin ? 1.0 / static_cast<double>(end - begin) : 0.0;
  u = Vec4{ s[0] * inverseCount, s[1] * inverseCount, s[2] * inverseCount, 0.0 };

  const auto rank = static_cast<SizeValueType>(
    std::lower_bound(m_GeneralVertices.begin(), m_GeneralVertices.end(), static_cast<IndexType32>(i)) -
    m_GeneralVertices.begin());
  double normal[3] = { 0.0, 0.0, 0.0 };
  for (IndexType32 k = m_GeneralPairOffsets[rank]; k < m_GeneralPairOffsets[rank + 1]; ++k)
  {
    const double * b = x + 3 * static_cast<SizeValueType>(m_GeneralPairs[2 * k]);
    const double * c = x + 3 * static_cast<SizeValueType>(m_GeneralPairs[2 * k + 1]);
    const double   e[3] = { b[0] - xi[0], b[1] - xi[1], b[2] - xi[2] };
    const double   f[3] = { c[0] - xi[0], c[1] - xi[1], c[2] - xi[2] };
    normal[0] += e[1] * f[2] - e[2] * f[1];
    normal[1] += e[2] * f[0] - e[0] * f[2];
    normal[2] += e[0] * f[1] - e[1] * f[0];
  }
  n = Vec4{ normal[0], normal[1], normal[2], 0.0 };
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
  // before the step: the geometry pass stores them, as for rigidity.
  const bool useImageTerms = this->UsesImageTerms();
  const bool useRigidity = m_Rigidity > 0.0 || useImageTerms;
  const bool useNormal = m_Balloon != 0.0 || (useElasticity && m_TangentialElasticity) || useImageTerms;

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

  constexpr SizeValueType blockSize = 512;
  static_assert(blockSize % ChunkSize == 0, "blocks are made of whole chunks");
  const bool          ordered = !m_ValenceOrder.empty();
  const SizeValueType numberOfBlocks = (numberOfPoints + blockSize - 1) / blockSize;
  MultiThreaderBase * threader = this->GetMultiThreader();
  threader->SetNumberOfWorkUnits(this->GetNumberOfWorkUnits());

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
    threader->ParallelizeArray(
      0,
      numberOfBlocks,
      [this, numberOfPoints, useNormal, ordered](SizeValueType block) {
        const SizeValueType begin = block * blockSize;
        const SizeValueType end = std::min(numberOfPoints, begin + blockSize);
        WithConstant(useNormal, [&](auto needNormal) {
          WithConstant(ordered, [&](auto inOrder) {
            this->GeometryBlock<decltype(needNormal)::value, decltype(inOrder)::value>(begin, end);
          });
        });
      },
      nullptr);
  }
  if (useImageTerms)
  {
    this->UpdateNormalSpeeds();
  }
  else
  {
    m_NormalSpeeds.clear();
  }

  std::vector<double> blockMaximum(numberOfBlocks, 0.0);
  threader->ParallelizeArray(
    0,
    numberOfBlocks,
    [this, numberOfPoints, useRigidity, useNormal, ordered, diagnose, &blockMaximum](SizeValueType block) {
      const SizeValueType begin = block * blockSize;
      const SizeValueType end = std::min(numberOfPoints, begin + blockSize);
      WithConstant(useRigidity, [&](auto rigidity) {
        WithConstant(useNormal, [&](auto normal) {
          WithConstant(ordered, [&](auto inOrder) {
            blockMaximum[block] =
              this->StepBlock<decltype(rigidity)::value, decltype(normal)::value, decltype(inOrder)::value>(
                begin, end, diagnose);
          });
        });
      });
    },
    nullptr);

  coordinates.swap(m_NextCoordinates);

  m_LastMaximumDisplacement = *std::max_element(blockMaximum.begin(), blockMaximum.end());
  if (m_ConvergenceTolerance > 0.0 && m_LastMaximumDisplacement < m_ConvergenceTolerance)
  {
    m_Converged = ++m_QuietIterations >= m_ConvergenceWindow;
  }
  else
  {
    m_QuietIterations = 0;
  }
}

template <typename TMesh, typename TForceImage>
template <bool NeedNormal, bool Ordered>
void
DeformableMeshFilter<TMesh, TForceImage>::GeometryBlock(SizeValueType begin, SizeValueType end)
{
  using namespace DeformableMeshFilterDetail;
  const double * x = this->GetCoordinates().data();
  float *        umbrellaField = m_Umbrella.data();
  float *        normalField = m_Normals.data();
  const double   orientationSign = m_OrientationSign;
  // The normals of a chunk of vertices are scaled to unit length after the
  // chunk: the square roots and divisions then overlap across vertices
  // instead of ending each vertex's chain of dependent operations.
  constexpr SizeValueType chunk = ChunkSize;
  Vec4                    normals[chunk];
  const uint8_t *         order = m_ValenceOrder.data();
  for (SizeValueType chunkBegin = begin; chunkBegin < end; chunkBegin += chunk)
  {
    const SizeValueType chunkEnd = std::min(end, chunkBegin + chunk);
    for (SizeValueType k = chunkBegin; k < chunkEnd; ++k)
    {
      const SizeValueType i = Ordered ? chunkBegin + order[k] : k;
      Vec4                u;
      Vec4                n;
      this->template ComputeGeometry<NeedNormal>(x, i, u, n);
      StoreFloat4(umbrellaField + 4 * i, u);
      if (NeedNormal)
      {
        normals[i - chunkBegin] = n;
      }
    }
    if (NeedNormal)
    {
      for (SizeValueType i = chunkBegin; i < chunkEnd; ++i)
      {
        const double squaredLength = Dot3(normals[i - chunkBegin], normals[i - chunkBegin]);
        StoreFloat4(normalField + 4 * i,
                    squaredLength > 0.0 ? normals[i - chunkBegin] * Splat(orientationSign / std::sqrt(squaredLength))
                                        : Vec4{});
      }
    }
  }
}

template <typename TMesh, typename TForceImage>
template <bool UseRigidity, bool UseNormal, bool Ordered>
double
DeformableMeshFilter<TMesh, TForceImage>::StepBlock(SizeValueType begin, SizeValueType end, bool diagnose)
{
  using namespace DeformableMeshFilterDetail;
  // Everything the loop reads, in locals: the compiler cannot keep members in
  // registers across the stores to the output arrays. Stability of the
  // explicit internal update requires a + 2b <= 1: larger sums are scaled.
  const double        internalSum = m_Elasticity + 2.0 * m_Rigidity;
  const double        internalScale = internalSum > 1.0 ? 1.0 / internalSum : 1.0;
  const double        elasticity = m_Elasticity * internalScale;
  const double        rigidity = m_Rigidity * internalScale;
  const bool          useElasticity = elasticity > 0.0;
  const bool          tangential = useElasticity && m_TangentialElasticity;
  const double        scaleFactor = m_ScaleFactor;
  const double        balloon = m_Balloon;
  const double        maximumStep = m_MaximumStepLength;
  const double        orientationSign = m_OrientationSign;
  const uint8_t *     order = m_ValenceOrder.data();
  const ForceSampler  sampler = m_Sampler;
  const double *      x = this->GetCoordinates().data();
  double *            next = m_NextCoordinates.data();
  const float *       umbrellaField = m_Umbrella.data();
  const float *       normalField = m_Normals.data();
  const IndexType32 * offsets = m_NeighbourOffsets.data();
  const IndexType32 * neighbours = m_Neighbours.data();
  uint8_t *           balloonReleased = m_BalloonReleased.data();
  const float *       normalSpeeds = m_NormalSpeeds.empty() ? nullptr : m_NormalSpeeds.data();
  float *             displacementMagnitudes = m_DisplacementMagnitudes.data();
  float *             externalMagnitudes = m_ExternalForceMagnitudes.data();
  float *             internalMagnitudes = m_InternalForceMagnitudes.data();

  // The external forces of a run of vertices first, then the rest: two short
  // loop bodies whose long dependency chains (index, voxel loads,
  // interpolation; neighbour loads, normal) overlap across vertices.
  constexpr SizeValueType run = ChunkSize;
  Vec4                    externalForces[run];
  double                  squaredSteps[run];
  double                  largest = 0.0; // squared
  for (SizeValueType runBegin = begin; runBegin < end; runBegin += run)
  {
    const SizeValueType runEnd = std::min(end, runBegin + run);
    SampleForces(sampler, x, runBegin, runEnd, scaleFactor, externalForces);
    for (SizeValueType k = runBegin; k < runEnd; ++k)
    {
      const SizeValueType i = Ordered ? runBegin + order[k] : k;
      const Vec4          xi = Load4(x + 3 * i);
      Vec4                u{};
      Vec4                n{};
      Vec4                internal{};
      if (UseRigidity)
      {
        u = LoadFloat4(umbrellaField + 4 * i);
        if (UseNormal)
        {
          n = LoadFloat4(normalField + 4 * i);
        }
        const IndexType32 first = offsets[i];
        const IndexType32 stop = offsets[i + 1];
        if (stop > first)
        {
          Vec4 sum{};
          if (!WithUsualValence(stop - first, [&](auto valence) {
                sum = GatherSum<decltype(valence)::value>(umbrellaField, neighbours + first);
              }))
          {
            for (IndexType32 k = first; k < stop; ++k)
            {
              sum += LoadFloat4(umbrellaField + 4 * static_cast<SizeValueType>(neighbours[k]));
            }
          }
          internal = Splat(rigidity) * (u - sum * Splat(InverseCount(stop - first)));
        }
      }
      else if (UseNormal)
      {
        this->template ComputeGeometry<true>(x, i, u, n);
        n = UnitVector(n, orientationSign);
      }
      else if (useElasticity)
      {
        this->template ComputeGeometry<false>(x, i, u, n);
      }
      if (useElasticity)
      {
        const Vec4 e = tangential ? u - Dot4Splat(u, n) * n : u;
        internal += Splat(elasticity) * e;
      }

      const Vec4 external = externalForces[i - runBegin];
      // The balloon carries a vertex to an edge, not past it: once the external
      // force opposes it with half its strength, the vertex is in the edge's
      // capture range and the balloon is released for it, so that it settles on
      // the edge itself instead of where the forces balance.
      double inflation = 0.0;
      if (UseNormal && balloon != 0.0 && !balloonReleased[i])
      {
        if (balloon * Dot3(external, n) <= -0.5 * balloon * balloon)
        {
          balloonReleased[i] = 1;
        }
        else
        {
          inflation = balloon;
        }
      }
      if (UseNormal && normalSpeeds != nullptr)
      {
        inflation += normalSpeeds[i];
      }
      Vec4 delta = external + internal;
      if (UseNormal)
      {
        delta += Splat(inflation) * n;
      }
      if (maximumStep > 0.0)
      {
        const double length = std::sqrt(Dot3(delta, delta));
        if (length > maximumStep)
        {
          delta *= Splat(maximumStep / length);
        }
      }
      // A 4-wide store spills into the next point's first coordinate, which the
      // next iteration of this loop overwrites; not at the block's end, nor
      // when the vertices are not processed in order.
      if (!Ordered && i + 1 < end)
      {
        Store4(next + 3 * i, xi + delta);
      }
      else
      {
        Store3(next + 3 * i, xi + delta);
      }

      // Diagnostics, in single precision as they are stored: the three lengths
      // with one square root. The largest displacement is kept squared.
      if (diagnose)
      {
        const Vec4 squares = SquaredLengths(delta, external, internal);
        SqrtStore3(squares, displacementMagnitudes + i, externalMagnitudes + i, internalMagnitudes + i);
        squaredSteps[i - runBegin] = squares[0];
      }
      else
      {
        squaredSteps[i - runBegin] = Dot3(delta, delta);
      }
    }
    // Apart from the loop above: a running maximum there is a dependency
    // chain through memory when the registers run short.
    for (SizeValueType k = 0; k < runEnd - runBegin; ++k)
    {
      largest = std::max(largest, squaredSteps[k]);
    }
  }
  return std::sqrt(largest);
}

template <typename TMesh, typename TForceImage>
void
DeformableMeshFilter<TMesh, TForceImage>::PrintSelf(std::ostream & os, Indent indent) const
{
  Superclass::PrintSelf(os, indent);
  os << indent << "ScaleFactor: " << m_ScaleFactor << std::endl;
  os << indent << "Elasticity: " << m_Elasticity << std::endl;
  os << indent << "TangentialElasticity: " << (m_TangentialElasticity ? "On" : "Off") << std::endl;
  os << indent << "Rigidity: " << m_Rigidity << std::endl;
  os << indent << "Balloon: " << m_Balloon << std::endl;
  os << indent << "MaximumStepLength: " << m_MaximumStepLength << std::endl;
  os << indent << "ConvergenceTolerance: " << m_ConvergenceTolerance << std::endl;
  os << indent << "ConvergenceWindow: " << m_ConvergenceWindow << std::endl;
  os << indent << "Converged: " << (m_Converged ? "true" : "false") << std::endl;
  os << indent << "QuietIterations: " << m_QuietIterations << std::endl;
  os << indent << "LastMaximumDisplacement: " << m_LastMaximumDisplacement << std::endl;
  os << indent << "OrientationSign: " << m_OrientationSign << std::endl;
  os << indent << "Neighbours: " << m_Neighbours.size() << " entries, Triangles: " << m_NumberOfTriangles
     << ", vertices outside a single fan: " << m_GeneralVertices.size() << std::endl;
  os << indent << "OrderedByValence: " << (m_ValenceOrder.empty() ? "Off" : "On") << std::endl;
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

#endif
