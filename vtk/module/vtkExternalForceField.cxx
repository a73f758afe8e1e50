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
#include "vtkFloatArray.h"
#include "vtkImageData.h"
#include "vtkInformation.h"
#include "vtkInformationVector.h"
#include "vtkObjectFactory.h"
#include "vtkPointData.h"
#include "vtkStreamingDemandDrivenPipeline.h"

#include <cmath>
#include <new>
#include <type_traits>

vtkStandardNewMacro(vtkExternalForceField);

namespace
{
template <unsigned int Dimension>
using IntensityImageType = itk::Image<float, Dimension>;
template <unsigned int Dimension>
using ForceImageType = itk::Image<itk::CovariantVector<float, Dimension>, Dimension>;
template <unsigned int Dimension>
using ForceFilterType = itk::ExternalForceImageFilter<IntensityImageType<Dimension>, ForceImageType<Dimension>>;
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
  // 3-D, or 2-D in a plane z = const (nx x ny x 1 points).
  const bool planar = extent[1] > extent[0] && extent[3] > extent[2] && extent[5] == extent[4];
  if (!planar && (extent[1] <= extent[0] || extent[3] <= extent[2] || extent[5] <= extent[4]))
  {
    vtkErrorMacro("The input image must be three-dimensional, or two-dimensional with nx x ny x 1 points; its "
                  "extent is ["
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

  // Runs the ITK filter of the image's dimension; the force comes back as a
  // three-component array (2-D: z component 0) on the input's points.
  vtkSmartPointer<vtkDataArray> force;
  auto                          run = [&](auto dimension) {
    constexpr unsigned int Dimension = decltype(dimension)::value;
    auto                   intensity = edm::ImageDataToImage<IntensityImageType<Dimension>>(input, array);
    auto                   filter = ForceFilterType<Dimension>::New();
    filter->SetInput(intensity);
    filter->SetSigma(this->Sigma);
    filter->SetNormalizeForces(this->NormalizeForces != 0);
    filter->SetUseGradientVectorFlow(this->UseGradientVectorFlow != 0);
    filter->SetGradientVectorFlowRegularization(this->GradientVectorFlowRegularization);
    filter->SetGradientVectorFlowIterations(static_cast<unsigned int>(this->GradientVectorFlowIterations));
    const auto * observed = filter.GetPointer();
    filter->AddObserver(itk::ProgressEvent(),
                        [this, observed](const itk::EventObject &) { this->UpdateProgress(observed->GetProgress()); });
    filter->Update();
    const auto *    field = filter->GetOutput();
    const auto *    buffer = field->GetBufferPointer();
    const vtkIdType numberOfPoints = input->GetNumberOfPoints();
    if (static_cast<vtkIdType>(field->GetBufferedRegion().GetNumberOfPixels()) != numberOfPoints)
    {
      itkGenericExceptionMacro("the force image has " << field->GetBufferedRegion().GetNumberOfPixels()
                                                      << " pixels, the input " << numberOfPoints << " points.");
    }
    auto values = vtkSmartPointer<vtkFloatArray>::New();
    values->SetName("Force");
    values->SetNumberOfComponents(3);
    values->SetNumberOfTuples(numberOfPoints);
    // ITK's and VTK's buffers both run x fastest: the i-th pixel is the i-th tuple.
    for (vtkIdType i = 0; i < numberOfPoints; ++i)
    {
      for (int c = 0; c < 3; ++c)
      {
        values->SetTypedComponent(i, c, c < static_cast<int>(Dimension) ? buffer[i][c] : 0.0f);
      }
    }
    force = values;
  };
  try
  {
    if (planar)
    {
      run(std::integral_constant<unsigned int, 2>());
    }
    else
    {
      run(std::integral_constant<unsigned int, 3>());
    }
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
  output->CopyStructure(input);
  output->GetPointData()->PassData(input->GetPointData());
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
