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

// The seed paper's DeformableMesh example and its Figure 1: a UV sphere
// deforms onto an ellipsoid of radii (18, 14, 28) centred in a 64^3 volume.
// The force field is itk::ExternalForceImageFilter's (gradient of the
// smoothed gradient magnitude, with gradient vector flow for a capture range
// that reaches the ends of the long axis), handed to vtkDeformableMesh as a
// vtkImageData.
//
// Usage: edmDeformableMeshRender [--png figure.png] [--iterations N]
//                                [--series dir/name.pvd [--interval K]]
//                                [--offscreen] [--exit-when-done]
// - with a display and no --png: an interactive window; a timer runs one more
//   iteration per frame up to N (IterateFromZero off), then the window stays
//   open for inspection (or closes with --exit-when-done);
// - otherwise: Figure 1 offscreen: four views of the mesh (wireframe, and its
//   cut in red) over the image slice y = 31 at iterations 0, 10, 50 and N
//   (default 200), written to a PNG (default DeformableMesh.png); the
//   composition is edm::WriteFigurePNG (vtk/rendering), shared with edmodel
//   demo;
// - with --series: every K-th iteration (default 10) as .vtp plus a .pvd.
// The program checks the known answer: the mean distance of the final mesh to
// the true ellipsoid is below 0.5 voxel.

#include "edmMeshBridge.h"
#include "edmRenderingCommon.h"
#include "vtkDeformableMesh.h"
#include "vtkIterationSeriesWriter.h"

#include "itkEllipsoidPhantom.h"
#include "itkExternalForceImageFilter.h"

#include "vtkCallbackCommand.h"
#include "vtkImageData.h"
#include "vtkPolyData.h"
#include "vtkRenderWindowInteractor.h"
#include "vtkRenderer.h"
#include "vtkSphereSource.h"
#include "vtkTextActor.h"

#include <array>
#include <chrono>
#include <string>
#include <vector>

namespace
{
using ImageType = itk::Image<float, 3>;
using ForceImageType = itk::Image<itk::CovariantVector<float, 3>, 3>;

constexpr double Center = 31.5;

itk::EllipsoidPhantom
MakeEllipsoid()
{
  itk::EllipsoidPhantom::PointType center;
  center.Fill(Center);
  itk::EllipsoidPhantom::VectorType radii;
  radii[0] = 18.0;
  radii[1] = 14.0;
  radii[2] = 28.0;
  return itk::EllipsoidPhantom(center, radii);
}

struct Animation
{
  vtkDeformableMesh * Deformable;
  vtkRenderWindow *   Window;
  vtkTextActor *      Label;
  int                 LastIteration;
  bool                ExitWhenDone;
};

void
NextFrame(vtkObject * caller, unsigned long, void * clientData, void *)
{
  auto * animation = static_cast<Animation *>(clientData);
  if (animation->Deformable->GetNumberOfIterations() >= animation->LastIteration)
  {
    if (animation->ExitWhenDone)
    {
      static_cast<vtkRenderWindowInteractor *>(caller)->TerminateApp();
    }
    return;
  }
  animation->Deformable->SetNumberOfIterations(animation->Deformable->GetNumberOfIterations() + 1);
  animation->Deformable->Update();
  animation->Label->SetInput(("iteration " + std::to_string(animation->Deformable->GetCurrentIteration())).c_str());
  animation->Window->Render();
}

double
MeanDistance(vtkPolyData * mesh)
{
  const auto ellipsoid = MakeEllipsoid();
  double     sum = 0.0;
  for (vtkIdType i = 0; i < mesh->GetNumberOfPoints(); ++i)
  {
    itk::EllipsoidPhantom::PointType p;
    mesh->GetPoint(i, p.GetDataPointer());
    sum += ellipsoid.DistanceToSurface(p);
  }
  return sum / mesh->GetNumberOfPoints();
}
} // namespace

int
main(int argc, char * argv[])
{
  using namespace edm::examples;
  const std::string png = Argument(argc, argv, "--png", "");
  const int         lastIteration = std::stoi(Argument(argc, argv, "--iterations", "200"));
  const std::string series = Argument(argc, argv, "--series", "");
  const int         interval = std::stoi(Argument(argc, argv, "--interval", "10"));
  const bool        interactive = png.empty() && HasDisplay() && !HasFlag(argc, argv, "--offscreen");
  if (lastIteration < 50)
  {
    std::cerr << "--iterations must be at least 50 (Figure 1 shows iterations 0, 10, 50 and the last)." << std::endl;
    return EXIT_FAILURE;
  }

  // The seed's volume: 64^3 unit voxels, the ellipsoid at 255 on 0.
  const auto             start = std::chrono::steady_clock::now();
  ImageType::SizeType    size;
  ImageType::SpacingType spacing;
  ImageType::PointType   origin;
  size.Fill(64);
  spacing.Fill(1.0);
  origin.Fill(0.0);
  const auto image =
    MakeEllipsoid().MakeImage<ImageType>(size, spacing, origin, ImageType::DirectionType::GetIdentity(), 255, 0);
  auto forces = itk::ExternalForceImageFilter<ImageType, ForceImageType>::New();
  forces->SetInput(image);
  forces->SetSigma(1.0);
  forces->UseGradientVectorFlowOn();
  forces->SetGradientVectorFlowIterations(300);
  forces->Update();
  auto         intensity = edm::ImageToImageData(image.GetPointer(), "Intensity");
  auto         forceField = edm::ImageToImageData(forces->GetOutput(), "Force");
  const double forceSeconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();

  vtkNew<vtkSphereSource> sphere;
  sphere->SetCenter(Center, Center, Center);
  sphere->SetRadius(16.0);
  sphere->SetThetaResolution(40);
  sphere->SetPhiResolution(40);
  sphere->SetOutputPointsPrecision(vtkAlgorithm::DOUBLE_PRECISION);

  vtkNew<vtkDeformableMesh> deformable;
  deformable->SetInputConnection(sphere->GetOutputPort());
  deformable->SetForceImageData(forceField);
  deformable->SetInputArrayToProcess(0, 1, 0, vtkDataObject::FIELD_ASSOCIATION_POINTS, "Force");
  deformable->SetScaleFactor(0.5);
  deformable->SetElasticity(0.2);
  deformable->IterateFromZeroOff();

  if (interactive)
  {
    vtkNew<vtkRenderWindow> window;
    window->SetWindowName("DeformableMesh");
    deformable->SetNumberOfIterations(0);
    deformable->Update();
    vtkNew<vtkRenderer> renderer;
    vtkTextActor *      label = edm::AddFigureView(renderer, intensity, deformable->GetOutput(), 0);
    window->AddRenderer(renderer);
    window->SetSize(700, 700);
    vtkNew<vtkRenderWindowInteractor> interactor;
    interactor->SetRenderWindow(window);
    window->Render();
    Animation animation{ deformable, window, label, lastIteration, HasFlag(argc, argv, "--exit-when-done") };
    vtkNew<vtkCallbackCommand> frame;
    frame->SetCallback(NextFrame);
    frame->SetClientData(&animation);
    interactor->AddObserver(vtkCommand::TimerEvent, frame);
    interactor->Initialize();
    interactor->CreateRepeatingTimer(20);
    interactor->Start();
    const double distance = MeanDistance(deformable->GetOutput());
    std::cout << "iteration " << deformable->GetCurrentIteration() << ": mean distance to the ellipsoid " << distance
              << " voxel" << std::endl;
    return deformable->GetCurrentIteration() == lastIteration && distance < 0.5 ? EXIT_SUCCESS : EXIT_FAILURE;
  }

  // Figure 1: the mesh at iterations 0, 10, 50 and the last, one more step
  // at a time from one snapshot to the next.
  const std::array<int, 4>                  snapshots = { 0, 10, 50, lastIteration };
  std::vector<vtkSmartPointer<vtkPolyData>> meshes;
  for (const int iteration : snapshots)
  {
    deformable->SetNumberOfIterations(iteration);
    deformable->Update();
    if (deformable->GetOutput()->GetNumberOfPoints() == 0)
    {
      std::cerr << "The deformation failed at iteration " << iteration << "." << std::endl;
      return EXIT_FAILURE;
    }
    auto copy = vtkSmartPointer<vtkPolyData>::New();
    copy->DeepCopy(deformable->GetOutput());
    meshes.push_back(copy);
    std::cout << "iteration " << deformable->GetCurrentIteration() << ": mean distance to the ellipsoid "
              << MeanDistance(copy) << " voxel" << std::endl;
  }
  const double finalDistance = MeanDistance(meshes.back());
  std::cout << "forces in " << forceSeconds << " s; " << sphere->GetOutput()->GetNumberOfPoints() << " vertices"
            << std::endl;

  if (!series.empty())
  {
    vtkNew<vtkIterationSeriesWriter> writer;
    writer->SetAlgorithm(deformable);
    writer->SetFileName(series.c_str());
    writer->SetInterval(interval);
    writer->SetNumberOfIterations(lastIteration);
    if (!writer->Write())
    {
      return EXIT_FAILURE;
    }
    std::cout << "Wrote " << writer->GetNumberOfWrittenFiles() << " iterations and " << series << std::endl;
  }

  const std::string whyNot = edm::WhyNoOffscreenRendering();
  if (!whyNot.empty())
  {
    std::cerr << "No Figure 1: " << whyNot << "." << std::endl;
    return SkipExitCode;
  }
  const std::string          fileName = png.empty() ? "DeformableMesh.png" : png;
  std::vector<vtkPolyData *> views;
  for (const auto & mesh : meshes)
  {
    views.push_back(mesh);
  }
  std::string error;
  if (!edm::WriteFigurePNG(intensity, views, std::vector<int>(snapshots.begin(), snapshots.end()), fileName, error))
  {
    std::cerr << "No Figure 1: " << error << std::endl;
    return EXIT_FAILURE;
  }
  std::cout << "Wrote " << fileName << std::endl;

  if (!(finalDistance < 0.5))
  {
    std::cerr << "The mesh did not reach the ellipsoid: mean distance " << finalDistance << " voxel." << std::endl;
    return EXIT_FAILURE;
  }
  return EXIT_SUCCESS;
}
