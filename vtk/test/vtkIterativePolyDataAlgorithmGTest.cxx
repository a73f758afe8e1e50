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

// The VTK faces through the VTK pipeline: the iteration contract (Update,
// Modified, SetInputConnection, SetInputData, IterateFromZero), exact
// delegation to the ITK filters, known answers, wrong inputs, time series.

#include "edmMeshBridge.h"
#include "vtkDeformableMesh.h"
#include "vtkIterationSeriesWriter.h"
#include "vtkIterativePolyDataAlgorithmInternals.h"
#include "vtkPolyDataIterativeWarp.h"

#include "itkBrownianMeshFilter.h"
#include "itkCommand.h"
#include "itkDeformableMeshFilter.h"
#include "itkEllipsoidPhantom.h"
#include "itkExternalForceImageFilter.h"

#include "vtkCallbackCommand.h"
#include "vtkCellArray.h"
#include "vtkCommand.h"
#include "vtkDoubleArray.h"
#include "vtkFloatArray.h"
#include "vtkIdList.h"
#include "vtkImageData.h"
#include "vtkNew.h"
#include "vtkObjectFactory.h"
#include "vtkPointData.h"
#include "vtkPolyData.h"
#include "vtkSphereSource.h"
#include "vtkTrivialProducer.h"
#include "vtkXMLDataElement.h"
#include "vtkXMLDataParser.h"
#include "vtkXMLPolyDataReader.h"

#include "gtest/gtest.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>

namespace
{
using MeshType = vtkIterativePolyDataAlgorithmInternals::MeshType;
using ImageType = itk::Image<float, 3>;
using ForceImageType = itk::Image<itk::CovariantVector<float, 3>, 3>;

/** Counts the steps the ITK filter inside a VTK algorithm runs. */
template <typename TAlgorithm>
class StepCounting : public TAlgorithm
{
public:
  static StepCounting *
  New()
  {
    VTK_STANDARD_NEW_BODY(StepCounting);
  }
  vtkTypeMacro(StepCounting, TAlgorithm);

  int Steps = 0;
  int
  TakeSteps()
  {
    const int steps = this->Steps;
    this->Steps = 0;
    return steps;
  }

protected:
  StepCounting()
  {
    this->Internals->Filter->AddObserver(itk::IterationEvent(), [this](const itk::EventObject &) { ++this->Steps; });
  }
  ~StepCounting() override = default;
};
using CountingWarp = StepCounting<vtkPolyDataIterativeWarp>;
using CountingDeformableMesh = StepCounting<vtkDeformableMesh>;

/** Records the error messages of a VTK object. */
class ErrorRecorder
{
public:
  explicit ErrorRecorder(vtkObject * object)
  {
    m_Callback->SetClientData(this);
    m_Callback->SetCallback([](vtkObject *, unsigned long, void * clientData, void * callData) {
      auto * self = static_cast<ErrorRecorder *>(clientData);
      self->m_Messages += callData != nullptr ? static_cast<const char *>(callData) : "";
      self->m_Messages += "\n";
      ++self->m_Count;
    });
    object->AddObserver(vtkCommand::ErrorEvent, m_Callback);
  }
  int
  Count() const
  {
    return m_Count;
  }
  const std::string &
  Messages() const
  {
    return m_Messages;
  }

private:
  vtkNew<vtkCallbackCommand> m_Callback;
  std::string                m_Messages;
  int                        m_Count{ 0 };
};

/** Points of a vtkPolyData, as doubles. */
std::vector<double>
Coordinates(vtkPolyData * polyData)
{
  std::vector<double> x(3 * polyData->GetNumberOfPoints());
  for (vtkIdType i = 0; i < polyData->GetNumberOfPoints(); ++i)
  {
    polyData->GetPoint(i, &x[3 * i]);
  }
  return x;
}

std::vector<double>
Coordinates(const MeshType * mesh)
{
  std::vector<double> x;
  for (auto it = mesh->GetPoints()->Begin(); it != mesh->GetPoints()->End(); ++it)
  {
    x.insert(x.end(), it.Value().Begin(), it.Value().End());
  }
  return x;
}

/** A UV sphere with a point array, as the seed's examples use. */
vtkSmartPointer<vtkPolyData>
MakeSphere(double radius, const double center[3])
{
  vtkNew<vtkSphereSource> source;
  source->SetRadius(radius);
  source->SetCenter(center[0], center[1], center[2]);
  source->SetThetaResolution(24);
  source->SetPhiResolution(16);
  source->SetOutputPointsPrecision(vtkAlgorithm::DOUBLE_PRECISION);
  source->Update();
  vtkSmartPointer<vtkPolyData> sphere = source->GetOutput();
  vtkNew<vtkDoubleArray>       label;
  label->SetName("Label");
  for (vtkIdType i = 0; i < sphere->GetNumberOfPoints(); ++i)
  {
    label->InsertNextValue(static_cast<double>(i));
  }
  sphere->GetPointData()->AddArray(label);
  return sphere;
}

MeshType::Pointer
ToITK(vtkPolyData * polyData)
{
  edm::MeshBridgeOptions options;
  options.PointData = false;
  options.CellData = false;
  return edm::PolyDataToMesh<MeshType>(polyData, options);
}

std::vector<double>
ReferenceWarp(vtkPolyData * input, unsigned int iterations, double stepLength, uint64_t seed)
{
  auto filter = itk::BrownianMeshFilter<MeshType>::New();
  filter->SetInput(ToITK(input));
  filter->SetNumberOfIterations(iterations);
  filter->SetStepLength(stepLength);
  filter->SetSeed(seed);
  filter->Update();
  return Coordinates(filter->GetOutput());
}

/** The test ellipsoid: radii (12, 10, 12) mm centred in a 48^3 image of
 * 1 mm voxels. */
itk::EllipsoidPhantom
MakeEllipsoid()
{
  itk::EllipsoidPhantom::PointType center;
  center.Fill(23.5);
  itk::EllipsoidPhantom::VectorType radii;
  radii[0] = 12.0;
  radii[1] = 10.0;
  radii[2] = 12.0;
  return itk::EllipsoidPhantom(center, radii);
}

/** The test ellipsoid as a binary image (255 inside, 0 outside), 48^3 voxels
 * of 1 mm. */
ImageType::Pointer
MakeEllipsoidImage()
{
  ImageType::SizeType size;
  size.Fill(48);
  ImageType::SpacingType spacing;
  spacing.Fill(1.0);
  ImageType::PointType origin;
  origin.Fill(0.0);
  return MakeEllipsoid().MakeImage<ImageType>(size, spacing, origin, ImageType::DirectionType::GetIdentity(), 255, 0);
}

/** ExternalForceImageFilter's force field (sigma 1 mm, normalised) of the
 * test ellipsoid. */
ForceImageType::Pointer
MakeForces()
{
  const auto image = MakeEllipsoidImage();
  auto       forces = itk::ExternalForceImageFilter<ImageType, ForceImageType>::New();
  forces->SetInput(image);
  forces->SetSigma(1.0);
  forces->Update();
  ForceImageType::Pointer result = forces->GetOutput();
  result->DisconnectPipeline();
  return result;
}

double
MeanDistanceToEllipsoid(vtkPolyData * polyData)
{
  const auto ellipsoid = MakeEllipsoid();
  double     sum = 0.0;
  for (vtkIdType i = 0; i < polyData->GetNumberOfPoints(); ++i)
  {
    itk::EllipsoidPhantom::PointType p;
    polyData->GetPoint(i, p.GetDataPointer());
    sum += ellipsoid.DistanceToSurface(p);
  }
  return sum / polyData->GetNumberOfPoints();
}

const double Origin[3] = { 0.0, 0.0, 0.0 };
const double Center[3] = { 23.5, 23.5, 23.5 };
} // namespace

TEST(VTKIterativeAlgorithms, ZeroIterationsGiveTheInputBack)
{
  auto                             sphere = MakeSphere(2.0, Origin);
  vtkNew<vtkPolyDataIterativeWarp> warp;
  warp->SetInputData(sphere);
  warp->SetStepLength(0.5);
  warp->Update();
  vtkPolyData * output = warp->GetOutput();
  EXPECT_EQ(warp->GetCurrentIteration(), 0);
  EXPECT_EQ(Coordinates(output), Coordinates(sphere));
  EXPECT_EQ(output->GetPoints()->GetDataType(), VTK_DOUBLE);
  EXPECT_EQ(output->GetNumberOfPolys(), sphere->GetNumberOfPolys());
  ASSERT_NE(output->GetPointData()->GetArray("Label"), nullptr);
  EXPECT_EQ(output->GetPointData()->GetArray("Label")->GetComponent(7, 0), 7.0);
  // The input is never modified.
  EXPECT_NE(output->GetPoints(), sphere->GetPoints());
}

TEST(VTKIterativeAlgorithms, WarpIsTheITKBrownianFilter)
{
  auto                             sphere = MakeSphere(2.0, Origin);
  vtkNew<vtkPolyDataIterativeWarp> warp;
  warp->SetInputData(sphere);
  warp->SetStepLength(0.25);
  warp->SetSeed(12345);
  warp->SetNumberOfIterations(7);
  warp->Update();
  EXPECT_EQ(warp->GetCurrentIteration(), 7);
  const auto expected = ReferenceWarp(sphere, 7, 0.25, 12345);
  EXPECT_EQ(Coordinates(warp->GetOutput()), expected);
  // The cells and point data are the input's.
  vtkNew<vtkIdList> a;
  vtkNew<vtkIdList> b;
  sphere->GetCellPoints(5, a);
  warp->GetOutput()->GetCellPoints(5, b);
  ASSERT_EQ(a->GetNumberOfIds(), b->GetNumberOfIds());
  for (vtkIdType k = 0; k < a->GetNumberOfIds(); ++k)
  {
    EXPECT_EQ(a->GetId(k), b->GetId(k));
  }

  // A different seed, a different walk; the RMS step is StepLength.
  warp->SetSeed(54321);
  warp->SetNumberOfIterations(1);
  warp->Update();
  const auto moved = Coordinates(warp->GetOutput());
  const auto start = Coordinates(sphere);
  double     squares = 0.0;
  for (std::size_t k = 0; k < start.size(); ++k)
  {
    squares += (moved[k] - start[k]) * (moved[k] - start[k]);
  }
  const double rms = std::sqrt(squares / sphere->GetNumberOfPoints());
  EXPECT_NEAR(rms, 0.25, 0.25 * 0.15); // 338 points: about 4% sampling error.
}

TEST(VTKIterativeAlgorithms, RaisingNumberOfIterationsByOneRunsOneStep)
{
  vtkNew<vtkSphereSource> source;
  source->SetRadius(3.0);
  source->SetOutputPointsPrecision(vtkAlgorithm::DOUBLE_PRECISION);
  vtkNew<CountingWarp> warp;
  warp->SetInputConnection(source->GetOutputPort());
  warp->SetStepLength(0.1);
  warp->IterateFromZeroOff();
  warp->SetNumberOfIterations(5);
  warp->Update();
  EXPECT_EQ(warp->TakeSteps(), 5);
  EXPECT_EQ(warp->GetCurrentIteration(), 5);

  for (int n = 6; n <= 8; ++n)
  {
    warp->SetNumberOfIterations(n);
    warp->Update();
    EXPECT_EQ(warp->TakeSteps(), 1) << "NumberOfIterations " << n;
    EXPECT_EQ(warp->GetCurrentIteration(), n);
  }
  // Continuing gives the same mesh as computing from the start.
  EXPECT_EQ(Coordinates(warp->GetOutput()), ReferenceWarp(source->GetOutput(), 8, 0.1, 0));

  // Modified() re-executes the VTK algorithm but no step is due.
  warp->Modified();
  warp->Update();
  EXPECT_EQ(warp->TakeSteps(), 0);
  EXPECT_EQ(warp->GetCurrentIteration(), 8);

  // Fewer iterations than done: restart from the input.
  warp->SetNumberOfIterations(3);
  warp->Update();
  EXPECT_EQ(warp->TakeSteps(), 3);
  EXPECT_EQ(Coordinates(warp->GetOutput()), ReferenceWarp(source->GetOutput(), 3, 0.1, 0));

  // Zero iterations: the input, and the next update starts from it.
  warp->SetNumberOfIterations(0);
  warp->Update();
  EXPECT_EQ(warp->TakeSteps(), 0);
  EXPECT_EQ(Coordinates(warp->GetOutput()), Coordinates(source->GetOutput()));
  warp->SetNumberOfIterations(1);
  warp->Update();
  EXPECT_EQ(warp->TakeSteps(), 1);
}

TEST(VTKIterativeAlgorithms, IterateFromZeroRunsEverythingAgain)
{
  vtkNew<vtkSphereSource> source;
  vtkNew<CountingWarp>    warp;
  warp->SetInputConnection(source->GetOutputPort());
  EXPECT_TRUE(warp->GetIterateFromZero());
  warp->SetNumberOfIterations(4);
  warp->Update();
  EXPECT_EQ(warp->TakeSteps(), 4);
  warp->SetNumberOfIterations(5);
  warp->Update();
  EXPECT_EQ(warp->TakeSteps(), 5);
  EXPECT_EQ(warp->GetCurrentIteration(), 5);
}

TEST(VTKIterativeAlgorithms, AChangedInputRestarts)
{
  // Through SetInputConnection: the source changes.
  vtkNew<vtkSphereSource> source;
  source->SetOutputPointsPrecision(vtkAlgorithm::DOUBLE_PRECISION);
  vtkNew<CountingWarp> warp;
  warp->SetInputConnection(source->GetOutputPort());
  warp->IterateFromZeroOff();
  warp->SetSeed(3);
  warp->SetNumberOfIterations(4);
  warp->Update();
  EXPECT_EQ(warp->TakeSteps(), 4);
  source->SetCenter(10.0, 0.0, 0.0);
  warp->SetNumberOfIterations(5);
  warp->Update();
  EXPECT_EQ(warp->TakeSteps(), 5);
  EXPECT_EQ(Coordinates(warp->GetOutput()), ReferenceWarp(source->GetOutput(), 5, 1.0, 3));

  // Through SetInputData: another polydata, then the same one modified.
  auto first = MakeSphere(1.0, Origin);
  warp->SetInputData(first);
  warp->Update();
  EXPECT_EQ(warp->TakeSteps(), 5);
  warp->SetNumberOfIterations(6);
  warp->Update();
  EXPECT_EQ(warp->TakeSteps(), 1);
  double p[3];
  first->GetPoint(0, p);
  p[0] += 1.0;
  first->GetPoints()->SetPoint(0, p);
  first->GetPoints()->Modified();
  warp->Update();
  EXPECT_EQ(warp->TakeSteps(), 6);
  EXPECT_EQ(Coordinates(warp->GetOutput()), ReferenceWarp(first, 6, 1.0, 3));
}

TEST(VTKIterativeAlgorithms, DeformableMeshIsTheITKFilterAndReachesTheEllipsoid)
{
  const auto forces = MakeForces();
  auto       forceImage = edm::ImageToImageData(forces.GetPointer(), "Force");
  auto       sphere = MakeSphere(11.0, Center);

  vtkNew<CountingDeformableMesh> deformable;
  deformable->SetInputData(sphere);
  deformable->SetForceImageData(forceImage);
  deformable->SetScaleFactor(0.5);
  deformable->SetNumberOfIterations(150);
  deformable->Update();
  EXPECT_EQ(deformable->TakeSteps(), 150);
  EXPECT_EQ(deformable->GetCurrentIteration(), 150);

  auto filter = itk::DeformableMeshFilter<MeshType, ForceImageType>::New();
  filter->SetInput(ToITK(sphere));
  filter->SetForceImage(forces);
  filter->SetScaleFactor(0.5);
  filter->SetNumberOfIterations(150);
  filter->Update();
  EXPECT_EQ(Coordinates(deformable->GetOutput()), Coordinates(filter->GetOutput()));

  // Known answer: the sphere (up to 1 mm off the surface) ends on the
  // ellipsoid, within a fifth of a voxel on average.
  const double before = MeanDistanceToEllipsoid(sphere);
  const double after = MeanDistanceToEllipsoid(deformable->GetOutput());
  std::cout << "mean distance to the ellipsoid: " << before << " mm before, " << after << " mm after" << std::endl;
  EXPECT_GT(before, 0.5);
  EXPECT_LT(after, 0.2);

  // Diagnostics: the last iteration's displacements.
  vtkDataArray * displacement = deformable->GetOutput()->GetPointData()->GetArray("DisplacementMagnitude");
  ASSERT_NE(displacement, nullptr);
  ASSERT_NE(deformable->GetOutput()->GetPointData()->GetArray("ExternalForceMagnitude"), nullptr);
  ASSERT_NE(deformable->GetOutput()->GetPointData()->GetArray("InternalForceMagnitude"), nullptr);
  EXPECT_NEAR(displacement->GetRange()[1], deformable->GetLastMaximumDisplacement(), 1e-6);
  EXPECT_NEAR(deformable->GetOutput()->GetPointData()->GetArray("InternalForceMagnitude")->GetRange()[1], 0.0, 0.0);
}

TEST(VTKIterativeAlgorithms, DeformableMeshContinuesStepByStep)
{
  const auto                 forces = MakeForces();
  auto                       forceImage = edm::ImageToImageData(forces.GetPointer(), "Force");
  vtkNew<vtkTrivialProducer> producer;
  producer->SetOutput(forceImage);
  vtkNew<vtkSphereSource> source;
  source->SetCenter(Center[0], Center[1], Center[2]);
  source->SetRadius(11.0);
  source->SetOutputPointsPrecision(vtkAlgorithm::DOUBLE_PRECISION);

  vtkNew<CountingDeformableMesh> deformable;
  deformable->SetInputConnection(0, source->GetOutputPort());
  deformable->SetForceImageConnection(producer->GetOutputPort());
  deformable->SetElasticity(0.2);
  deformable->SetRigidity(0.05);
  deformable->SetScaleFactor(0.5);
  deformable->IterateFromZeroOff();
  deformable->SetNumberOfIterations(0);
  deformable->Update();
  // Iteration 0: zero diagnostics.
  EXPECT_EQ(deformable->GetOutput()->GetPointData()->GetArray("DisplacementMagnitude")->GetRange()[1], 0.0);
  for (int n = 1; n <= 10; ++n)
  {
    deformable->SetNumberOfIterations(n);
    deformable->Update();
    EXPECT_EQ(deformable->TakeSteps(), 1) << "iteration " << n;
  }
  auto filter = itk::DeformableMeshFilter<MeshType, ForceImageType>::New();
  filter->SetInput(ToITK(source->GetOutput()));
  filter->SetForceImage(forces);
  filter->SetElasticity(0.2);
  filter->SetRigidity(0.05);
  filter->SetScaleFactor(0.5);
  filter->SetNumberOfIterations(10);
  filter->Update();
  EXPECT_EQ(Coordinates(deformable->GetOutput()), Coordinates(filter->GetOutput()));
  EXPECT_GT(deformable->GetOutput()->GetPointData()->GetArray("InternalForceMagnitude")->GetRange()[1], 0.0);

  // A parameter change continues from the current mesh.
  deformable->SetScaleFactor(0.25);
  deformable->SetNumberOfIterations(11);
  deformable->Update();
  EXPECT_EQ(deformable->TakeSteps(), 1);
}

TEST(VTKIterativeAlgorithms, DeformableMeshStopsAtConvergence)
{
  const auto forces = MakeForces();
  auto       forceImage = edm::ImageToImageData(forces.GetPointer(), "Force");
  auto       sphere = MakeSphere(11.0, Center);

  vtkNew<vtkDeformableMesh> deformable;
  deformable->SetInputData(sphere);
  deformable->SetForceImageData(forceImage);
  deformable->SetScaleFactor(0.5);
  deformable->SetConvergenceTolerance(0.01);
  deformable->SetConvergenceWindow(3);
  deformable->SetNumberOfIterations(1000);
  deformable->Update();
  EXPECT_TRUE(deformable->GetConverged());
  EXPECT_LT(deformable->GetCurrentIteration(), 1000);
  EXPECT_LT(deformable->GetLastMaximumDisplacement(), 0.01);

  auto filter = itk::DeformableMeshFilter<MeshType, ForceImageType>::New();
  filter->SetInput(ToITK(sphere));
  filter->SetForceImage(forces);
  filter->SetScaleFactor(0.5);
  filter->SetConvergenceTolerance(0.01);
  filter->SetConvergenceWindow(3);
  filter->SetNumberOfIterations(1000);
  filter->Update();
  EXPECT_EQ(static_cast<itk::SizeValueType>(deformable->GetCurrentIteration()), filter->GetCurrentIteration());
  EXPECT_EQ(Coordinates(deformable->GetOutput()), Coordinates(filter->GetOutput()));
  std::cout << "converged at iteration " << deformable->GetCurrentIteration() << std::endl;
}

TEST(VTKIterativeAlgorithms, DeformableMeshUsesTheArrayToProcess)
{
  const auto forces = MakeForces();
  auto       forceImage = edm::ImageToImageData(forces.GetPointer(), "Force");
  // A zero field next to the real one, made the active vectors.
  vtkNew<vtkFloatArray> zero;
  zero->SetName("Zero");
  zero->SetNumberOfComponents(3);
  zero->SetNumberOfTuples(forceImage->GetNumberOfPoints());
  zero->Fill(0.0);
  forceImage->GetPointData()->AddArray(zero);
  forceImage->GetPointData()->SetActiveVectors("Zero");
  auto sphere = MakeSphere(11.0, Center);

  vtkNew<vtkDeformableMesh> deformable;
  deformable->SetInputData(0, sphere);
  deformable->SetInputData(1, forceImage);
  deformable->SetNumberOfIterations(5);
  deformable->Update();
  EXPECT_EQ(Coordinates(deformable->GetOutput()), Coordinates(sphere));

  deformable->SetInputArrayToProcess(0, 1, 0, vtkDataObject::FIELD_ASSOCIATION_POINTS, "Force");
  deformable->Update();
  EXPECT_NE(Coordinates(deformable->GetOutput()), Coordinates(sphere));
  EXPECT_LT(MeanDistanceToEllipsoid(deformable->GetOutput()), MeanDistanceToEllipsoid(sphere));
}

TEST(VTKIterativeAlgorithms, WrongInputsGiveAnErrorAndAnEmptyOutput)
{
  const auto forces = MakeForces();
  auto       forceImage = edm::ImageToImageData(forces.GetPointer(), "Force");
  auto       sphere = MakeSphere(11.0, Center);

  // No image on port 1.
  vtkNew<vtkDeformableMesh> deformable;
  ErrorRecorder             errors(deformable);
  deformable->SetInputData(sphere);
  deformable->SetNumberOfIterations(3);
  deformable->Update();
  EXPECT_GE(errors.Count(), 1);
  EXPECT_NE(errors.Messages().find("No force image"), std::string::npos) << errors.Messages();
  EXPECT_EQ(deformable->GetOutput()->GetNumberOfPoints(), 0);

  // A one-component array.
  vtkNew<vtkImageData> scalarImage;
  scalarImage->SetDimensions(8, 8, 8);
  scalarImage->AllocateScalars(VTK_FLOAT, 1);
  deformable->SetInputArrayToProcess(0, 1, 0, vtkDataObject::FIELD_ASSOCIATION_POINTS, "ImageScalars");
  scalarImage->GetPointData()->GetScalars()->SetName("ImageScalars");
  deformable->SetForceImageData(scalarImage);
  deformable->Update();
  EXPECT_NE(errors.Messages().find("it must have 3"), std::string::npos) << errors.Messages();
  EXPECT_EQ(deformable->GetOutput()->GetNumberOfPoints(), 0);

  // A missing array.
  deformable->SetInputArrayToProcess(0, 1, 0, vtkDataObject::FIELD_ASSOCIATION_POINTS, "NoSuchArray");
  deformable->Update();
  EXPECT_NE(errors.Messages().find("No force array"), std::string::npos) << errors.Messages();
  EXPECT_EQ(deformable->GetOutput()->GetNumberOfPoints(), 0);

  // An invalid parameter: the ITK filter's exception becomes an error.
  deformable->SetInputArrayToProcess(0, 1, 0, vtkDataObject::FIELD_ASSOCIATION_POINTS, "Force");
  deformable->SetForceImageData(forceImage);
  deformable->SetScaleFactor(std::nan(""));
  deformable->Update();
  EXPECT_NE(errors.Messages().find("ScaleFactor must be finite"), std::string::npos) << errors.Messages();
  EXPECT_EQ(deformable->GetOutput()->GetNumberOfPoints(), 0);

  // Good inputs again: it works.
  deformable->SetScaleFactor(0.5);
  deformable->Update();
  EXPECT_EQ(deformable->GetOutput()->GetNumberOfPoints(), sphere->GetNumberOfPoints());
  EXPECT_EQ(deformable->GetCurrentIteration(), 3);

  // Empty polydata, to both classes.
  vtkNew<vtkPolyData> empty;
  const int           before = errors.Count();
  deformable->SetInputData(empty);
  deformable->Update();
  EXPECT_GT(errors.Count(), before);
  EXPECT_NE(errors.Messages().find("empty"), std::string::npos) << errors.Messages();
  EXPECT_EQ(deformable->GetOutput()->GetNumberOfPoints(), 0);

  vtkNew<vtkPolyDataIterativeWarp> warp;
  ErrorRecorder                    warpErrors(warp);
  warp->SetInputData(empty);
  warp->SetNumberOfIterations(2);
  warp->Update();
  EXPECT_GE(warpErrors.Count(), 1);
  EXPECT_EQ(warp->GetOutput()->GetNumberOfPoints(), 0);
}

TEST(VTKIterativeAlgorithms, ProgressIsReportedAndAbortStopsBetweenSteps)
{
  auto                 sphere = MakeSphere(2.0, Origin);
  vtkNew<CountingWarp> warp;
  warp->SetInputData(sphere);
  warp->IterateFromZeroOff();
  warp->SetNumberOfIterations(20);

  struct Observed
  {
    std::vector<double> Progress;
    vtkAlgorithm *      Algorithm;
    double              AbortAt;
  } observed{ {}, warp, 0.5 };
  vtkNew<vtkCallbackCommand> onProgress;
  onProgress->SetClientData(&observed);
  onProgress->SetCallback([](vtkObject *, unsigned long, void * clientData, void * callData) {
    auto *       self = static_cast<Observed *>(clientData);
    const double progress = *static_cast<double *>(callData);
    self->Progress.push_back(progress);
    if (progress >= self->AbortAt)
    {
      self->Algorithm->SetAbortExecute(1);
    }
  });
  warp->AddObserver(vtkCommand::ProgressEvent, onProgress);
  warp->Update();
  // Progress rises, and the abort request stops the ITK filter after the step
  // that reported half of the work.
  ASSERT_GE(observed.Progress.size(), 2u);
  EXPECT_TRUE(std::is_sorted(observed.Progress.begin(), observed.Progress.end()));
  EXPECT_EQ(warp->TakeSteps(), 10);
  EXPECT_EQ(warp->GetCurrentIteration(), 10);
  EXPECT_EQ(Coordinates(warp->GetOutput()), ReferenceWarp(sphere, 10, 1.0, 0));

  // Resuming (Modified, as with the ITK filter) runs the remaining steps.
  observed.AbortAt = 2.0;
  warp->SetAbortExecute(0);
  warp->Modified();
  warp->Update();
  EXPECT_EQ(warp->TakeSteps(), 10);
  EXPECT_EQ(warp->GetCurrentIteration(), 20);
  EXPECT_EQ(Coordinates(warp->GetOutput()), ReferenceWarp(sphere, 20, 1.0, 0));
}

/** The region-force cases: the test ellipsoid's intensities riding on a zero
 * force image as its active scalars (as vtkExternalForceField's output
 * carries them), a sphere 5 mm inside it, and the model's parameters, set
 * alike on the VTK and the ITK class. */
struct RegionForceCase
{
  ImageType::Pointer            image = MakeEllipsoidImage(); // 255 inside, 0 outside
  ForceImageType::Pointer       forces = MakeForces();
  vtkSmartPointer<vtkImageData> forceImage;
  vtkSmartPointer<vtkPolyData>  sphere = MakeSphere(5.0, Center);

  RegionForceCase()
  {
    forces->FillBuffer(itk::CovariantVector<float, 3>(0.0f));
    forceImage = edm::ImageToImageData(forces.GetPointer(), "Force");
    const auto intensities = edm::ImageToImageData(image.GetPointer(), "Intensity");
    forceImage->GetPointData()->AddArray(intensities->GetPointData()->GetArray("Intensity"));
    forceImage->GetPointData()->SetActiveScalars("Intensity");
  }

  template <typename TFilter>
  static void
  SetModel(TFilter * filter)
  {
    filter->SetScaleFactor(0.0);
    filter->SetRegionWeight(0.25);
    filter->SetElasticity(0.3);
    filter->SetTangentialElasticity(false);
    filter->SetRigidity(0.05);
    filter->SetNumberOfIterations(600);
  }

  vtkSmartPointer<vtkDeformableMesh>
  VTKFilter() const
  {
    auto deformable = vtkSmartPointer<vtkDeformableMesh>::New();
    deformable->SetInputData(sphere);
    deformable->SetForceImageData(forceImage);
    SetModel(deformable.GetPointer());
    return deformable;
  }

  itk::DeformableMeshFilter<MeshType, ForceImageType>::Pointer
  ITKFilter() const
  {
    auto filter = itk::DeformableMeshFilter<MeshType, ForceImageType>::New();
    filter->SetInput(ToITK(sphere));
    filter->SetForceImage(forces);
    filter->SetIntensityImage(image);
    SetModel(filter.GetPointer());
    return filter;
  }
};

TEST(VTKIterativeAlgorithms, DeformableMeshRegionForceIsTheITKFilterAndStopsOnTheEllipsoid)
{
  RegionForceCase c;

  auto deformable = c.VTKFilter();
  deformable->Update();

  auto filter = c.ITKFilter();
  filter->Update();
  EXPECT_EQ(Coordinates(deformable->GetOutput()), Coordinates(filter->GetOutput()));
  // Known answer: from 5 mm inside everywhere to the ellipsoid's surface.
  EXPECT_LT(MeanDistanceToEllipsoid(deformable->GetOutput()), 0.3);

  // Without intensities: an error and an empty output.
  c.forceImage->GetPointData()->RemoveArray("Intensity");
  ErrorRecorder errors(deformable);
  deformable->Modified();
  deformable->Update();
  EXPECT_GE(errors.Count(), 1);
  EXPECT_NE(errors.Messages().find("intensities"), std::string::npos) << errors.Messages();
  EXPECT_EQ(deformable->GetOutput()->GetNumberOfPoints(), 0);
}

// A given object range (EstimateObjectIntensityRange off) is the ITK filter's
// SetObjectIntensityRange() with a tenth of the range as transition width;
// the surface stops on the iso-surface of the range's lower bound. A range
// whose bounds are not in order is an error.
TEST(VTKIterativeAlgorithms, DeformableMeshGivenObjectRangeIsTheITKFilters)
{
  RegionForceCase c;

  auto deformable = c.VTKFilter();
  deformable->EstimateObjectIntensityRangeOff();
  deformable->SetObjectIntensityRange(127.5, 1000.0);
  deformable->SetEdgePolarity(1);
  deformable->Update();

  auto filter = c.ITKFilter();
  filter->SetObjectIntensityRange(127.5, 1000.0, 87.25);
  filter->SetEdgePolarity(1);
  filter->Update();
  EXPECT_DOUBLE_EQ(filter->GetObjectIntensityLower(), 127.5);
  EXPECT_EQ(Coordinates(deformable->GetOutput()), Coordinates(filter->GetOutput()));
  // Within half a voxel (0.36 measured): the wide fixed transition (a tenth of
  // the range) lets the membrane hold the surface a little further inside
  // than the estimated model does.
  EXPECT_LT(MeanDistanceToEllipsoid(deformable->GetOutput()), 0.5);

  ErrorRecorder errors(deformable);
  deformable->SetObjectIntensityRange(200.0, 100.0);
  deformable->Update();
  EXPECT_GE(errors.Count(), 1);
  EXPECT_NE(errors.Messages().find("object intensity range"), std::string::npos) << errors.Messages();
  EXPECT_EQ(deformable->GetOutput()->GetNumberOfPoints(), 0);
}

TEST(VTKIterativeAlgorithms, PrintSelfPrintsEveryParameter)
{
  vtkNew<vtkDeformableMesh> deformable;
  deformable->SetBalloon(0.125);
  std::ostringstream stream;
  deformable->Print(stream);
  for (const char * name : { "NumberOfIterations",
                             "CurrentIteration",
                             "IterateFromZero",
                             "ScaleFactor",
                             "Elasticity",
                             "TangentialElasticity",
                             "Rigidity",
                             "Balloon: 0.125",
                             "RegionWeight",
                             "RegionSigma",
                             "EdgeSearchWeight",
                             "EdgeSearchDistance",
                             "IntensityTolerance",
                             "EstimateBackgroundIntensity",
                             "BackgroundUpdateInterval",
                             "EstimateObjectIntensityRange",
                             "ObjectIntensityRange",
                             "EdgePolarity",
                             "MaximumStepLength",
                             "RemeshingEdgeLength",
                             "RemeshingInterval",
                             "TangentialDrift",
                             "ReferenceEdgeLength",
                             "ConvergenceAlongNormals",
                             "PreventSelfIntersections",
                             "MinimumDistance",
                             "FixedBoundary",
                             "ConvergenceTolerance",
                             "ConvergenceWindow",
                             "MeshDimension",
                             "NumberOfClosedContours",
                             "NumberOfOpenContours",
                             "ComputeDiagnostics",
                             "Converged",
                             "LastMaximumDisplacement",
                             "NumberOfCollisionsPrevented" })
  {
    EXPECT_NE(stream.str().find(name), std::string::npos) << name;
  }
  vtkNew<vtkPolyDataIterativeWarp> warp;
  std::ostringstream               warpStream;
  warp->Print(warpStream);
  EXPECT_NE(warpStream.str().find("StepLength: 1"), std::string::npos);
  EXPECT_NE(warpStream.str().find("Seed: 0"), std::string::npos);
}

TEST(VTKIterativeAlgorithms, SeriesWriterWritesEveryKthIterationAndACollection)
{
  auto                             sphere = MakeSphere(2.0, Origin);
  vtkNew<vtkPolyDataIterativeWarp> warp;
  warp->SetInputData(sphere);
  warp->SetStepLength(0.1);
  warp->SetSeed(7);

  const std::string                directory = EDM_TEST_OUTPUT_DIRECTORY;
  const std::string                collection = directory + "/warp_series.pvd";
  vtkNew<vtkIterationSeriesWriter> writer;
  writer->SetAlgorithm(warp);
  writer->SetFileName(collection.c_str());
  writer->SetInterval(4);
  writer->SetNumberOfIterations(10);
  ASSERT_EQ(writer->Write(), 1);
  ASSERT_EQ(writer->GetNumberOfWrittenFiles(), 4);
  const int expectedIterations[4] = { 0, 4, 8, 10 };
  for (int k = 0; k < 4; ++k)
  {
    EXPECT_EQ(writer->GetWrittenIteration(k), expectedIterations[k]);
    vtkNew<vtkXMLPolyDataReader> reader;
    reader->SetFileName(writer->GetWrittenFileName(k));
    reader->Update();
    EXPECT_EQ(Coordinates(reader->GetOutput()), ReferenceWarp(sphere, expectedIterations[k], 0.1, 7))
      << writer->GetWrittenFileName(k);
    EXPECT_NE(reader->GetOutput()->GetPointData()->GetArray("Label"), nullptr);
  }
  char expectedName[64];
  std::snprintf(expectedName, sizeof(expectedName), "/warp_series_%06d.vtp", 8);
  EXPECT_EQ(std::string(writer->GetWrittenFileName(2)), directory + expectedName);
  // The algorithm's settings are restored.
  EXPECT_TRUE(warp->GetIterateFromZero());
  EXPECT_EQ(warp->GetNumberOfIterations(), 0);

  // The collection, parsed as ParaView's reader does: one DataSet per file,
  // the iteration as time step, file names relative to the collection.
  vtkNew<vtkXMLDataParser> parser;
  parser->SetFileName(collection.c_str());
  ASSERT_EQ(parser->Parse(), 1);
  vtkXMLDataElement * root = parser->GetRootElement();
  ASSERT_NE(root, nullptr);
  EXPECT_STREQ(root->GetAttribute("type"), "Collection");
  vtkXMLDataElement * datasets = root->FindNestedElementWithName("Collection");
  ASSERT_NE(datasets, nullptr);
  ASSERT_EQ(datasets->GetNumberOfNestedElements(), 4);
  for (int k = 0; k < 4; ++k)
  {
    vtkXMLDataElement * dataset = datasets->GetNestedElement(k);
    EXPECT_STREQ(dataset->GetName(), "DataSet");
    EXPECT_EQ(std::string(dataset->GetAttribute("timestep")), std::to_string(expectedIterations[k]));
    vtkNew<vtkXMLPolyDataReader> reader;
    reader->SetFileName((directory + "/" + dataset->GetAttribute("file")).c_str());
    reader->Update();
    EXPECT_EQ(Coordinates(reader->GetOutput()), ReferenceWarp(sphere, expectedIterations[k], 0.1, 7));
  }

  // Errors: no algorithm, no file name, an unwritable directory.
  vtkNew<vtkIterationSeriesWriter> bad;
  ErrorRecorder                    errors(bad);
  EXPECT_EQ(bad->Write(), 0);
  bad->SetAlgorithm(warp);
  EXPECT_EQ(bad->Write(), 0);
  bad->SetFileName((directory + "/no/such/directory/series.pvd").c_str());
  EXPECT_EQ(bad->WriteIteration(sphere, 0), 0);
  EXPECT_EQ(bad->WriteCollection(), 0);
  EXPECT_GE(errors.Count(), 4);
}

// Issue 15 item 2: a remeshing ITK filter's changing mesh passes through the
// VTK face, step by step, and into a .pvd series.
namespace
{
/** The triangles of a polydata, 3 point ids each. */
std::vector<vtkIdType>
Triangles(vtkPolyData * polyData)
{
  std::vector<vtkIdType> ids;
  vtkCellArray *         polys = polyData->GetPolys();
  polys->InitTraversal();
  vtkIdType         n = 0;
  const vtkIdType * cell = nullptr;
  while (polys->GetNextCell(n, cell))
  {
    ids.insert(ids.end(), cell, cell + n);
    ids.push_back(-n);
  }
  return ids;
}
std::vector<vtkIdType>
Triangles(const MeshType * mesh)
{
  std::vector<vtkIdType> ids;
  for (auto it = mesh->GetCells()->Begin(); it != mesh->GetCells()->End(); ++it)
  {
    const auto * p = it.Value()->PointIdsBegin();
    const auto   n = static_cast<vtkIdType>(it.Value()->GetNumberOfPoints());
    ids.insert(ids.end(), p, p + n);
    ids.push_back(-n);
  }
  return ids;
}
} // namespace

TEST(VTKIterativeAlgorithms, DeformableMeshPassesARemeshedSurfaceThrough)
{
  const auto                 forces = MakeForces();
  auto                       forceImage = edm::ImageToImageData(forces.GetPointer(), "Force");
  vtkNew<vtkTrivialProducer> producer;
  producer->SetOutput(forceImage);
  vtkNew<vtkSphereSource> source;
  source->SetCenter(Center[0], Center[1], Center[2]);
  source->SetRadius(11.0);
  source->SetOutputPointsPrecision(vtkAlgorithm::DOUBLE_PRECISION);
  source->Update();
  const vtkIdType inputPoints = source->GetOutput()->GetNumberOfPoints();

  vtkNew<CountingDeformableMesh> deformable;
  deformable->SetInputConnection(0, source->GetOutputPort());
  deformable->SetForceImageConnection(producer->GetOutputPort());
  deformable->SetElasticity(0.2);
  deformable->SetRigidity(0.05);
  deformable->SetScaleFactor(0.5);
  deformable->SetRemeshingEdgeLength(1.5);
  deformable->SetRemeshingInterval(5);
  deformable->IterateFromZeroOff();
  for (int n = 1; n <= 12; ++n)
  {
    deformable->SetNumberOfIterations(n);
    deformable->Update();
    EXPECT_EQ(deformable->TakeSteps(), 1) << "iteration " << n;
    vtkPolyData * output = deformable->GetOutput();
    if (n < 5)
    {
      EXPECT_EQ(output->GetNumberOfPoints(), inputPoints) << n;
    }
    else
    {
      EXPECT_GT(output->GetNumberOfPoints(), 4 * inputPoints) << "remeshed to edges of 1.5 mm at " << n;
      EXPECT_EQ(output->GetNumberOfPolys(), output->GetNumberOfCells()) << "triangles only";
    }
    vtkDataArray * diagnostics = output->GetPointData()->GetArray("DisplacementMagnitude");
    ASSERT_NE(diagnostics, nullptr);
    EXPECT_EQ(diagnostics->GetNumberOfTuples(), output->GetNumberOfPoints()) << n;
  }
  auto filter = itk::DeformableMeshFilter<MeshType, ForceImageType>::New();
  filter->SetInput(ToITK(source->GetOutput()));
  filter->SetForceImage(forces);
  filter->SetElasticity(0.2);
  filter->SetRigidity(0.05);
  filter->SetScaleFactor(0.5);
  filter->SetRemeshingEdgeLength(1.5);
  filter->SetRemeshingInterval(5);
  filter->SetNumberOfIterations(12);
  filter->Update();
  EXPECT_EQ(Coordinates(deformable->GetOutput()), Coordinates(filter->GetOutput()));
  EXPECT_EQ(Triangles(deformable->GetOutput()), Triangles(filter->GetOutput()));

  // The series: iterations 0, 5, 10 and 12, each file with its own mesh.
  const std::string                directory = EDM_TEST_OUTPUT_DIRECTORY;
  vtkNew<vtkIterationSeriesWriter> writer;
  writer->SetAlgorithm(deformable);
  writer->SetFileName((directory + "/remeshed_series.pvd").c_str());
  writer->SetInterval(5);
  writer->SetNumberOfIterations(12);
  ASSERT_EQ(writer->Write(), 1);
  ASSERT_EQ(writer->GetNumberOfWrittenFiles(), 4);
  for (int k = 0; k < 4; ++k)
  {
    vtkNew<vtkXMLPolyDataReader> reader;
    reader->SetFileName(writer->GetWrittenFileName(k));
    reader->Update();
    vtkPolyData * mesh = reader->GetOutput();
    if (k == 0)
    {
      EXPECT_EQ(mesh->GetNumberOfPoints(), inputPoints);
    }
    else
    {
      EXPECT_GT(mesh->GetNumberOfPoints(), 4 * inputPoints) << writer->GetWrittenFileName(k);
    }
    if (k == 3)
    {
      EXPECT_EQ(Coordinates(mesh), Coordinates(filter->GetOutput()));
      EXPECT_EQ(Triangles(mesh), Triangles(filter->GetOutput()));
    }
  }
}

TEST(VTKIterativeAlgorithms, PreventSelfIntersectionsGivesTheITKFiltersSurface)
{
  // A sphere of radius 5 mm inside the test ellipsoid (no image force
  // there) deflated by a balloon of -0.4 mm per iteration: its fronts meet
  // at the centre after about 11 iterations. Without prevention the 14th
  // iteration's surface has 1 352 intersecting pairs of triangles (192 at
  // the 12th); with PreventSelfIntersections (MinimumDistance 0.05 mm) none.
  // vtkDeformableMesh runs the ITK filter: the same surface, bit for bit,
  // and the same count of near-collisions handled.
  const auto                 forces = MakeForces();
  auto                       forceImage = edm::ImageToImageData(forces.GetPointer(), "Force");
  vtkNew<vtkTrivialProducer> producer;
  producer->SetOutput(forceImage);
  vtkNew<vtkSphereSource> source;
  source->SetCenter(Center[0], Center[1], Center[2]);
  source->SetRadius(5.0);
  source->SetThetaResolution(24);
  source->SetPhiResolution(24);
  source->SetOutputPointsPrecision(vtkAlgorithm::DOUBLE_PRECISION);
  source->Update();
  constexpr int iterations = 14;

  for (const bool prevent : { false, true })
  {
    vtkNew<vtkDeformableMesh> deformable;
    deformable->SetInputConnection(0, source->GetOutputPort());
    deformable->SetForceImageConnection(producer->GetOutputPort());
    deformable->SetElasticity(0.2);
    deformable->SetRigidity(0.05);
    deformable->SetScaleFactor(0.5);
    deformable->SetBalloon(-0.4);
    deformable->SetPreventSelfIntersections(prevent);
    deformable->SetMinimumDistance(0.05);
    deformable->SetNumberOfIterations(iterations);
    deformable->Update();
    const auto               mesh = ToITK(deformable->GetOutput());
    const itk::SizeValueType intersecting = itk::SurfaceCollision::CountSelfIntersections(mesh.GetPointer());

    auto filter = itk::DeformableMeshFilter<MeshType, ForceImageType>::New();
    filter->SetInput(ToITK(source->GetOutput()));
    filter->SetForceImage(forces);
    filter->SetElasticity(0.2);
    filter->SetRigidity(0.05);
    filter->SetScaleFactor(0.5);
    filter->SetBalloon(-0.4);
    filter->SetPreventSelfIntersections(prevent);
    filter->SetMinimumDistance(0.05);
    filter->SetNumberOfIterations(iterations);
    filter->Update();
    EXPECT_EQ(Coordinates(deformable->GetOutput()), Coordinates(filter->GetOutput())) << prevent;
    EXPECT_EQ(deformable->GetNumberOfCollisionsPrevented(),
              static_cast<vtkIdType>(filter->GetTotalNumberOfCollisionsPrevented()));
    if (prevent)
    {
      EXPECT_EQ(intersecting, 0u);
      EXPECT_GT(deformable->GetNumberOfCollisionsPrevented(), 0);
    }
    else
    {
      EXPECT_GT(intersecting, 100u) << "the fronts pass through each other when nothing holds them";
      EXPECT_EQ(deformable->GetNumberOfCollisionsPrevented(), 0);
    }
    std::cout << (prevent ? "with" : "without") << " prevention: " << intersecting << " intersecting pairs, "
              << deformable->GetNumberOfCollisionsPrevented() << " near-collisions handled" << std::endl;
  }
}

TEST(VTKIterativeAlgorithms, ReferenceEdgeLengthAndConvergenceAlongNormalsGiveTheITKFiltersSurface)
{
  // The sphere of radius 11 (edges about 2.2 mm) onto the test ellipsoid
  // with ReferenceEdgeLength 4 mm (internal forces scaled to the mesh's
  // resolution, in sub-steps) and the
  // convergence test along the normals: the VTK class runs the ITK filter
  // with these settings, so the same surface bit for bit, the same number of
  // iterations and the same sub-steps.
  const auto                 forces = MakeForces();
  auto                       forceImage = edm::ImageToImageData(forces.GetPointer(), "Force");
  vtkNew<vtkTrivialProducer> producer;
  producer->SetOutput(forceImage);
  vtkNew<vtkSphereSource> source;
  source->SetCenter(Center[0], Center[1], Center[2]);
  source->SetRadius(11.0);
  source->SetThetaResolution(32);
  source->SetPhiResolution(32);
  source->SetOutputPointsPrecision(vtkAlgorithm::DOUBLE_PRECISION);
  source->Update();

  vtkNew<vtkDeformableMesh> deformable;
  deformable->SetInputConnection(0, source->GetOutputPort());
  deformable->SetForceImageConnection(producer->GetOutputPort());
  deformable->SetElasticity(0.2);
  deformable->SetRigidity(0.05);
  deformable->SetScaleFactor(0.5);
  deformable->SetReferenceEdgeLength(4.0);
  deformable->ConvergenceAlongNormalsOn();
  deformable->SetConvergenceTolerance(0.01);
  deformable->SetNumberOfIterations(400);
  deformable->Update();

  auto filter = itk::DeformableMeshFilter<MeshType, ForceImageType>::New();
  filter->SetInput(ToITK(source->GetOutput()));
  filter->SetForceImage(forces);
  filter->SetElasticity(0.2);
  filter->SetRigidity(0.05);
  filter->SetScaleFactor(0.5);
  filter->SetReferenceEdgeLength(4.0);
  filter->SetConvergenceAlongNormals(true);
  filter->SetConvergenceTolerance(0.01);
  filter->SetNumberOfIterations(400);
  filter->Update();
  EXPECT_GT(filter->GetNumberOfSubSteps(), 1u) << "edges shorter than L: the internal forces in sub-steps";
  EXPECT_TRUE(filter->GetConverged());
  EXPECT_EQ(deformable->GetConverged(), 1);
  EXPECT_EQ(deformable->GetCurrentIteration(), static_cast<int>(filter->GetCurrentIteration()));
  EXPECT_EQ(Coordinates(deformable->GetOutput()), Coordinates(filter->GetOutput()));

  // Without the reference length (the weights relative to the mesh's own
  // edges) the surface differs.
  deformable->SetReferenceEdgeLength(0.0);
  deformable->Update();
  EXPECT_NE(Coordinates(deformable->GetOutput()), Coordinates(filter->GetOutput()));
}
