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
#include "vtkDeformableMesh.h"

#include "edmMeshBridge.h"
#include "vtkIterativePolyDataAlgorithmInternals.h"

#include "itkCovariantVector.h"
#include "itkDeformableMeshFilter.h"
#include "itkImage.h"

#include "vtkAlgorithmOutput.h"
#include "vtkDataArray.h"
#include "vtkDataObject.h"
#include "vtkDataSetAttributes.h"
#include "vtkFloatArray.h"
#include "vtkImageData.h"
#include "vtkInformation.h"
#include "vtkInformationVector.h"
#include "vtkObjectFactory.h"
#include "vtkPointData.h"
#include "vtkPolyData.h"

#include <new>
#include <vector>

vtkStandardNewMacro(vtkDeformableMesh);

/** The typed ITK filter and the force image converted from port 1, with what
 * it was made from. */
class vtkDeformableMeshInternals
{
public:
  using MeshType = vtkIterativePolyDataAlgorithmInternals::MeshType;
  using ForceImageType = itk::Image<itk::CovariantVector<float, 3>, 3>;
  using FilterType = itk::DeformableMeshFilter<MeshType, ForceImageType>;

  FilterType::Pointer     Filter;
  ForceImageType::Pointer ForceImage;
  const vtkImageData *    Image = nullptr;
  vtkMTimeType            ImageTime = 0;
  const vtkDataArray *    Array = nullptr;
  vtkMTimeType            ArrayTime = 0;
  // The region force's intensities (second array of port 1).
  FilterType::IntensityImageType::Pointer IntensityImage;
  const vtkImageData *                    IntensitySource = nullptr;
  vtkMTimeType                            IntensitySourceTime = 0;
  const vtkDataArray *                    IntensityArray = nullptr;
  vtkMTimeType                            IntensityArrayTime = 0;
};

//------------------------------------------------------------------------------
vtkDeformableMesh::vtkDeformableMesh()
  : DeformableInternals(new vtkDeformableMeshInternals)
{
  this->SetNumberOfInputPorts(2);
  this->DeformableInternals->Filter = vtkDeformableMeshInternals::FilterType::New();
  this->Internals->Filter = this->DeformableInternals->Filter.GetPointer();
  // The defaults are the ITK filter's, so that both faces stay the same.
  const auto * filter = this->DeformableInternals->Filter.GetPointer();
  this->ScaleFactor = filter->GetScaleFactor();
  this->Elasticity = filter->GetElasticity();
  this->TangentialElasticity = filter->GetTangentialElasticity() ? 1 : 0;
  this->Rigidity = filter->GetRigidity();
  this->Balloon = filter->GetBalloon();
  this->MaximumStepLength = filter->GetMaximumStepLength();
  this->RemeshingEdgeLength = filter->GetRemeshingEdgeLength();
  this->RemeshingInterval = static_cast<int>(filter->GetRemeshingInterval());
  this->ConvergenceTolerance = filter->GetConvergenceTolerance();
  this->ConvergenceWindow = static_cast<int>(filter->GetConvergenceWindow());
  this->RegionWeight = filter->GetRegionWeight();
  this->RegionSigma = filter->GetRegionSigma();
  this->EdgeSearchWeight = filter->GetEdgeSearchWeight();
  this->EdgeSearchDistance = filter->GetEdgeSearchDistance();
  this->IntensityTolerance = filter->GetIntensityTolerance();
  this->EstimateBackgroundIntensity = filter->GetEstimateBackgroundIntensity() ? 1 : 0;
  this->BackgroundUpdateInterval = static_cast<int>(filter->GetBackgroundUpdateInterval());
  this->EstimateObjectIntensityRange = filter->GetEstimateObjectIntensityRange() ? 1 : 0;
  this->EdgePolarity = filter->GetEdgePolarity();
  this->SetInputArrayToProcess(0, 1, 0, vtkDataObject::FIELD_ASSOCIATION_POINTS, vtkDataSetAttributes::VECTORS);
  this->SetInputArrayToProcess(1, 1, 0, vtkDataObject::FIELD_ASSOCIATION_POINTS, vtkDataSetAttributes::SCALARS);
}

//------------------------------------------------------------------------------
vtkDeformableMesh::~vtkDeformableMesh()
{
  if (!edmProcessIsExiting())
  {
    delete this->DeformableInternals;
  }
}

//------------------------------------------------------------------------------
void
vtkDeformableMesh::SetForceImageData(vtkImageData * image)
{
  this->SetInputData(1, image);
}

//------------------------------------------------------------------------------
void
vtkDeformableMesh::SetForceImageConnection(vtkAlgorithmOutput * output)
{
  this->SetInputConnection(1, output);
}

//------------------------------------------------------------------------------
int
vtkDeformableMesh::FillInputPortInformation(int port, vtkInformation * info)
{
  if (port == 0)
  {
    info->Set(vtkAlgorithm::INPUT_REQUIRED_DATA_TYPE(), "vtkPolyData");
    return 1;
  }
  if (port == 1)
  {
    // Optional for the executive, so that a missing image reaches
    // PrepareFilter() and gets a clear message and an empty output.
    info->Set(vtkAlgorithm::INPUT_REQUIRED_DATA_TYPE(), "vtkImageData");
    info->Set(vtkAlgorithm::INPUT_IS_OPTIONAL(), 1);
    return 1;
  }
  return 0;
}

//------------------------------------------------------------------------------
int
vtkDeformableMesh::PrepareFilter(vtkInformationVector ** inputVector)
{
  vtkDeformableMeshInternals & internals = *this->DeformableInternals;
  this->Converged = 0;
  vtkImageData * image = vtkImageData::GetData(inputVector[1]);
  if (image == nullptr)
  {
    vtkErrorMacro("No force image: connect a vtkImageData with a three-component point array to input port 1 "
                  "(SetForceImageData or SetForceImageConnection).");
    return 0;
  }
  if (image->GetNumberOfPoints() == 0)
  {
    vtkErrorMacro("The force image on input port 1 is empty.");
    return 0;
  }
  vtkDataArray * array = this->GetInputArrayToProcess(0, inputVector);
  if (array == nullptr)
  {
    vtkErrorMacro("No force array: the image on input port 1 has no array matching SetInputArrayToProcess "
                  "(default: the active point vectors).");
    return 0;
  }
  if (array->GetNumberOfComponents() != 3)
  {
    vtkErrorMacro("The force array \"" << (array->GetName() ? array->GetName() : "") << "\" has "
                                       << array->GetNumberOfComponents() << " components; it must have 3.");
    return 0;
  }
  if (array->GetNumberOfTuples() != image->GetNumberOfPoints())
  {
    vtkErrorMacro("The force array must be a point array of the image on input port 1.");
    return 0;
  }

  if (!internals.ForceImage || internals.Image != image || internals.ImageTime != image->GetMTime() ||
      internals.Array != array || internals.ArrayTime != array->GetMTime())
  {
    try
    {
      internals.ForceImage = edm::ImageDataToImage<vtkDeformableMeshInternals::ForceImageType>(image, array);
    }
    catch (const itk::ExceptionObject & error)
    {
      vtkErrorMacro("Cannot convert the force image: " << error.GetDescription());
      internals.ForceImage = nullptr;
      return 0;
    }
    catch (const std::bad_alloc &)
    {
      vtkErrorMacro("Out of memory converting the force image of " << image->GetNumberOfPoints() << " voxels.");
      internals.ForceImage = nullptr;
      return 0;
    }
    internals.Image = image;
    internals.ImageTime = image->GetMTime();
    internals.Array = array;
    internals.ArrayTime = array->GetMTime();
    internals.Filter->SetForceImage(internals.ForceImage);
  }

  auto * filter = internals.Filter.GetPointer();
  if (this->RegionWeight > 0.0 || this->EdgeSearchWeight > 0.0)
  {
    vtkDataArray * intensities = this->GetInputArrayToProcess(1, inputVector);
    if (intensities == nullptr || intensities->GetNumberOfComponents() != 1 ||
        intensities->GetNumberOfTuples() != image->GetNumberOfPoints())
    {
      vtkErrorMacro("RegionWeight is " << this->RegionWeight << " and EdgeSearchWeight " << this->EdgeSearchWeight
                                       << " but the image on input port 1 has no one-component point array of "
                                          "intensities matching SetInputArrayToProcess(1, ...) (default: the active "
                                          "scalars).");
      return 0;
    }
    if (!internals.IntensityImage || internals.IntensitySource != image ||
        internals.IntensitySourceTime != image->GetMTime() || internals.IntensityArray != intensities ||
        internals.IntensityArrayTime != intensities->GetMTime())
    {
      try
      {
        internals.IntensityImage =
          edm::ImageDataToImage<vtkDeformableMeshInternals::FilterType::IntensityImageType>(image, intensities);
      }
      catch (const itk::ExceptionObject & error)
      {
        vtkErrorMacro("Cannot convert the intensities: " << error.GetDescription());
        internals.IntensityImage = nullptr;
        return 0;
      }
      catch (const std::bad_alloc &)
      {
        vtkErrorMacro("Out of memory converting the intensities of " << image->GetNumberOfPoints() << " voxels.");
        internals.IntensityImage = nullptr;
        return 0;
      }
      internals.IntensitySource = image;
      internals.IntensitySourceTime = image->GetMTime();
      internals.IntensityArray = intensities;
      internals.IntensityArrayTime = intensities->GetMTime();
    }
    filter->SetIntensityImage(internals.IntensityImage);
  }
  filter->SetRegionWeight(this->RegionWeight);
  filter->SetRegionSigma(this->RegionSigma);
  filter->SetEdgeSearchWeight(this->EdgeSearchWeight);
  filter->SetEdgeSearchDistance(this->EdgeSearchDistance);
  filter->SetIntensityTolerance(this->IntensityTolerance);
  filter->SetEstimateBackgroundIntensity(this->EstimateBackgroundIntensity != 0);
  filter->SetBackgroundUpdateInterval(static_cast<unsigned int>(this->BackgroundUpdateInterval));
  if (this->EstimateObjectIntensityRange)
  {
    filter->SetEstimateObjectIntensityRange(true);
  }
  else
  {
    // The ITK filter checks the range at its reset (finite, in order, a
    // positive width): a reversed or empty range is its exception.
    const double lower = this->ObjectIntensityRange[0];
    const double upper = this->ObjectIntensityRange[1];
    filter->SetObjectIntensityRange(lower, upper, 0.1 * (upper - lower));
  }
  filter->SetEdgePolarity(this->EdgePolarity);
  filter->SetScaleFactor(this->ScaleFactor);
  filter->SetElasticity(this->Elasticity);
  filter->SetTangentialElasticity(this->TangentialElasticity != 0);
  filter->SetRigidity(this->Rigidity);
  filter->SetBalloon(this->Balloon);
  filter->SetMaximumStepLength(this->MaximumStepLength);
  filter->SetRemeshingEdgeLength(this->RemeshingEdgeLength);
  filter->SetRemeshingInterval(static_cast<unsigned int>(this->RemeshingInterval));
  filter->SetConvergenceTolerance(this->ConvergenceTolerance);
  filter->SetConvergenceWindow(static_cast<unsigned int>(this->ConvergenceWindow));
  return 1;
}

//------------------------------------------------------------------------------
void
vtkDeformableMesh::AddOutputArrays(vtkPolyData * output)
{
  const auto * filter = this->DeformableInternals->Filter.GetPointer();
  this->Converged = filter->GetConverged() ? 1 : 0;
  this->LastMaximumDisplacement = filter->GetLastMaximumDisplacement();
  if (!this->ComputeDiagnostics)
  {
    return;
  }
  const vtkIdType numberOfPoints = output->GetNumberOfPoints();
  auto            addArray = [output, numberOfPoints](const char * name, const std::vector<float> & values) {
    auto array = vtkSmartPointer<vtkFloatArray>::New();
    array->SetName(name);
    array->SetNumberOfTuples(numberOfPoints);
    const bool available = static_cast<vtkIdType>(values.size()) == numberOfPoints;
    for (vtkIdType i = 0; i < numberOfPoints; ++i)
    {
      array->SetValue(i, available ? values[i] : 0.0f);
    }
    output->GetPointData()->AddArray(array);
  };
  addArray("DisplacementMagnitude", filter->GetDisplacementMagnitudes());
  addArray("ExternalForceMagnitude", filter->GetExternalForceMagnitudes());
  addArray("InternalForceMagnitude", filter->GetInternalForceMagnitudes());
}

//------------------------------------------------------------------------------
void
vtkDeformableMesh::PrintSelf(ostream & os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "ScaleFactor: " << this->ScaleFactor << "\n";
  os << indent << "Elasticity: " << this->Elasticity << "\n";
  os << indent << "TangentialElasticity: " << (this->TangentialElasticity ? "On" : "Off") << "\n";
  os << indent << "Rigidity: " << this->Rigidity << "\n";
  os << indent << "Balloon: " << this->Balloon << "\n";
  os << indent << "RegionWeight: " << this->RegionWeight << "\n";
  os << indent << "RegionSigma: " << this->RegionSigma << "\n";
  os << indent << "EdgeSearchWeight: " << this->EdgeSearchWeight << "\n";
  os << indent << "EdgeSearchDistance: " << this->EdgeSearchDistance << "\n";
  os << indent << "IntensityTolerance: " << this->IntensityTolerance << "\n";
  os << indent << "EstimateBackgroundIntensity: " << this->EstimateBackgroundIntensity << "\n";
  os << indent << "BackgroundUpdateInterval: " << this->BackgroundUpdateInterval << "\n";
  os << indent << "EstimateObjectIntensityRange: " << this->EstimateObjectIntensityRange << "\n";
  os << indent << "ObjectIntensityRange: " << this->ObjectIntensityRange[0] << " " << this->ObjectIntensityRange[1]
     << "\n";
  os << indent << "EdgePolarity: " << this->EdgePolarity << "\n";
  os << indent << "MaximumStepLength: " << this->MaximumStepLength << "\n";
  os << indent << "RemeshingEdgeLength: " << this->RemeshingEdgeLength << "\n";
  os << indent << "RemeshingInterval: " << this->RemeshingInterval << "\n";
  os << indent << "ConvergenceTolerance: " << this->ConvergenceTolerance << "\n";
  os << indent << "ConvergenceWindow: " << this->ConvergenceWindow << "\n";
  os << indent << "ComputeDiagnostics: " << (this->ComputeDiagnostics ? "On" : "Off") << "\n";
  os << indent << "Converged: " << (this->Converged ? "true" : "false") << "\n";
  os << indent << "LastMaximumDisplacement: " << this->LastMaximumDisplacement << "\n";
  os << indent << "ForceImage: "
     << (this->DeformableInternals->ForceImage
           ? this->DeformableInternals->ForceImage->GetBufferedRegion().GetNumberOfPixels()
           : 0)
     << " pixels converted\n";
}
