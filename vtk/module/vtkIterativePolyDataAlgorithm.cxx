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
#include "vtkIterativePolyDataAlgorithm.h"

#include "edmMeshBridge.h"
#include "vtkIterativePolyDataAlgorithmInternals.h"

#include "itkCommand.h"

#include "vtkCellData.h"
#include "vtkDataArray.h"
#include "vtkFieldData.h"
#include "vtkInformation.h"
#include "vtkInformationVector.h"
#include "vtkPointData.h"
#include "vtkPoints.h"
#include "vtkPolyData.h"

#include <algorithm>
#include <atomic>
#include <type_traits>

namespace
{
std::atomic<bool> processIsExiting{ false };
struct ExitFlag
{
  ~ExitFlag() { processIsExiting = true; }
} exitFlag;
} // namespace

bool
edmProcessIsExiting()
{
  return processIsExiting;
}

//------------------------------------------------------------------------------
vtkIterativePolyDataAlgorithm::vtkIterativePolyDataAlgorithm()
  : Internals(new vtkIterativePolyDataAlgorithmInternals)
{}

//------------------------------------------------------------------------------
vtkIterativePolyDataAlgorithm::~vtkIterativePolyDataAlgorithm()
{
  if (!edmProcessIsExiting())
  {
    delete this->Internals;
  }
}

//------------------------------------------------------------------------------
void
vtkIterativePolyDataAlgorithm::AddOutputArrays(vtkPolyData *)
{}

//------------------------------------------------------------------------------
int
vtkIterativePolyDataAlgorithm::RequestMeshDimension(vtkPolyData *, vtkInformationVector **)
{
  return 3;
}

//------------------------------------------------------------------------------
int
vtkIterativePolyDataAlgorithm::RequestData(vtkInformation *,
                                           vtkInformationVector ** inputVector,
                                           vtkInformationVector *  outputVector)
{
  vtkPolyData * input = vtkPolyData::GetData(inputVector[0]);
  vtkPolyData * output = vtkPolyData::GetData(outputVector);
  if (output == nullptr)
  {
    vtkErrorMacro("No output polydata.");
    return 0;
  }
  output->Initialize();
  if (input == nullptr || input->GetNumberOfPoints() == 0)
  {
    vtkErrorMacro("The input polydata is empty: it has no points.");
    return 0;
  }
  vtkIterativePolyDataAlgorithmInternals & internals = *this->Internals;
  if (!internals.Filter)
  {
    vtkErrorMacro("No ITK filter: the subclass did not create one.");
    return 0;
  }
  const int dimension = this->RequestMeshDimension(input, inputVector);
  if (dimension != 2 && dimension != 3)
  {
    this->MeshDimension = 0;
    output->Initialize();
    return 0; // the subclass said why
  }
  if (dimension == 2 && !internals.ContourFilter)
  {
    vtkErrorMacro("This algorithm has no 2-D ITK filter: it does not deform contours.");
    this->MeshDimension = 0;
    return 0;
  }
  this->MeshDimension = dimension;
  // A new ITK mesh when the input changed or the dimension did: a new mesh
  // makes the ITK filter restart, the same one lets it continue.
  const vtkMTimeType inputTime = input->GetMTime();
  const bool         inputChanged = internals.InputPolyData != input || internals.InputTime != inputTime;
  if (dimension == 3)
  {
    internals.InputContourMesh = nullptr;
  }
  else
  {
    internals.InputMesh = nullptr;
  }

  // Converts the input if needed, prepares and updates the ITK filter of the
  // dimension, then builds the output. Returns 0 after a vtkErrorMacro.
  auto run = [&](auto * filter, auto & cachedMesh) -> int {
    using MeshType = typename std::decay_t<decltype(cachedMesh)>::ObjectType;
    try
    {
      if (!cachedMesh || inputChanged)
      {
        edm::MeshBridgeOptions options;
        options.PointData = false;
        options.CellData = false;
        // The 2-D filter reads a contour as a chain of segments.
        options.PolyLinesAsSegments = MeshType::PointDimension == 2;
        cachedMesh = edm::PolyDataToMesh<MeshType>(input, options);
        internals.InputPolyData = input;
        internals.InputTime = inputTime;
        filter->SetInput(cachedMesh);
      }
      if (!this->PrepareFilter(inputVector))
      {
        output->Initialize();
        return 0;
      }
      filter->SetNumberOfIterations(static_cast<itk::SizeValueType>(this->NumberOfIterations));
      filter->SetIterateFromZero(this->IterateFromZero != 0);
      filter->SetAbortGenerateData(false);

      // Progress and abort go through observers of the ITK filter's events.
      const auto onProgress = [this, filter](const itk::EventObject &) {
        this->UpdateProgress(filter->GetProgress());
        if (this->GetAbortExecute())
        {
          filter->SetAbortGenerateData(true);
        }
      };
      const unsigned long progressTag = filter->AddObserver(itk::ProgressEvent(), onProgress);
      try
      {
        filter->Update();
      }
      catch (...)
      {
        filter->RemoveObserver(progressTag);
        throw;
      }
      filter->RemoveObserver(progressTag);
    }
    catch (const itk::ExceptionObject & error)
    {
      vtkErrorMacro("The ITK filter failed: " << error.GetDescription());
      // The next update starts afresh from the input.
      cachedMesh = nullptr;
      output->Initialize();
      return 0;
    }
    this->CurrentIteration = static_cast<int>(filter->GetCurrentIteration());

    // A remeshed surface: the ITK filter's points and triangles, no point or
    // cell data (they described the input's points and cells).
    if (filter->GetTopologyChanged())
    {
      try
      {
        edm::MeshBridgeOptions options;
        options.PointData = false;
        options.CellData = false;
        vtkSmartPointer<vtkPolyData> remeshed = edm::MeshToPolyData(filter->GetOutput(), options);
        output->ShallowCopy(remeshed);
      }
      catch (const itk::ExceptionObject & error)
      {
        vtkErrorMacro("Converting the remeshed surface failed: " << error.GetDescription());
        output->Initialize();
        return 0;
      }
      output->GetFieldData()->PassData(input->GetFieldData());
      this->AddOutputArrays(output);
      return 1;
    }

    // The input's structure and attributes with the ITK filter's points (2-D:
    // in the plane z = ContourPlaneZ).
    const auto *    itkPoints = filter->GetOutput()->GetPoints();
    const vtkIdType numberOfPoints = input->GetNumberOfPoints();
    if (itkPoints == nullptr || static_cast<vtkIdType>(itkPoints->Size()) != numberOfPoints)
    {
      vtkErrorMacro("The ITK filter returned " << (itkPoints ? itkPoints->Size() : 0) << " points for an input of "
                                               << numberOfPoints << ".");
      output->Initialize();
      return 0;
    }
    auto points = vtkSmartPointer<vtkPoints>::New();
    points->SetDataType(input->GetPoints()->GetDataType());
    points->SetNumberOfPoints(numberOfPoints);
    vtkIdType i = 0;
    for (auto it = itkPoints->Begin(); it != itkPoints->End(); ++it, ++i)
    {
      const auto & p = it.Value();
      if constexpr (MeshType::PointDimension == 2)
      {
        points->SetPoint(i, p[0], p[1], this->ContourPlaneZ);
      }
      else
      {
        points->SetPoint(i, p.GetDataPointer());
      }
    }
    output->CopyStructure(input);
    output->SetPoints(points);
    output->GetPointData()->PassData(input->GetPointData());
    output->GetCellData()->PassData(input->GetCellData());
    output->GetFieldData()->PassData(input->GetFieldData());
    this->AddOutputArrays(output);
    return 1;
  };
  return dimension == 3 ? run(internals.Filter.GetPointer(), internals.InputMesh)
                        : run(internals.ContourFilter.GetPointer(), internals.InputContourMesh);
}

//------------------------------------------------------------------------------
void
vtkIterativePolyDataAlgorithm::PrintSelf(ostream & os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "NumberOfIterations: " << this->NumberOfIterations << "\n";
  os << indent << "CurrentIteration: " << this->CurrentIteration << "\n";
  os << indent << "IterateFromZero: " << (this->IterateFromZero ? "On" : "Off") << "\n";
  os << indent << "MeshDimension: " << this->MeshDimension << "\n";
  os << indent << "ContourPlaneZ: " << this->ContourPlaneZ << "\n";
  os << indent << "CachedInput: "
     << (this->Internals->InputMesh          ? this->Internals->InputMesh->GetNumberOfPoints()
         : this->Internals->InputContourMesh ? this->Internals->InputContourMesh->GetNumberOfPoints()
                                             : 0)
     << " points\n";
  os << indent << "ITKFilter: " << (this->Internals->Filter ? this->Internals->Filter->GetNameOfClass() : "(none)")
     << "\n";
  os << indent << "ContourITKFilter: "
     << (this->Internals->ContourFilter ? this->Internals->ContourFilter->GetNameOfClass() : "(none)") << "\n";
}
