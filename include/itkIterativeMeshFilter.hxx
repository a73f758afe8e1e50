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
#ifndef itkIterativeMeshFilter_hxx
#define itkIterativeMeshFilter_hxx

#include "itkIterativeMeshFilter.h"
#include "itkTriangleCell.h"
#include "itkMultiThreaderBase.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <new>

namespace itk
{

template <typename TInputMesh, typename TOutputMesh>
IterativeMeshFilter<TInputMesh, TOutputMesh>::IterativeMeshFilter() = default;

template <typename TInputMesh, typename TOutputMesh>
IterativeMeshFilter<TInputMesh, TOutputMesh>::~IterativeMeshFilter()
{
  this->ReleaseOutputCells();
}

template <typename TInputMesh, typename TOutputMesh>
void
IterativeMeshFilter<TInputMesh, TOutputMesh>::ReleaseOutputCells()
{
  // The cells are allocated one by one; an output mesh that still shares the
  // container deletes them when it releases it last.
  if (m_OutputCells && m_OutputCells->GetReferenceCount() == 1)
  {
    for (auto it = m_OutputCells->Begin(); it != m_OutputCells->End(); ++it)
    {
      delete it.Value();
    }
  }
  m_OutputCells = nullptr;
}

template <typename TInputMesh, typename TOutputMesh>
void
IterativeMeshFilter<TInputMesh, TOutputMesh>::VerifyPreconditions() const
{
  if (this->GetInput() == nullptr)
  {
    itkExceptionMacro("No input mesh: call SetInput() before Update().");
  }
  Superclass::VerifyPreconditions();
}

template <typename TInputMesh, typename TOutputMesh>
void
IterativeMeshFilter<TInputMesh, TOutputMesh>::CacheInput()
{
  const InputMeshType * input = this->GetInput();
  const auto *          points = input->GetPoints();
  const SizeValueType   numberOfPoints = points->Size();

  m_NumberOfCachedPoints = 0;
  m_Coordinates.assign(numberOfPoints * m_CoordinateStride, 0.0);
  SizeValueType expectedId = 0;
  for (auto it = points->Begin(); it != points->End(); ++it, ++expectedId)
  {
    if (it.Index() != expectedId)
    {
      itkExceptionMacro("The input mesh's point identifiers must run from 0 to N-1; point #"
                        << expectedId << " has identifier " << it.Index() << ".");
    }
    const auto & p = it.Value();
    for (unsigned int d = 0; d < PointDimension; ++d)
    {
      const double value = static_cast<double>(p[d]);
      if (!std::isfinite(value))
      {
        itkExceptionMacro("The input mesh has a non-finite coordinate (NaN or infinity) at point #" << expectedId
                                                                                                    << ".");
      }
      m_Coordinates[expectedId * m_CoordinateStride + d] = value;
    }
  }
  m_NumberOfCachedPoints = numberOfPoints;
  m_NumberOfInputPoints = numberOfPoints;
  m_CachedInputTime = std::max(input->GetMTime(), input->GetUpdateMTime());
}

template <typename TInputMesh, typename TOutputMesh>
void
IterativeMeshFilter<TInputMesh, TOutputMesh>::GenerateData()
{
  try
  {
    this->RunIterations();
  }
  catch (const std::bad_alloc &)
  {
    m_Cached = false;
    const SizeValueType numberOfPoints = this->GetInput()->GetNumberOfPoints();
    itkExceptionMacro("Out of memory while deforming a mesh of "
                      << numberOfPoints << " points (the filter holds a few hundred bytes per point, about "
                      << 300.0 * numberOfPoints / 1e6 << " MB, besides the input and output meshes).");
  }
}

template <typename TInputMesh, typename TOutputMesh>
void
IterativeMeshFilter<TInputMesh, TOutputMesh>::ThrowNonFiniteCoordinate(SizeValueType firstIteration)
{
  // The next update starts again from the input.
  m_Cached = false;
  const SizeValueType n = this->GetNumberOfCachedPoints() * m_CoordinateStride;
  SizeValueType       i = 0;
  while (i < n && std::isfinite(m_Coordinates[i]))
  {
    ++i;
  }
  const double        value = i < n ? m_Coordinates[i] : std::numeric_limits<double>::quiet_NaN();
  const SizeValueType point = i / m_CoordinateStride;
  const SizeValueType pointId =
    point < m_OutputPointIdentifiers.size() ? static_cast<SizeValueType>(m_OutputPointIdentifiers[point]) : point;
  itkExceptionMacro("Point #" << pointId << " has a non-finite coordinate (" << value << ") after iteration "
                              << m_CurrentIteration << " (this update ran iterations " << firstIteration + 1 << " to "
                              << m_CurrentIteration
                              << "): the step diverged. Likely causes: a force image holding NaN or infinite "
                                 "values, or steps so large (scale factor, balloon) that the coordinates overflowed.");
}

template <typename TInputMesh, typename TOutputMesh>
void
IterativeMeshFilter<TInputMesh, TOutputMesh>::RunIterations()
{
  const InputMeshType * input = this->GetInput();
  if (input == nullptr)
  {
    itkExceptionMacro("No input mesh: call SetInput() before Update().");
  }
  if (input->GetPoints() == nullptr || input->GetNumberOfPoints() == 0)
  {
    itkExceptionMacro("The input mesh is empty: it has no points.");
  }

  const ModifiedTimeType inputTime = std::max(input->GetMTime(), input->GetUpdateMTime());
  const bool             restart = !m_Cached || m_IterateFromZero || m_NumberOfIterations == 0 ||
                       m_NumberOfIterations < m_CurrentIteration || inputTime > m_CachedInputTime ||
                       input->GetNumberOfPoints() != m_NumberOfInputPoints;
  if (restart)
  {
    m_Cached = false;
    this->ReleaseOutputCells();
    m_TopologyChanged = false;
    m_OutputCellsStale = false;
    std::vector<uint32_t>().swap(m_CachedTriangles);
    m_OutputPointIdentifiers.clear();
    this->CacheInput();
    m_CurrentIteration = 0;
    this->Reset();
    m_Cached = true;
  }

  // Structure first, so that an observer of IterationEvent sees a whole mesh.
  // The cells are cloned once per restart; later updates share the clone.
  if (m_TopologyChanged)
  {
    this->InstallChangedStructure();
  }
  else
  {
    if (m_OutputCells.IsNull())
    {
      this->CopyInputMeshToOutputMeshCells();
      m_OutputCells = this->GetOutput()->GetCells();
    }
    else
    {
      this->GetOutput()->SetCellsAllocationMethod(
        MeshEnums::MeshClassCellsAllocationMethod::CellsAllocatedDynamicallyCellByCell);
      this->GetOutput()->SetCells(m_OutputCells);
    }
    this->CopyInputMeshToOutputMeshCellData();
    this->CopyInputMeshToOutputMeshPointData();
  }
  this->UpdateOutputPoints();

  const SizeValueType firstIteration = m_CurrentIteration;
  const double        iterationsToRun = static_cast<double>(m_NumberOfIterations) - firstIteration;
  while (m_CurrentIteration < m_NumberOfIterations && !this->HasConverged())
  {
    this->Iterate();
    ++m_CurrentIteration;
    if (this->HasObserver(IterationEvent()))
    {
      if (m_OutputCellsStale)
      {
        this->InstallChangedStructure();
      }
      // Observers never see a non-finite mesh.
      this->UpdateOutputPoints();
      if (!m_OutputPointsFinite)
      {
        this->ThrowNonFiniteCoordinate(firstIteration);
      }
      this->InvokeEvent(IterationEvent());
    }
    this->UpdateProgress(static_cast<float>((m_CurrentIteration - firstIteration) / iterationsToRun));
    if (this->GetAbortGenerateData())
    {
      break;
    }
  }
  if (m_OutputCellsStale)
  {
    this->InstallChangedStructure();
  }
  this->UpdateOutputPoints();
  if (!m_OutputPointsFinite)
  {
    this->ThrowNonFiniteCoordinate(firstIteration);
  }
}

template <typename TInputMesh, typename TOutputMesh>
void
IterativeMeshFilter<TInputMesh, TOutputMesh>::UpdateOutputPoints()
{
  const SizeValueType numberOfPoints = this->GetNumberOfCachedPoints();
  OutputMeshType *    output = this->GetOutput();
  // Rewrite the container of the previous update in place unless someone else
  // (an observer, a downstream filter) still holds it.
  const bool reusable = m_OutputPoints && m_OutputPoints->Size() == numberOfPoints &&
                        (m_OutputPoints->GetReferenceCount() == 1 ||
                         (m_OutputPoints->GetReferenceCount() == 2 && output->GetPoints() == m_OutputPoints));
  if (!reusable)
  {
    m_OutputPoints = OutputPointsContainer::New();
    m_OutputPoints->Reserve(numberOfPoints);
  }
  OutputPointsContainer * points = m_OutputPoints;
  // Through the STL container: ElementAt() calls Modified() for every point,
  // which costs as much as a step of DeformableMeshFilter on large meshes.
  // The finite check rides on the copy: x * 0 is 0 for a finite x and NaN for
  // an infinite or NaN one.
  auto &           elements = points->CastToSTLContainer();
  const double *   x = m_Coordinates.data();
  double           check = 0.0;
  const uint32_t * ids = m_OutputPointIdentifiers.size() == numberOfPoints ? m_OutputPointIdentifiers.data() : nullptr;
  const unsigned int stride = m_CoordinateStride;
  for (SizeValueType i = 0; i < numberOfPoints; ++i, x += stride)
  {
    OutputPointType & p = elements[ids ? ids[i] : i];
    for (unsigned int d = 0; d < PointDimension; ++d)
    {
      p[d] = static_cast<typename OutputPointType::ValueType>(x[d]);
      check += x[d] * 0.0;
    }
  }
  m_OutputPointsFinite = check == 0.0;
  points->Modified();
  output->SetPoints(points);
}

template <typename TInputMesh, typename TOutputMesh>
void
IterativeMeshFilter<TInputMesh, TOutputMesh>::SetCachedTriangles(SizeValueType                 numberOfPoints,
                                                                 const std::vector<uint32_t> & triangles)
{
  m_NumberOfCachedPoints = numberOfPoints;
  m_CachedTriangles = triangles;
  m_TopologyChanged = true;
  m_OutputCellsStale = true;
  m_OutputPointIdentifiers.clear();
}

template <typename TInputMesh, typename TOutputMesh>
void
IterativeMeshFilter<TInputMesh, TOutputMesh>::InstallChangedStructure()
{
  OutputMeshType * output = this->GetOutput();
  if (m_OutputCellsStale || m_OutputCells.IsNull())
  {
    using CellType = typename OutputMeshType::CellType;
    using TriangleType = TriangleCell<CellType>;
    const SizeValueType numberOfTriangles = m_CachedTriangles.size() / 3;
    // The triangle cells of the previous structure are taken over, with new
    // point identifiers, unless someone other than the filter and its output
    // (a downstream filter, an observer) still holds their container: a
    // change of the structure (remeshing) then allocates no cell but for the
    // triangles added.
    std::vector<CellType *> taken;
    if (m_OutputCells &&
        (m_OutputCells->GetReferenceCount() == 1 ||
         (m_OutputCells->GetReferenceCount() == 2 && output->GetCells() == m_OutputCells.GetPointer())))
    {
      taken.reserve(m_OutputCells->Size());
      for (auto it = m_OutputCells->Begin(); it != m_OutputCells->End(); ++it)
      {
        taken.push_back(it.Value());
      }
      m_OutputCells->CastToSTLContainer().clear();
    }
    this->ReleaseOutputCells();
    for (SizeValueType t = numberOfTriangles; t < taken.size(); ++t)
    {
      delete taken[t];
    }
    const SizeValueType numberTaken = std::min<SizeValueType>(taken.size(), numberOfTriangles);
    taken.resize(numberOfTriangles, nullptr);
    for (SizeValueType t = numberTaken; t < numberOfTriangles; ++t)
    {
      taken[t] = new TriangleType;
    }
    // The point identifiers in parallel: the cells are allocated one by one,
    // and a serial pass over them costs 3 % of a combined benchmark update
    // at a million points (a cache miss per cell). A cell taken over that is
    // not a triangle (put in the output by someone else) is replaced after.
    constexpr SizeValueType block = 16384;
    const SizeValueType     numberOfBlocks = (numberOfTriangles + block - 1) / block;
    std::vector<uint8_t>    foreign(numberOfBlocks, 0);
    const auto              setBlock = [&](SizeValueType b) {
      for (SizeValueType t = b * block; t < std::min(numberOfTriangles, (b + 1) * block); ++t)
      {
        CellType * cell = taken[t];
        if (cell == nullptr || cell->GetType() != CommonEnums::CellGeometry::TRIANGLE_CELL)
        {
          foreign[b] = 1;
          continue;
        }
        for (unsigned int k = 0; k < 3; ++k)
        {
          cell->SetPointId(k, m_CachedTriangles[3 * t + k]);
        }
      }
    };
    if (numberOfBlocks > 1)
    {
      MultiThreaderBase * threader = this->GetMultiThreader();
      threader->SetNumberOfWorkUnits(this->GetNumberOfWorkUnits());
      threader->ParallelizeArray(0, numberOfBlocks, setBlock, nullptr);
    }
    else if (numberOfBlocks == 1)
    {
      setBlock(0);
    }
    for (SizeValueType b = 0; b < numberOfBlocks; ++b)
    {
      for (SizeValueType t = b * block; foreign[b] != 0 && t < std::min(numberOfTriangles, (b + 1) * block); ++t)
      {
        if (taken[t] == nullptr || taken[t]->GetType() != CommonEnums::CellGeometry::TRIANGLE_CELL)
        {
          delete taken[t];
          taken[t] = new TriangleType;
          for (unsigned int k = 0; k < 3; ++k)
          {
            taken[t]->SetPointId(k, m_CachedTriangles[3 * t + k]);
          }
        }
      }
    }
    auto cells = OutputCellsContainer::New();
    cells->Reserve(numberOfTriangles);
    auto & elements = cells->CastToSTLContainer();
    for (SizeValueType t = 0; t < numberOfTriangles; ++t)
    {
      elements[t] = taken[t];
    }
    m_OutputCells = cells;
    m_OutputCellsStale = false;
  }
  output->SetCellsAllocationMethod(MeshEnums::MeshClassCellsAllocationMethod::CellsAllocatedDynamicallyCellByCell);
  output->SetCells(m_OutputCells);
  output->SetCellData(OutputMeshType::CellDataContainer::New());
  output->SetPointData(OutputMeshType::PointDataContainer::New());
}

template <typename TInputMesh, typename TOutputMesh>
void
IterativeMeshFilter<TInputMesh, TOutputMesh>::PrintSelf(std::ostream & os, Indent indent) const
{
  Superclass::PrintSelf(os, indent);
  os << indent << "NumberOfIterations: " << m_NumberOfIterations << std::endl;
  os << indent << "CurrentIteration: " << m_CurrentIteration << std::endl;
  os << indent << "IterateFromZero: " << (m_IterateFromZero ? "On" : "Off") << std::endl;
  os << indent << "Cached: " << (m_Cached ? "true" : "false") << std::endl;
  os << indent << "CachedInputTime: " << m_CachedInputTime << std::endl;
  os << indent << "OutputCells: " << (m_OutputCells ? m_OutputCells->Size() : 0) << " shared cells" << std::endl;
  os << indent << "OutputPoints: " << (m_OutputPoints ? m_OutputPoints->Size() : 0) << " reusable points" << std::endl;
  os << indent << "Coordinates: " << this->GetNumberOfCachedPoints() << " cached points, " << m_CoordinateStride
     << " values each" << std::endl;
  os << indent << "OutputPointsFinite: " << (m_OutputPointsFinite ? "true" : "false") << std::endl;
  os << indent << "NumberOfInputPoints: " << m_NumberOfInputPoints << std::endl;
  os << indent << "TopologyChanged: " << (m_TopologyChanged ? "true" : "false") << ", " << m_CachedTriangles.size() / 3
     << " triangles" << (m_OutputCellsStale ? " (output cells stale)" : "") << std::endl;
  os << indent << "OutputPointIdentifiers: " << (m_OutputPointIdentifiers.empty() ? "cached order" : "renumbered")
     << std::endl;
}

} // end namespace itk

#endif
