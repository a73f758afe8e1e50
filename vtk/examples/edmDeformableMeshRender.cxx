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
//   cut in red) over the image slice y = 31 at iterations 0, 10, 50 and N (default 200), written to a PNG
//   (default DeformableMesh.png);
// - with --series: every K-th iteration (default 10) as .vtp plus a .pvd.
// The program checks the known answer: the mean distance of the final mesh to
// the true ellipsoid is below 0.5 voxel.

#include "edmMeshBridge.h"
#include "edmRenderingCommon.h"
#include "vtkDeformableMesh.h"
#include "vtkIterationSeriesWriter.h"

#include "itkEllipsoidPhantom.h"
#include "itkExternalForceImageFilter.h"

#include "vtkActor.h"
#include "vtkCallbackCommand.h"
#include "vtkCamera.h"
#include "vtkCoordinate.h"
#include "vtkCutter.h"
#include "vtkImageActor.h"
#include "vtkImageData.h"
#include "vtkImageMapper3D.h"
#include "vtkImageProperty.h"
#include "vtkPlane.h"
#include "vtkPolyData.h"
#include "vtkPolyDataMapper.h"
#include "vtkProperty.h"
#include "vtkRenderWindowInteractor.h"
#include "vtkRenderer.h"
#include "vtkSphereSource.h"
#include "vtkTextActor.h"
#include "vtkTextProperty.h"

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

/** The slice y = Center of the image, with the mesh's wireframe and its cut
 * by the slice plane, labelled with the iteration. */
vtkTextActor *
AddView(vtkRenderer * renderer, vtkImageData * image, vtkPolyData * mesh, int iteration)
{
  vtkNew<vtkImageActor> slice;
  slice->GetMapper()->SetInputData(image);
  slice->SetDisplayExtent(0, 63, 31, 31, 0, 63);
  slice->GetProperty()->SetColorWindow(400.0);
  slice->GetProperty()->SetColorLevel(100.0);
  renderer->AddViewProp(slice);

  vtkNew<vtkPolyDataMapper> wireMapper;
  wireMapper->SetInputData(mesh);
  wireMapper->ScalarVisibilityOff();
  vtkNew<vtkActor> wire;
  wire->SetMapper(wireMapper);
  wire->GetProperty()->SetRepresentationToWireframe();
  wire->GetProperty()->SetColor(0.3, 0.6, 1.0);
  wire->GetProperty()->SetOpacity(0.25);
  wire->GetProperty()->LightingOff(); // Flat colours: lines have no meaningful normals.
  renderer->AddActor(wire);

  vtkNew<vtkPlane> plane;
  plane->SetOrigin(Center, 31.0, Center);
  plane->SetNormal(0.0, 1.0, 0.0);
  vtkNew<vtkCutter> cutter;
  cutter->SetInputData(mesh);
  cutter->SetCutFunction(plane);
  vtkNew<vtkPolyDataMapper> cutMapper;
  cutMapper->SetInputConnection(cutter->GetOutputPort());
  cutMapper->ScalarVisibilityOff();
  vtkNew<vtkActor> cut;
  cut->SetMapper(cutMapper);
  cut->GetProperty()->SetColor(1.0, 0.2, 0.1);
  cut->GetProperty()->SetLineWidth(3.0);
  cut->GetProperty()->LightingOff();
  // In front of everything: the parallel projection along y does not show
  // the shift.
  cut->SetPosition(0.0, -64.0, 0.0);
  renderer->AddActor(cut);

  vtkNew<vtkTextActor> label;
  label->SetInput(("iteration " + std::to_string(iteration)).c_str());
  label->GetTextProperty()->SetFontSize(22);
  label->GetTextProperty()->SetColor(1.0, 1.0, 1.0);
  label->GetPositionCoordinate()->SetCoordinateSystemToNormalizedViewport();
  label->SetPosition(0.03, 0.03);
  renderer->AddActor2D(label);

  renderer->SetBackground(0.1, 0.1, 0.2);
  vtkCamera * camera = renderer->GetActiveCamera();
  // Looking along +y at the slice, z up: the cut of the mesh (red) over the
  // ellipse of the image, the mesh's wireframe (blue) for its shape.
  camera->ParallelProjectionOn();
  camera->SetFocalPoint(Center, Center, Center);
  camera->SetPosition(Center, Center - 200.0, Center);
  camera->SetViewUp(0.0, 0.0, 1.0);
  renderer->ResetCamera();
  camera->SetParallelScale(34.0);
  return label;
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

  vtkNew<vtkRenderWindow> window;
  window->SetWindowName("DeformableMesh");
  if (interactive)
  {
    deformable->SetNumberOfIterations(0);
    deformable->Update();
    vtkNew<vtkRenderer> renderer;
    vtkTextActor *      label = AddView(renderer, intensity, deformable->GetOutput(), 0);
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

  if (!HasDisplay() && !CanRenderWithoutDisplay(window))
  {
    std::cerr << "No display, and this VTK renders through X only: run under xvfb-run." << std::endl;
    return SkipExitCode;
  }
  window->SetOffScreenRendering(1);
  window->SetSize(1000, 1000);
  const double viewports[4][4] = {
    { 0.0, 0.5, 0.5, 1.0 }, { 0.5, 0.5, 1.0, 1.0 }, { 0.0, 0.0, 0.5, 0.5 }, { 0.5, 0.0, 1.0, 0.5 }
  };
  for (int k = 0; k < 4; ++k)
  {
    vtkNew<vtkRenderer> renderer;
    renderer->SetViewport(viewports[k]);
    AddView(renderer, intensity, meshes[k], snapshots[k]);
    window->AddRenderer(renderer);
  }
  if (!WritePNG(window, png.empty() ? "DeformableMesh.png" : png))
  {
    return EXIT_FAILURE;
  }

  if (!(finalDistance < 0.5))
  {
    std::cerr << "The mesh did not reach the ellipsoid: mean distance " << finalDistance << " voxel." << std::endl;
    return EXIT_FAILURE;
  }
  return EXIT_SUCCESS;
}
