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

// vtkExternalForceField through the VTK pipeline: exact delegation to
// itk::ExternalForceImageFilter in physical space, the direction of the force
// around a known ellipsoid, the chain Force Field -> Deformable Mesh, wrong
// inputs.

#include "edmMeshBridge.h"
#include "vtkDeformableMesh.h"
#include "vtkExternalForceField.h"

#include "itkEllipsoidPhantom.h"
#include "itkExternalForceImageFilter.h"

#include "vtkCallbackCommand.h"
#include "vtkCommand.h"
#include "vtkDataArray.h"
#include "vtkFloatArray.h"
#include "vtkImageData.h"
#include "vtkNew.h"
#include "vtkPointData.h"
#include "vtkPolyData.h"
#include "vtkSphereSource.h"
#include "vtkTrivialProducer.h"

#include "gtest/gtest.h"

#include <cmath>
#include <string>

namespace
{
using ImageType = itk::Image<float, 3>;
using ForceImageType = itk::Image<itk::CovariantVector<float, 3>, 3>;

/** The ellipsoid of radii (12, 10, 12) mm centred at \a center. */
itk::EllipsoidPhantom
MakeEllipsoid(const double center[3])
{
  itk::EllipsoidPhantom::PointType c;
  for (unsigned int d = 0; d < 3; ++d)
  {
    c[d] = center[d];
  }
  itk::EllipsoidPhantom::VectorType radii;
  radii[0] = 12.0;
  radii[1] = 10.0;
  radii[2] = 12.0;
  return itk::EllipsoidPhantom(c, radii);
}

/** A binary ellipsoid (255 inside, 0 outside) as ITK sees it. */
ImageType::Pointer
MakeITKImage(const double center[3], const double spacing[3], const double origin[3], unsigned int size)
{
  ImageType::SizeType    s;
  ImageType::SpacingType sp;
  ImageType::PointType   o;
  for (unsigned int d = 0; d < 3; ++d)
  {
    s[d] = size;
    sp[d] = spacing[d];
    o[d] = origin[d];
  }
  return MakeEllipsoid(center).MakeImage<ImageType>(s, sp, o, ImageType::DirectionType::GetIdentity(), 255, 0);
}

/** Records the error messages of a VTK object. */
class Errors
{
public:
  explicit Errors(vtkObject * object)
  {
    m_Callback->SetClientData(this);
    m_Callback->SetCallback([](vtkObject *, unsigned long, void * clientData, void * callData) {
      auto * self = static_cast<Errors *>(clientData);
      self->m_Text += callData != nullptr ? static_cast<const char *>(callData) : "";
      self->m_Text += "\n";
    });
    object->AddObserver(vtkCommand::ErrorEvent, m_Callback);
  }
  bool
  Contains(const std::string & text) const
  {
    return m_Text.find(text) != std::string::npos;
  }
  const std::string &
  Text() const
  {
    return m_Text;
  }

private:
  vtkNew<vtkCallbackCommand> m_Callback;
  std::string                m_Text;
};

/** The force of a vtkExternalForceField output at the point of index (i, j, k). */
void
ForceAt(vtkImageData * image, int i, int j, int k, double force[3])
{
  int ijk[3] = { i, j, k };
  image->GetPointData()->GetArray("Force")->GetTuple(image->ComputePointId(ijk), force);
}

double
MeanDistance(vtkPolyData * polyData, const itk::EllipsoidPhantom & ellipsoid)
{
  double sum = 0.0;
  for (vtkIdType i = 0; i < polyData->GetNumberOfPoints(); ++i)
  {
    itk::EllipsoidPhantom::PointType p;
    polyData->GetPoint(i, p.GetDataPointer());
    sum += ellipsoid.DistanceToSurface(p);
  }
  return sum / static_cast<double>(polyData->GetNumberOfPoints());
}
} // namespace

TEST(VTKExternalForceField, IsTheITKFilterInPhysicalSpace)
{
  // Anisotropic spacing and an origin away from zero: the VTK class must give
  // the ITK filter's field, value for value, on the input's geometry.
  const double center[3] = { 10.0, -5.0, 20.0 };
  const double spacing[3] = { 1.0, 1.25, 0.8 };
  const double origin[3] = { -14.0, -33.0, 2.0 };
  const auto   itkImage = MakeITKImage(center, spacing, origin, 40);
  auto         vtkImage = edm::ImageToImageData(itkImage.GetPointer(), "Intensity");

  auto reference = itk::ExternalForceImageFilter<ImageType, ForceImageType>::New();
  reference->SetInput(itkImage);
  reference->SetSigma(1.5);
  reference->Update();

  vtkNew<vtkExternalForceField> forces;
  forces->SetInputData(vtkImage);
  forces->SetSigma(1.5);
  forces->Update();
  vtkImageData * output = forces->GetOutput();

  int inputExtent[6];
  int outputExtent[6];
  vtkImage->GetExtent(inputExtent);
  output->GetExtent(outputExtent);
  for (int d = 0; d < 6; ++d)
  {
    EXPECT_EQ(outputExtent[d], inputExtent[d]);
  }
  for (int d = 0; d < 3; ++d)
  {
    EXPECT_DOUBLE_EQ(output->GetSpacing()[d], spacing[d]);
    EXPECT_DOUBLE_EQ(output->GetOrigin()[d], origin[d]);
  }
  vtkDataArray * force = output->GetPointData()->GetVectors();
  ASSERT_NE(force, nullptr);
  EXPECT_STREQ(force->GetName(), "Force");
  EXPECT_EQ(force->GetNumberOfComponents(), 3);
  EXPECT_NE(output->GetPointData()->GetArray("Intensity"), nullptr) << "the input arrays are passed";

  const ForceImageType * expected = reference->GetOutput();
  const auto *           buffer = expected->GetBufferPointer();
  ASSERT_EQ(force->GetNumberOfTuples(), static_cast<vtkIdType>(expected->GetBufferedRegion().GetNumberOfPixels()));
  vtkIdType mismatches = 0;
  for (vtkIdType i = 0; i < force->GetNumberOfTuples(); ++i)
  {
    for (int c = 0; c < 3; ++c)
    {
      mismatches += force->GetComponent(i, c) != static_cast<double>(buffer[i][c]) ? 1 : 0;
    }
  }
  EXPECT_EQ(mismatches, 0);
}

TEST(VTKExternalForceField, ParametersReachTheITKFilter)
{
  const double center[3] = { 23.5, 23.5, 23.5 };
  const double spacing[3] = { 1.0, 1.0, 1.0 };
  const double origin[3] = { 0.0, 0.0, 0.0 };
  const auto   itkImage = MakeITKImage(center, spacing, origin, 48);
  auto         vtkImage = edm::ImageToImageData(itkImage.GetPointer(), "Intensity");

  auto reference = itk::ExternalForceImageFilter<ImageType, ForceImageType>::New();
  reference->SetInput(itkImage);
  reference->SetSigma(0.5);
  reference->SetNormalizeForces(false);
  reference->SetUseGradientVectorFlow(true);
  reference->SetGradientVectorFlowRegularization(0.2);
  reference->SetGradientVectorFlowIterations(20);
  reference->Update();

  vtkNew<vtkExternalForceField> forces;
  forces->SetInputData(vtkImage);
  forces->SetSigma(0.5);
  forces->NormalizeForcesOff();
  forces->UseGradientVectorFlowOn();
  forces->SetGradientVectorFlowRegularization(0.2);
  forces->SetGradientVectorFlowIterations(20);
  forces->Update();

  vtkDataArray * force = forces->GetOutput()->GetPointData()->GetArray("Force");
  ASSERT_NE(force, nullptr);
  const auto * buffer = reference->GetOutput()->GetBufferPointer();
  vtkIdType    mismatches = 0;
  for (vtkIdType i = 0; i < force->GetNumberOfTuples(); ++i)
  {
    for (int c = 0; c < 3; ++c)
    {
      mismatches += force->GetComponent(i, c) != static_cast<double>(buffer[i][c]) ? 1 : 0;
    }
  }
  EXPECT_EQ(mismatches, 0);
}

TEST(VTKExternalForceField, PointsTowardTheEllipsoidSurface)
{
  // Along the x axis through the centre (23.5, 23.5, 23.5) of unit voxels the
  // surface is at x = 11.5 and x = 35.5: the force points to it from both
  // sides, and vanishes at the centre, far from any edge.
  const double center[3] = { 23.5, 23.5, 23.5 };
  const double spacing[3] = { 1.0, 1.0, 1.0 };
  const double origin[3] = { 0.0, 0.0, 0.0 };
  const auto   itkImage = MakeITKImage(center, spacing, origin, 48);
  auto         vtkImage = edm::ImageToImageData(itkImage.GetPointer(), "Intensity");

  vtkNew<vtkExternalForceField> forces;
  forces->SetInputData(vtkImage);
  forces->Update();
  vtkImageData * output = forces->GetOutput();

  double f[3];
  ForceAt(output, 38, 23, 23, f); // outside, beyond x = 35.5
  EXPECT_LT(f[0], 0.0);
  ForceAt(output, 33, 23, 23, f); // inside, before x = 35.5
  EXPECT_GT(f[0], 0.0);
  ForceAt(output, 9, 23, 23, f); // outside, below x = 11.5
  EXPECT_GT(f[0], 0.0);
  ForceAt(output, 14, 23, 23, f); // inside
  EXPECT_LT(f[0], 0.0);
  ForceAt(output, 23, 23, 23, f);
  EXPECT_LT(std::sqrt(f[0] * f[0] + f[1] * f[1] + f[2] * f[2]), 1e-3);

  // Normalised: the largest force has length 1.
  double     largest = 0.0;
  const auto array = output->GetPointData()->GetArray("Force");
  for (vtkIdType i = 0; i < array->GetNumberOfTuples(); ++i)
  {
    const double * v = array->GetTuple3(i);
    largest = std::max(largest, std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]));
  }
  EXPECT_NEAR(largest, 1.0, 1e-6);
}

TEST(VTKExternalForceField, DrivesADeformableMeshOntoTheEllipsoid)
{
  // The seed's pipeline: volume -> Force Field -> Deformable Mesh (port 1,
  // default array: the active vectors "Force").
  const double               center[3] = { 23.5, 23.5, 23.5 };
  const double               spacing[3] = { 1.0, 1.0, 1.0 };
  const double               origin[3] = { 0.0, 0.0, 0.0 };
  const auto                 itkImage = MakeITKImage(center, spacing, origin, 48);
  vtkNew<vtkTrivialProducer> volume;
  volume->SetOutput(edm::ImageToImageData(itkImage.GetPointer(), "Intensity"));

  vtkNew<vtkExternalForceField> forces;
  forces->SetInputConnection(volume->GetOutputPort());

  vtkNew<vtkSphereSource> sphere;
  sphere->SetCenter(center[0], center[1], center[2]);
  sphere->SetRadius(11.0);
  sphere->SetThetaResolution(32);
  sphere->SetPhiResolution(32);
  sphere->Update();

  vtkNew<vtkDeformableMesh> deformable;
  deformable->SetInputConnection(0, sphere->GetOutputPort());
  deformable->SetForceImageConnection(forces->GetOutputPort());
  deformable->SetScaleFactor(0.5);
  deformable->SetNumberOfIterations(100);
  deformable->Update();

  const auto   ellipsoid = MakeEllipsoid(center);
  const double before = MeanDistance(sphere->GetOutput(), ellipsoid);
  const double after = MeanDistance(deformable->GetOutput(), ellipsoid);
  std::cout << "mean distance to the ellipsoid: " << before << " -> " << after << " mm" << std::endl;
  EXPECT_GT(before, 0.5);
  EXPECT_LT(after, 0.25);
}

TEST(VTKExternalForceField, WrongInputsGiveAnErrorAndAnEmptyOutput)
{
  vtkNew<vtkExternalForceField> forces;
  Errors                        errors(forces);

  // A two-component array.
  vtkNew<vtkImageData> image;
  image->SetDimensions(8, 8, 8);
  image->AllocateScalars(VTK_FLOAT, 2);
  image->GetPointData()->GetScalars()->Fill(0.0);
  forces->SetInputData(image);
  forces->Update();
  EXPECT_TRUE(errors.Contains("it must have 1")) << errors.Text();
  EXPECT_EQ(forces->GetOutput()->GetNumberOfPoints(), 0);

  // A missing array.
  image->AllocateScalars(VTK_FLOAT, 1);
  image->GetPointData()->GetScalars()->SetName("Intensity");
  forces->SetInputArrayToProcess(0, 0, 0, vtkDataObject::FIELD_ASSOCIATION_POINTS, "NoSuchArray");
  image->Modified();
  forces->Update();
  EXPECT_TRUE(errors.Contains("No intensity array")) << errors.Text();
  EXPECT_EQ(forces->GetOutput()->GetNumberOfPoints(), 0);

  // An image flat along y (a 2-D image is flat along z: nx x ny x 1).
  vtkNew<vtkImageData> slice;
  slice->SetDimensions(8, 1, 8);
  slice->AllocateScalars(VTK_FLOAT, 1);
  slice->GetPointData()->GetScalars()->Fill(0.0);
  forces->SetInputArrayToProcess(0, 0, 0, vtkDataObject::FIELD_ASSOCIATION_POINTS, vtkDataSetAttributes::SCALARS);
  forces->SetInputData(slice);
  forces->Update();
  EXPECT_TRUE(errors.Contains("three-dimensional")) << errors.Text();
  EXPECT_EQ(forces->GetOutput()->GetNumberOfPoints(), 0);

  // An invalid parameter.
  forces->SetInputData(image);
  forces->SetGradientVectorFlowRegularization(0.0);
  forces->Update();
  EXPECT_TRUE(errors.Contains("GradientVectorFlowRegularization")) << errors.Text();
  EXPECT_EQ(forces->GetOutput()->GetNumberOfPoints(), 0);

  // And back to a valid configuration.
  forces->SetGradientVectorFlowRegularization(0.1);
  forces->Update();
  EXPECT_EQ(forces->GetOutput()->GetNumberOfPoints(), 512);
}
