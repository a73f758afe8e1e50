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
}

template <typename TMesh, typename TForceImage>
inline bool
DeformableMeshFilter<TMesh, TForceImage>::SampleForce(const double * x, double * force) const
{
  const double d[3] = { x[0] - m_ForceOrigin[0], x[1] - m_ForceOrigin[1], x[2] - m_ForceOrigin[2] };
  int64_t      i0[3];
  int64_t      i1[3];
  double       w[3];
  for (unsigned int k = 0; k < 3; ++k)
  {
    const double c = m_PhysicalToIndex[k][0] * d[0] + m_PhysicalToIndex[k][1] * d[1] + m_PhysicalToIndex[k][2] * d[2] -
                     m_BufferStart[k];
    // Same inside test as itk::LinearInterpolateImageFunction: half a voxel
    // beyond the first and last voxel centres, values clamped at the border.
    if (!(c >= -0.5 && c < static_cast<double>(m_BufferSize[k]) - 0.5))
    {
      force[0] = force[1] = force[2] = 0.0;
      return false;
    }
    const double floorC = std::floor(c);
    w[k] = c - floorC;
    const auto base = static_cast<int64_t>(floorC);
    i0[k] = std::max<int64_t>(base, 0);
    i1[k] = std::min<int64_t>(base + 1, m_BufferSize[k] - 1);
  }
  const int64_t strideY = m_BufferSize[0];
  const int64_t strideZ = m_BufferSize[0] * m_BufferSize[1];
  const int64_t z0 = i0[2] * strideZ;
  const int64_t z1 = i1[2] * strideZ;
  const int64_t y0 = i0[1] * strideY;
  const int64_t y1 = i1[1] * strideY;

  const ForcePixelType & p000 = m_ForceBuffer[z0 + y0 + i0[0]];
  const ForcePixelType & p100 = m_ForceBuffer[z0 + y0 + i1[0]];
  const ForcePixelType & p010 = m_ForceBuffer[z0 + y1 + i0[0]];
  const ForcePixelType & p110 = m_ForceBuffer[z0 + y1 + i1[0]];
  const ForcePixelType & p001 = m_ForceBuffer[z1 + y0 + i0[0]];
  const ForcePixelType & p101 = m_ForceBuffer[z1 + y0 + i1[0]];
  const ForcePixelType & p011 = m_ForceBuffer[z1 + y1 + i0[0]];
  const ForcePixelType & p111 = m_ForceBuffer[z1 + y1 + i1[0]];
  const double           wx = w[0];
  const double           wy = w[1];
  const double           wz = w[2];
  for (unsigned int k = 0; k < 3; ++k)
  {
    const double a00 = p000[k] + wx * (p100[k] - p000[k]);
    const double a10 = p010[k] + wx * (p110[k] - p010[k]);
    const double a01 = p001[k] + wx * (p101[k] - p001[k]);
    const double a11 = p011[k] + wx * (p111[k] - p011[k]);
    const double b0 = a00 + wy * (a10 - a00);
    const double b1 = a01 + wy * (a11 - a01);
    force[k] = b0 + wz * (b1 - b0);
  }
  return true;
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

  // CSR table of the edges opposite each vertex in its triangles, oriented as
  // the triangles: the normal of vertex i sums (b - x_i) x (c - x_i) over its
  // pairs (b, c), with no triangle indirection in the step.
  const SizeValueType numberOfTriangles = triangles.size() / 3;
  m_VertexTriangleOffsets.assign(numberOfPoints + 1, 0);
  for (const IndexType32 v : triangles)
  {
    ++m_VertexTriangleOffsets[v + 1];
  }
  for (SizeValueType i = 0; i < numberOfPoints; ++i)
  {
    m_VertexTriangleOffsets[i + 1] += m_VertexTriangleOffsets[i];
  }
  m_VertexTriangles.resize(2 * static_cast<SizeValueType>(m_VertexTriangleOffsets[numberOfPoints]));
  {
    std::vector<IndexType32> fill(m_VertexTriangleOffsets.begin(), m_VertexTriangleOffsets.end() - 1);
    for (SizeValueType t = 0; t < numberOfTriangles; ++t)
    {
      for (unsigned int k = 0; k < 3; ++k)
      {
        IndexType32 * pair = m_VertexTriangles.data() + 2 * static_cast<SizeValueType>(fill[triangles[3 * t + k]]++);
        pair[0] = triangles[3 * t + (k + 1) % 3];
        pair[1] = triangles[3 * t + (k + 2) % 3];
      }
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
}

template <typename TMesh, typename TForceImage>
void
DeformableMeshFilter<TMesh, TForceImage>::Reset()
{
  this->BuildTopology();
  const SizeValueType numberOfPoints = this->GetNumberOfCachedPoints();
  m_NextCoordinates.resize(3 * numberOfPoints);
  std::vector<double>().swap(m_Umbrella);
  m_BalloonReleased.clear();
  m_DisplacementMagnitudes.clear();
  m_ExternalForceMagnitudes.clear();
  m_InternalForceMagnitudes.clear();
  m_Converged = false;
  m_QuietIterations = 0;
  m_LastMaximumDisplacement = 0.0;
}

template <typename TMesh, typename TForceImage>
inline void
DeformableMeshFilter<TMesh, TForceImage>::ComputeNormal(const double * x, SizeValueType i, double * normal) const
{
  double n[3] = { 0.0, 0.0, 0.0 };
  for (IndexType32 k = m_VertexTriangleOffsets[i]; k < m_VertexTriangleOffsets[i + 1]; ++k)
  {
    const double * a = x + 3 * i;
    const double * b = x + 3 * m_VertexTriangles[2 * k];
    const double * c = x + 3 * m_VertexTriangles[2 * k + 1];
    const double   u[3] = { b[0] - a[0], b[1] - a[1], b[2] - a[2] };
    const double   v[3] = { c[0] - a[0], c[1] - a[1], c[2] - a[2] };
    n[0] += u[1] * v[2] - u[2] * v[1];
    n[1] += u[2] * v[0] - u[0] * v[2];
    n[2] += u[0] * v[1] - u[1] * v[0];
  }
  const double length = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
  const double scale = length > 0.0 ? m_OrientationSign / length : 0.0;
  normal[0] = n[0] * scale;
  normal[1] = n[1] * scale;
  normal[2] = n[2] * scale;
}

template <typename TMesh, typename TForceImage>
void
DeformableMeshFilter<TMesh, TForceImage>::Iterate()
{
  std::vector<double> & coordinates = this->GetCoordinates();
  const SizeValueType   numberOfPoints = this->GetNumberOfCachedPoints();
  const double *        x = coordinates.data();
  double *              next = m_NextCoordinates.data();

  // Stability of the explicit internal update requires a + 2b <= 1.
  const double        internalSum = m_Elasticity + 2.0 * m_Rigidity;
  const double        internalScale = internalSum > 1.0 ? 1.0 / internalSum : 1.0;
  const double        elasticity = m_Elasticity * internalScale;
  const double        rigidity = m_Rigidity * internalScale;
  const bool          useElasticity = elasticity > 0.0;
  const bool          useRigidity = rigidity > 0.0;
  const bool          useNormal = m_Balloon != 0.0 || (useElasticity && m_TangentialElasticity);
  const double        scaleFactor = m_ScaleFactor;
  const double        balloon = m_Balloon;
  const double        maximumStep = m_MaximumStepLength;
  const IndexType32 * offsets = m_NeighbourOffsets.data();
  const IndexType32 * neighbours = m_Neighbours.data();

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
  uint8_t * balloonReleased = m_BalloonReleased.data();
  float *   displacementMagnitudes = m_DisplacementMagnitudes.data();
  float *   externalMagnitudes = m_ExternalForceMagnitudes.data();
  float *   internalMagnitudes = m_InternalForceMagnitudes.data();

  // Umbrella vector: centroid of the neighbours minus the vertex.
  auto umbrella = [x, offsets, neighbours](SizeValueType i, double * u) {
    const IndexType32 begin = offsets[i];
    const IndexType32 end = offsets[i + 1];
    if (begin == end)
    {
      u[0] = u[1] = u[2] = 0.0;
      return;
    }
    double s[3] = { 0.0, 0.0, 0.0 };
    for (IndexType32 k = begin; k < end; ++k)
    {
      const double * y = x + 3 * neighbours[k];
      s[0] += y[0];
      s[1] += y[1];
      s[2] += y[2];
    }
    const double   inverseCount = 1.0 / static_cast<double>(end - begin);
    const double * xi = x + 3 * i;
    u[0] = s[0] * inverseCount - xi[0];
    u[1] = s[1] * inverseCount - xi[1];
    u[2] = s[2] * inverseCount - xi[2];
  };

  constexpr SizeValueType blockSize = 2048;
  const SizeValueType     numberOfBlocks = (numberOfPoints + blockSize - 1) / blockSize;
  MultiThreaderBase *     threader = this->GetMultiThreader();
  threader->SetNumberOfWorkUnits(this->GetNumberOfWorkUnits());

  if (useRigidity && m_Umbrella.size() != 3 * numberOfPoints)
  {
    m_Umbrella.resize(3 * numberOfPoints);
  }
  double * umbrellaField = m_Umbrella.data();
  if (useRigidity)
  {
    threader->ParallelizeArray(
      0,
      numberOfBlocks,
      [&](SizeValueType block) {
        const SizeValueType end = std::min(numberOfPoints, (block + 1) * blockSize);
        for (SizeValueType i = block * blockSize; i < end; ++i)
        {
          umbrella(i, umbrellaField + 3 * i);
        }
      },
      nullptr);
  }

  std::vector<double> blockMaximum(numberOfBlocks, 0.0);
  threader->ParallelizeArray(
    0,
    numberOfBlocks,
    [&](SizeValueType block) {
      double              largest = 0.0;
      const SizeValueType end = std::min(numberOfPoints, (block + 1) * blockSize);
      for (SizeValueType i = block * blockSize; i < end; ++i)
      {
        const double * xi = x + 3 * i;
        double         external[3];
        this->SampleForce(xi, external);
        double delta[3] = { scaleFactor * external[0], scaleFactor * external[1], scaleFactor * external[2] };
        double internal[3] = { 0.0, 0.0, 0.0 };

        double normal[3] = { 0.0, 0.0, 0.0 };
        if (useNormal)
        {
          this->ComputeNormal(x, i, normal);
        }
        if (useElasticity || useRigidity)
        {
          double u[3];
          if (useRigidity)
          {
            u[0] = umbrellaField[3 * i];
            u[1] = umbrellaField[3 * i + 1];
            u[2] = umbrellaField[3 * i + 2];
          }
          else
          {
            umbrella(i, u);
          }
          if (useElasticity)
          {
            double e[3] = { u[0], u[1], u[2] };
            if (m_TangentialElasticity)
            {
              const double normalPart = e[0] * normal[0] + e[1] * normal[1] + e[2] * normal[2];
              e[0] -= normalPart * normal[0];
              e[1] -= normalPart * normal[1];
              e[2] -= normalPart * normal[2];
            }
            internal[0] += elasticity * e[0];
            internal[1] += elasticity * e[1];
            internal[2] += elasticity * e[2];
          }
          if (useRigidity && offsets[i + 1] > offsets[i])
          {
            double mean[3] = { 0.0, 0.0, 0.0 };
            for (IndexType32 k = offsets[i]; k < offsets[i + 1]; ++k)
            {
              const double * uj = umbrellaField + 3 * neighbours[k];
              mean[0] += uj[0];
              mean[1] += uj[1];
              mean[2] += uj[2];
            }
            const double inverseCount = 1.0 / static_cast<double>(offsets[i + 1] - offsets[i]);
            internal[0] -= rigidity * (mean[0] * inverseCount - u[0]);
            internal[1] -= rigidity * (mean[1] * inverseCount - u[1]);
            internal[2] -= rigidity * (mean[2] * inverseCount - u[2]);
          }
        }
        // The balloon carries a vertex to an edge, not past it: once the
        // external force opposes it with half its strength, the vertex is in
        // the edge's capture range and the balloon is released for it, so that
        // it settles on the edge itself instead of where the forces balance.
        double inflation = 0.0;
        if (balloon != 0.0 && !balloonReleased[i])
        {
          const double externalAlongNormal = delta[0] * normal[0] + delta[1] * normal[1] + delta[2] * normal[2];
          if (balloon * externalAlongNormal <= -0.5 * balloon * balloon)
          {
            balloonReleased[i] = 1;
          }
          else
          {
            inflation = balloon;
          }
        }
        delta[0] += internal[0] + inflation * normal[0];
        delta[1] += internal[1] + inflation * normal[1];
        delta[2] += internal[2] + inflation * normal[2];

        double length = std::sqrt(delta[0] * delta[0] + delta[1] * delta[1] + delta[2] * delta[2]);
        if (maximumStep > 0.0 && length > maximumStep)
        {
          const double shrink = maximumStep / length;
          delta[0] *= shrink;
          delta[1] *= shrink;
          delta[2] *= shrink;
          length = maximumStep;
        }
        double * xn = next + 3 * i;
        xn[0] = xi[0] + delta[0];
        xn[1] = xi[1] + delta[1];
        xn[2] = xi[2] + delta[2];

        displacementMagnitudes[i] = static_cast<float>(length);
        externalMagnitudes[i] =
          static_cast<float>(std::abs(scaleFactor) * std::sqrt(external[0] * external[0] + external[1] * external[1] +
                                                               external[2] * external[2]));
        internalMagnitudes[i] = static_cast<float>(
          std::sqrt(internal[0] * internal[0] + internal[1] * internal[1] + internal[2] * internal[2]));
        largest = std::max(largest, length);
      }
      blockMaximum[block] = largest;
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
  os << indent << "Neighbours: " << m_Neighbours.size() << " entries, Triangles: " << m_NumberOfTriangles << std::endl;
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
