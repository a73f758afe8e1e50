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

  try
  {
    // A new ITK mesh only when the input changed: a new mesh makes the ITK
    // filter restart, the same one lets it continue.
    const vtkMTimeType inputTime = input->GetMTime();
    if (!internals.InputMesh || internals.InputPolyData != input || internals.InputTime != inputTime)
    {
      edm::MeshBridgeOptions options;
      options.PointData = false;
      options.CellData = false;
      internals.InputMesh = edm::PolyDataToMesh<vtkIterativePolyDataAlgorithmInternals::MeshType>(input, options);
      internals.InputPolyData = input;
      internals.InputTime = inputTime;
      internals.Filter->SetInput(internals.InputMesh);
    }
    if (!this->PrepareFilter(inputVector))
    {
      output->Initialize();
      return 0;
    }
    internals.Filter->SetNumberOfIterations(static_cast<itk::SizeValueType>(this->NumberOfIterations));
    internals.Filter->SetIterateFromZero(this->IterateFromZero != 0);
    internals.Filter->SetAbortGenerateData(false);

    // Progress and abort go through observers of the ITK filter's events.
    const auto onProgress = [this](const itk::EventObject &) {
      this->UpdateProgress(this->Internals->Filter->GetProgress());
      if (this->GetAbortExecute())
      {
        this->Internals->Filter->SetAbortGenerateData(true);
      }
    };
    const unsigned long progressTag = internals.Filter->AddObserver(itk::ProgressEvent(), onProgress);
    try
    {
      internals.Filter->Update();
    }
    catch (...)
    {
      internals.Filter->RemoveObserver(progressTag);
      throw;
    }
    internals.Filter->RemoveObserver(progressTag);
  }
  catch (const itk::ExceptionObject & error)
  {
    vtkErrorMacro("The ITK filter failed: " << error.GetDescription());
    // The next update starts afresh from the input.
    internals.InputMesh = nullptr;
    output->Initialize();
    return 0;
  }
  this->CurrentIteration = static_cast<int>(internals.Filter->GetCurrentIteration());

  // A remeshed surface: the ITK filter's points and triangles, no point or
  // cell data (they described the input's points and cells).
  if (internals.Filter->GetTopologyChanged())
  {
    try
    {
      edm::MeshBridgeOptions options;
      options.PointData = false;
      options.CellData = false;
      vtkSmartPointer<vtkPolyData> remeshed = edm::MeshToPolyData(internals.Filter->GetOutput(), options);
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

  // The input's structure and attributes with the ITK filter's points.
  const auto *    itkPoints = internals.Filter->GetOutput()->GetPoints();
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
    points->SetPoint(i, it.Value().GetDataPointer());
  }
  output->CopyStructure(input);
  output->SetPoints(points);
  output->GetPointData()->PassData(input->GetPointData());
  output->GetCellData()->PassData(input->GetCellData());
  output->GetFieldData()->PassData(input->GetFieldData());
  this->AddOutputArrays(output);
  return 1;
}

//------------------------------------------------------------------------------
void
vtkIterativePolyDataAlgorithm::PrintSelf(ostream & os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "NumberOfIterations: " << this->NumberOfIterations << "\n";
  os << indent << "CurrentIteration: " << this->CurrentIteration << "\n";
  os << indent << "IterateFromZero: " << (this->IterateFromZero ? "On" : "Off") << "\n";
  os << indent << "CachedInput: " << (this->Internals->InputMesh ? this->Internals->InputMesh->GetNumberOfPoints() : 0)
     << " points\n";
  os << indent << "ITKFilter: " << (this->Internals->Filter ? this->Internals->Filter->GetNameOfClass() : "(none)")
     << "\n";
}
