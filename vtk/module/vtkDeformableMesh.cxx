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
#include "vtkCellArray.h"
#include "vtkCellArrayIterator.h"
#include "vtkIdList.h"
#include "vtkDataArray.h"
#include "vtkDataObject.h"
#include "vtkDataSetAttributes.h"
#include "vtkFloatArray.h"
#include "vtkImageData.h"
#include "vtkInformation.h"
#include "vtkInformationVector.h"
#include "vtkMatrix3x3.h"
#include "vtkObjectFactory.h"
#include "vtkPointData.h"
#include "vtkPolyData.h"

#include <algorithm>
#include <cmath>
#include <new>
#include <sstream>
#include <type_traits>
#include <vector>

vtkStandardNewMacro(vtkDeformableMesh);

namespace
{
/** An itk::Image converted from a point array of a vtkImageData, with what it
 * was made from: converted again only when the image or the array changes. */
template <typename TImage>
struct ConvertedImage
{
  typename TImage::Pointer Image;
  const vtkImageData *     Source = nullptr;
  vtkMTimeType             SourceTime = 0;
  const vtkDataArray *     Array = nullptr;
  vtkMTimeType             ArrayTime = 0;

  bool
  IsUpToDate(vtkImageData * source, vtkDataArray * array) const
  {
    return this->Image && this->Source == source && this->SourceTime == source->GetMTime() && this->Array == array &&
           this->ArrayTime == array->GetMTime();
  }
  void
  Remember(vtkImageData * source, vtkDataArray * array)
  {
    this->Source = source;
    this->SourceTime = source->GetMTime();
    this->Array = array;
    this->ArrayTime = array->GetMTime();
  }
};

/** The first two components of a 2- or 3-component array: the in-plane force
 * of a 2-D image. */
vtkSmartPointer<vtkDataArray>
InPlaneComponents(vtkDataArray * array)
{
  if (array->GetNumberOfComponents() == 2)
  {
    return array;
  }
  auto inPlane = vtkSmartPointer<vtkFloatArray>::New();
  inPlane->SetName(array->GetName());
  inPlane->SetNumberOfComponents(2);
  inPlane->SetNumberOfTuples(array->GetNumberOfTuples());
  for (vtkIdType i = 0; i < array->GetNumberOfTuples(); ++i)
  {
    inPlane->SetTypedComponent(i, 0, static_cast<float>(array->GetComponent(i, 0)));
    inPlane->SetTypedComponent(i, 1, static_cast<float>(array->GetComponent(i, 1)));
  }
  return inPlane;
}
} // namespace

/** The typed ITK filters (3-D surfaces, 2-D contours) and the images
 * converted from port 1, with what they were made from. */
class vtkDeformableMeshInternals
{
public:
  using MeshType = vtkIterativePolyDataAlgorithmInternals::MeshType;
  using ForceImageType = itk::Image<itk::CovariantVector<float, 3>, 3>;
  using FilterType = itk::DeformableMeshFilter<MeshType, ForceImageType>;
  using ContourMeshType = vtkIterativePolyDataAlgorithmInternals::ContourMeshType;
  using ContourForceImageType = itk::Image<itk::CovariantVector<float, 2>, 2>;
  using ContourFilterType = itk::DeformableMeshFilter<ContourMeshType, ContourForceImageType>;

  FilterType::Pointer                                   Filter;
  ConvertedImage<ForceImageType>                        ForceImage;
  ConvertedImage<FilterType::IntensityImageType>        IntensityImage; // the region force's (second array)
  ContourFilterType::Pointer                            ContourFilter;
  ConvertedImage<ContourForceImageType>                 ContourForceImage;
  ConvertedImage<ContourFilterType::IntensityImageType> ContourIntensityImage;
};

//------------------------------------------------------------------------------
vtkDeformableMesh::vtkDeformableMesh()
  : DeformableInternals(new vtkDeformableMeshInternals)
{
  this->SetNumberOfInputPorts(2);
  this->DeformableInternals->Filter = vtkDeformableMeshInternals::FilterType::New();
  this->DeformableInternals->ContourFilter = vtkDeformableMeshInternals::ContourFilterType::New();
  this->Internals->Filter = this->DeformableInternals->Filter.GetPointer();
  this->Internals->ContourFilter = this->DeformableInternals->ContourFilter.GetPointer();
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
  this->TangentialDrift = static_cast<int>(filter->GetTangentialDrift());
  this->ReferenceEdgeLength = filter->GetReferenceEdgeLength();
  this->ConvergenceAlongNormals = filter->GetConvergenceAlongNormals() ? 1 : 0;
  this->PreventSelfIntersections = filter->GetPreventSelfIntersections() ? 1 : 0;
  this->MinimumDistance = filter->GetMinimumDistance();
  this->FixedBoundary = filter->GetFixedBoundary() ? 1 : 0;
  this->ConvergenceTolerance = filter->GetConvergenceTolerance();
  this->ConvergenceWindow = static_cast<int>(filter->GetConvergenceWindow());
  this->ConvergenceFraction = filter->GetConvergenceFraction();
  this->DampOscillations = filter->GetDampOscillations() ? 1 : 0;
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
vtkDeformableMesh::RequestMeshDimension(vtkPolyData * input, vtkInformationVector ** inputVector)
{
  this->NumberOfClosedContours = 0;
  this->NumberOfOpenContours = 0;
  vtkImageData * image = vtkImageData::GetData(inputVector[1]);
  if (image == nullptr || image->GetNumberOfPoints() == 0)
  {
    return 3; // PrepareFilter() says what is missing
  }
  int extent[6];
  image->GetExtent(extent);
  const vtkIdType lines = input->GetNumberOfLines();
  const vtkIdType polys = input->GetNumberOfPolys();
  const vtkIdType strips = input->GetNumberOfStrips();
  const vtkIdType verts = input->GetNumberOfVerts();
  const auto      extentText = [&extent]() {
    std::ostringstream text;
    text << (extent[1] - extent[0] + 1) << " x " << (extent[3] - extent[2] + 1) << " x " << (extent[5] - extent[4] + 1);
    return text.str();
  };

  if (extent[4] != extent[5])
  {
    // A 3-D image: surfaces, and curves in space. Lines alone in one plane
    // z = const are a 2-D contour, which needs a 2-D image.
    if (lines > 0 && polys == 0 && strips == 0)
    {
      double bounds[6];
      input->GetBounds(bounds);
      const double size = std::max({ bounds[1] - bounds[0], bounds[3] - bounds[2], 1e-300 });
      if (bounds[5] - bounds[4] <= 1e-9 * size)
      {
        vtkErrorMacro("The input is a 2-D contour (" << lines << " line(s) in the plane z = " << bounds[4]
                                                     << "), but the force image on input port 1 is 3-D ("
                                                     << extentText()
                                                     << " points): a contour needs a 2-D image of nx x ny x 1 "
                                                        "points (for example one slice, vtkExtractVOI).");
        return 0;
      }
    }
    return 3;
  }

  // A 2-D image: contours in its plane.
  if (extent[0] == extent[1] || extent[2] == extent[3])
  {
    vtkErrorMacro("The force image on input port 1 has " << extentText()
                                                         << " points: a 2-D image must be nx x ny x 1 (flat along z "
                                                            "only).");
    return 0;
  }
  if (lines == 0 || polys > 0 || strips > 0 || verts > 0)
  {
    vtkErrorMacro("The force image on input port 1 is 2-D ("
                  << extentText() << " points): the input must be contours, as lines or polylines only, but it has "
                  << lines << " line(s), " << polys << " polygon(s) or triangle(s), " << strips
                  << " triangle strip(s) and " << verts
                  << " vertex cell(s). A 2-D model deforms contours; remove the other cells (for example "
                     "vtkRegularPolygonSource with GeneratePolygonOff).");
    return 0;
  }
  {
    vtkCellArray * cells = input->GetLines();
    vtkIdType      cellId = 0;
    auto           iterator = vtk::TakeSmartPointer(cells->NewIterator());
    for (iterator->GoToFirstCell(); !iterator->IsDoneWithTraversal(); iterator->GoToNextCell(), ++cellId)
    {
      if (iterator->GetCurrentCell()->GetNumberOfIds() < 2)
      {
        vtkErrorMacro("Line cell " << cellId << " has " << iterator->GetCurrentCell()->GetNumberOfIds()
                                   << " point(s): a contour needs at least 2.");
        return 0;
      }
    }
  }
  const vtkMatrix3x3 * direction = image->GetDirectionMatrix();
  for (int k = 0; k < 2; ++k)
  {
    if (std::abs(direction->GetElement(k, 2)) > 1e-9 || std::abs(direction->GetElement(2, k)) > 1e-9)
    {
      vtkErrorMacro("The 2-D force image's direction matrix mixes z with x and y: its plane is not z = const, "
                    "and a contour is deformed in a plane z = const.");
      return 0;
    }
  }
  double corner[3];
  image->TransformIndexToPhysicalPoint(extent[0], extent[2], extent[4], corner);
  this->ContourPlaneZ = corner[2];
  return 2;
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
  const bool contours = this->MeshDimension == 2;
  if (contours ? (array->GetNumberOfComponents() != 2 && array->GetNumberOfComponents() != 3)
               : array->GetNumberOfComponents() != 3)
  {
    vtkErrorMacro("The force array \"" << (array->GetName() ? array->GetName() : "") << "\" has "
                                       << array->GetNumberOfComponents() << " components; it must have 3"
                                       << (contours ? " (or 2 over a 2-D image)." : "."));
    return 0;
  }
  if (array->GetNumberOfTuples() != image->GetNumberOfPoints())
  {
    vtkErrorMacro("The force array must be a point array of the image on input port 1.");
    return 0;
  }

  // Converts the arrays of port 1 when they changed and passes the parameters
  // to the ITK filter of the model's dimension.
  auto prepare = [&](auto * filter, auto & forceImage, auto & intensityImage) -> int {
    using ForceImageType = typename std::decay_t<decltype(*forceImage.Image)>;
    using IntensityImageType = typename std::decay_t<decltype(*intensityImage.Image)>;
    if (!forceImage.IsUpToDate(image, array))
    {
      try
      {
        vtkSmartPointer<vtkDataArray> components = array;
        if (contours)
        {
          components = InPlaneComponents(array);
        }
        forceImage.Image = edm::ImageDataToImage<ForceImageType>(image, components);
      }
      catch (const itk::ExceptionObject & error)
      {
        vtkErrorMacro("Cannot convert the force image: " << error.GetDescription());
        forceImage.Image = nullptr;
        return 0;
      }
      catch (const std::bad_alloc &)
      {
        vtkErrorMacro("Out of memory converting the force image of " << image->GetNumberOfPoints() << " voxels.");
        forceImage.Image = nullptr;
        return 0;
      }
      forceImage.Remember(image, array);
      filter->SetForceImage(forceImage.Image);
    }

    if (this->RegionWeight > 0.0 || this->EdgeSearchWeight > 0.0)
    {
      vtkDataArray * intensities = this->GetInputArrayToProcess(1, inputVector);
      if (intensities == nullptr || intensities->GetNumberOfComponents() != 1 ||
          intensities->GetNumberOfTuples() != image->GetNumberOfPoints())
      {
        vtkErrorMacro("RegionWeight is " << this->RegionWeight << " and EdgeSearchWeight " << this->EdgeSearchWeight
                                         << " but the image on input port 1 has no one-component point array of "
                                            "intensities matching SetInputArrayToProcess(1, ...) (default: the "
                                            "active scalars).");
        return 0;
      }
      if (!intensityImage.IsUpToDate(image, intensities))
      {
        try
        {
          intensityImage.Image = edm::ImageDataToImage<IntensityImageType>(image, intensities);
        }
        catch (const itk::ExceptionObject & error)
        {
          vtkErrorMacro("Cannot convert the intensities: " << error.GetDescription());
          intensityImage.Image = nullptr;
          return 0;
        }
        catch (const std::bad_alloc &)
        {
          vtkErrorMacro("Out of memory converting the intensities of " << image->GetNumberOfPoints() << " voxels.");
          intensityImage.Image = nullptr;
          return 0;
        }
        intensityImage.Remember(image, intensities);
      }
      filter->SetIntensityImage(intensityImage.Image);
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
    filter->SetTangentialDrift(static_cast<itk::DeformableMeshFilterEnums::TangentialDrift>(this->TangentialDrift));
    filter->SetReferenceEdgeLength(this->ReferenceEdgeLength);
    filter->SetConvergenceAlongNormals(this->ConvergenceAlongNormals != 0);
    filter->SetPreventSelfIntersections(this->PreventSelfIntersections != 0);
    filter->SetMinimumDistance(this->MinimumDistance);
    filter->SetFixedBoundary(this->FixedBoundary != 0);
    filter->SetConvergenceTolerance(this->ConvergenceTolerance);
    filter->SetConvergenceWindow(static_cast<unsigned int>(this->ConvergenceWindow));
    filter->SetConvergenceFraction(this->ConvergenceFraction);
    filter->SetDampOscillations(this->DampOscillations != 0);
    return 1;
  };
  return contours
           ? prepare(internals.ContourFilter.GetPointer(), internals.ContourForceImage, internals.ContourIntensityImage)
           : prepare(internals.Filter.GetPointer(), internals.ForceImage, internals.IntensityImage);
}

//------------------------------------------------------------------------------
void
vtkDeformableMesh::AddOutputArrays(vtkPolyData * output)
{
  auto add = [this, output](const auto * filter) {
    this->Converged = filter->GetConverged() ? 1 : 0;
    this->LastMaximumDisplacement = filter->GetLastMaximumDisplacement();
    this->NumberOfCollisionsPrevented = static_cast<vtkIdType>(filter->GetTotalNumberOfCollisionsPrevented());
    this->NumberOfClosedContours = static_cast<int>(filter->GetNumberOfClosedContours());
    this->NumberOfOpenContours = static_cast<int>(filter->GetNumberOfOpenContours());
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
  };
  if (this->MeshDimension == 2)
  {
    add(this->DeformableInternals->ContourFilter.GetPointer());
  }
  else
  {
    add(this->DeformableInternals->Filter.GetPointer());
  }
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
  os << indent << "TangentialDrift: " << this->TangentialDrift << "\n";
  os << indent << "ReferenceEdgeLength: " << this->ReferenceEdgeLength << "\n";
  os << indent << "ConvergenceAlongNormals: " << (this->ConvergenceAlongNormals ? "On" : "Off") << "\n";
  os << indent << "PreventSelfIntersections: " << (this->PreventSelfIntersections ? "On" : "Off") << "\n";
  os << indent << "MinimumDistance: " << this->MinimumDistance << "\n";
  os << indent << "FixedBoundary: " << (this->FixedBoundary ? "On" : "Off") << "\n";
  os << indent << "ConvergenceTolerance: " << this->ConvergenceTolerance << "\n";
  os << indent << "ConvergenceWindow: " << this->ConvergenceWindow << "\n";
  os << indent << "ConvergenceFraction: " << this->ConvergenceFraction << "\n";
  os << indent << "DampOscillations: " << (this->DampOscillations ? "On" : "Off") << "\n";
  os << indent << "ComputeDiagnostics: " << (this->ComputeDiagnostics ? "On" : "Off") << "\n";
  os << indent << "Converged: " << (this->Converged ? "true" : "false") << "\n";
  os << indent << "LastMaximumDisplacement: " << this->LastMaximumDisplacement << "\n";
  os << indent << "NumberOfCollisionsPrevented: " << this->NumberOfCollisionsPrevented << "\n";
  os << indent << "NumberOfClosedContours: " << this->NumberOfClosedContours << "\n";
  os << indent << "NumberOfOpenContours: " << this->NumberOfOpenContours << "\n";
  const auto & forces3 = this->DeformableInternals->ForceImage.Image;
  const auto & forces2 = this->DeformableInternals->ContourForceImage.Image;
  os << indent << "ForceImage: " << (forces3 ? forces3->GetBufferedRegion().GetNumberOfPixels() : 0)
     << " voxels converted (3-D), " << (forces2 ? forces2->GetBufferedRegion().GetNumberOfPixels() : 0)
     << " pixels (2-D)\n";
}
