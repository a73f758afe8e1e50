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
#include "vtkExternalForceField.h"

#include "edmMeshBridge.h"

#include "itkCommand.h"
#include "itkCovariantVector.h"
#include "itkExternalForceImageFilter.h"
#include "itkImage.h"

#include "vtkDataArray.h"
#include "vtkDataObject.h"
#include "vtkDataSetAttributes.h"
#include "vtkImageData.h"
#include "vtkInformation.h"
#include "vtkInformationVector.h"
#include "vtkObjectFactory.h"
#include "vtkPointData.h"
#include "vtkStreamingDemandDrivenPipeline.h"

#include <cmath>
#include <new>

vtkStandardNewMacro(vtkExternalForceField);

namespace
{
using IntensityImageType = itk::Image<float, 3>;
using ForceImageType = itk::Image<itk::CovariantVector<float, 3>, 3>;
using ForceFilterType = itk::ExternalForceImageFilter<IntensityImageType, ForceImageType>;
} // namespace

//------------------------------------------------------------------------------
vtkExternalForceField::vtkExternalForceField()
{
  this->SetInputArrayToProcess(0, 0, 0, vtkDataObject::FIELD_ASSOCIATION_POINTS, vtkDataSetAttributes::SCALARS);
}

//------------------------------------------------------------------------------
int
vtkExternalForceField::FillInputPortInformation(int port, vtkInformation * info)
{
  if (port != 0)
  {
    return 0;
  }
  info->Set(vtkAlgorithm::INPUT_REQUIRED_DATA_TYPE(), "vtkImageData");
  return 1;
}

//------------------------------------------------------------------------------
int
vtkExternalForceField::RequestUpdateExtent(vtkInformation *,
                                           vtkInformationVector ** inputVector,
                                           vtkInformationVector *)
{
  // Smoothing and diffusion are global: the whole input is needed.
  vtkInformation * inInfo = inputVector[0]->GetInformationObject(0);
  inInfo->Set(vtkStreamingDemandDrivenPipeline::UPDATE_EXTENT(),
              inInfo->Get(vtkStreamingDemandDrivenPipeline::WHOLE_EXTENT()),
              6);
  return 1;
}

//------------------------------------------------------------------------------
int
vtkExternalForceField::RequestData(vtkInformation *,
                                   vtkInformationVector ** inputVector,
                                   vtkInformationVector *  outputVector)
{
  vtkImageData * input = vtkImageData::GetData(inputVector[0]);
  vtkImageData * output = vtkImageData::GetData(outputVector);
  if (output == nullptr)
  {
    vtkErrorMacro("No output image.");
    return 0;
  }
  output->Initialize();
  if (input == nullptr || input->GetNumberOfPoints() == 0)
  {
    vtkErrorMacro("The input image is empty.");
    return 0;
  }
  int extent[6];
  input->GetExtent(extent);
  if (extent[1] <= extent[0] || extent[3] <= extent[2] || extent[5] <= extent[4])
  {
    vtkErrorMacro("The input image must be three-dimensional; its extent is ["
                  << extent[0] << ", " << extent[1] << "] x [" << extent[2] << ", " << extent[3] << "] x [" << extent[4]
                  << ", " << extent[5] << "].");
    return 0;
  }
  vtkDataArray * array = this->GetInputArrayToProcess(0, inputVector);
  if (array == nullptr)
  {
    vtkErrorMacro("No intensity array: the input image has no point array matching SetInputArrayToProcess "
                  "(default: the active point scalars).");
    return 0;
  }
  if (array->GetNumberOfComponents() != 1)
  {
    vtkErrorMacro("The intensity array \"" << (array->GetName() ? array->GetName() : "") << "\" has "
                                           << array->GetNumberOfComponents() << " components; it must have 1.");
    return 0;
  }
  if (array->GetNumberOfTuples() != input->GetNumberOfPoints())
  {
    vtkErrorMacro("The intensity array must be a point array of the input image.");
    return 0;
  }
  if (!std::isfinite(this->Sigma) || !(this->GradientVectorFlowRegularization > 0.0) ||
      !std::isfinite(this->GradientVectorFlowRegularization))
  {
    vtkErrorMacro("Invalid parameters: Sigma must be finite and non-negative, GradientVectorFlowRegularization "
                  "positive and finite.");
    return 0;
  }

  vtkSmartPointer<vtkImageData> forces;
  try
  {
    IntensityImageType::Pointer intensity = edm::ImageDataToImage<IntensityImageType>(input, array);
    auto                        filter = ForceFilterType::New();
    filter->SetInput(intensity);
    filter->SetSigma(this->Sigma);
    filter->SetNormalizeForces(this->NormalizeForces != 0);
    filter->SetUseGradientVectorFlow(this->UseGradientVectorFlow != 0);
    filter->SetGradientVectorFlowRegularization(this->GradientVectorFlowRegularization);
    filter->SetGradientVectorFlowIterations(static_cast<unsigned int>(this->GradientVectorFlowIterations));
    const ForceFilterType * observed = filter.GetPointer();
    filter->AddObserver(itk::ProgressEvent(),
                        [this, observed](const itk::EventObject &) { this->UpdateProgress(observed->GetProgress()); });
    filter->Update();
    forces = edm::ImageToImageData(filter->GetOutput(), "Force");
  }
  catch (const itk::ExceptionObject & error)
  {
    vtkErrorMacro("The ITK filter failed: " << error.GetDescription());
    output->Initialize();
    return 0;
  }
  catch (const std::bad_alloc &)
  {
    vtkErrorMacro("Out of memory computing the force field of " << input->GetNumberOfPoints() << " voxels.");
    output->Initialize();
    return 0;
  }

  // The input's geometry and point arrays, plus the force as active vectors.
  output->CopyStructure(forces);
  output->GetPointData()->PassData(input->GetPointData());
  vtkDataArray * force = forces->GetPointData()->GetArray("Force");
  output->GetPointData()->AddArray(force);
  output->GetPointData()->SetActiveVectors("Force");
  return 1;
}

//------------------------------------------------------------------------------
void
vtkExternalForceField::PrintSelf(ostream & os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "Sigma: " << this->Sigma << "\n";
  os << indent << "NormalizeForces: " << (this->NormalizeForces ? "On" : "Off") << "\n";
  os << indent << "UseGradientVectorFlow: " << (this->UseGradientVectorFlow ? "On" : "Off") << "\n";
  os << indent << "GradientVectorFlowRegularization: " << this->GradientVectorFlowRegularization << "\n";
  os << indent << "GradientVectorFlowIterations: " << this->GradientVectorFlowIterations << "\n";
}
