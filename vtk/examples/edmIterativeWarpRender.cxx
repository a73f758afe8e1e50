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

// The seed paper's IterativeWarp example: a point cloud (vtkPointSource)
// walks at random, one iteration of vtkPolyDataIterativeWarp per frame, with
// IterateFromZero off so that each frame costs one step.
//
// Usage: edmIterativeWarpRender [--png file.png] [--iterations N]
//                               [--step-length s] [--seed k] [--offscreen]
// - with a display and no --png: an interactive window; a timer raises
//   NumberOfIterations by one and renders, until the window is closed (or N
//   iterations when --iterations is given);
// - otherwise: N iterations (default 100) offscreen, the cloud at iteration 0
//   (grey) and N (coloured by distance walked) written to a PNG
//   (default IterativeWarp.png).
// The program checks the known answer of a Brownian walk: after N steps of
// root mean square length s, the root mean square distance walked is
// s sqrt(N) (within 5 % for 2000 points).

#include "edmRenderingCommon.h"
#include "vtkPolyDataIterativeWarp.h"

#include "vtkActor.h"
#include "vtkCallbackCommand.h"
#include "vtkCamera.h"
#include "vtkDoubleArray.h"
#include "vtkPointData.h"
#include "vtkPointSource.h"
#include "vtkPolyData.h"
#include "vtkPolyDataMapper.h"
#include "vtkProperty.h"
#include "vtkRenderWindowInteractor.h"
#include "vtkRenderer.h"
#include "vtkTextActor.h"
#include "vtkTextProperty.h"

#include <cmath>
#include <string>

namespace
{
struct Animation
{
  vtkPolyDataIterativeWarp * Warp;
  vtkRenderWindow *          Window;
  vtkTextActor *             Label;
  int                        LastIteration;
};

void
NextFrame(vtkObject * caller, unsigned long, void * clientData, void *)
{
  auto * animation = static_cast<Animation *>(clientData);
  if (animation->LastIteration > 0 && animation->Warp->GetNumberOfIterations() >= animation->LastIteration)
  {
    static_cast<vtkRenderWindowInteractor *>(caller)->TerminateApp();
    return;
  }
  animation->Warp->SetNumberOfIterations(animation->Warp->GetNumberOfIterations() + 1);
  animation->Warp->Update();
  animation->Label->SetInput(("iteration " + std::to_string(animation->Warp->GetCurrentIteration())).c_str());
  animation->Window->Render();
}

double
RootMeanSquareDistance(vtkPolyData * a, vtkPolyData * b)
{
  double sum = 0.0;
  for (vtkIdType i = 0; i < a->GetNumberOfPoints(); ++i)
  {
    double p[3];
    double q[3];
    a->GetPoint(i, p);
    b->GetPoint(i, q);
    sum += (p[0] - q[0]) * (p[0] - q[0]) + (p[1] - q[1]) * (p[1] - q[1]) + (p[2] - q[2]) * (p[2] - q[2]);
  }
  return std::sqrt(sum / a->GetNumberOfPoints());
}
} // namespace

int
main(int argc, char * argv[])
{
  using namespace edm::examples;
  const std::string png = Argument(argc, argv, "--png", "");
  const int         requested = std::stoi(Argument(argc, argv, "--iterations", "0"));
  const double      stepLength = std::stod(Argument(argc, argv, "--step-length", "0.01"));
  const int         seed = std::stoi(Argument(argc, argv, "--seed", "0"));
  const bool        interactive = png.empty() && HasDisplay() && !HasFlag(argc, argv, "--offscreen");

  vtkNew<vtkPointSource> cloud;
  cloud->SetNumberOfPoints(2000);
  cloud->SetRadius(0.5);
  cloud->SetDistributionToUniform();
  cloud->SetOutputPointsPrecision(vtkAlgorithm::DOUBLE_PRECISION);
  cloud->Update();

  vtkNew<vtkPolyDataIterativeWarp> warp;
  warp->SetInputConnection(cloud->GetOutputPort());
  warp->SetStepLength(stepLength);
  warp->SetSeed(seed);
  warp->IterateFromZeroOff();

  vtkNew<vtkPolyDataMapper> startMapper;
  startMapper->SetInputConnection(cloud->GetOutputPort());
  startMapper->ScalarVisibilityOff();
  vtkNew<vtkActor> start;
  start->SetMapper(startMapper);
  start->GetProperty()->SetColor(0.6, 0.6, 0.6);
  start->GetProperty()->SetPointSize(2.0);

  vtkNew<vtkPolyDataMapper> mapper;
  mapper->SetInputConnection(warp->GetOutputPort());
  mapper->ScalarVisibilityOff();
  vtkNew<vtkActor> walkers;
  walkers->SetMapper(mapper);
  walkers->GetProperty()->SetColor(0.9, 0.3, 0.1);
  walkers->GetProperty()->SetPointSize(3.0);

  vtkNew<vtkTextActor> label;
  label->GetTextProperty()->SetFontSize(20);
  label->GetTextProperty()->SetColor(1.0, 1.0, 1.0);
  label->SetDisplayPosition(10, 10);

  vtkNew<vtkRenderer> renderer;
  renderer->AddActor(start);
  renderer->AddActor(walkers);
  renderer->AddActor2D(label);
  renderer->SetBackground(0.1, 0.1, 0.2);
  vtkNew<vtkRenderWindow> window;
  window->AddRenderer(renderer);
  window->SetSize(600, 600);
  window->SetWindowName("IterativeWarp");

  if (interactive)
  {
    vtkNew<vtkRenderWindowInteractor> interactor;
    interactor->SetRenderWindow(window);
    warp->SetNumberOfIterations(0);
    warp->Update();
    label->SetInput("iteration 0");
    renderer->ResetCamera();
    window->Render();
    Animation                  animation{ warp, window, label, requested };
    vtkNew<vtkCallbackCommand> frame;
    frame->SetCallback(NextFrame);
    frame->SetClientData(&animation);
    interactor->AddObserver(vtkCommand::TimerEvent, frame);
    interactor->Initialize();
    interactor->CreateRepeatingTimer(30);
    interactor->Start();
    std::cout << "Stopped at iteration " << warp->GetCurrentIteration() << std::endl;
    return requested == 0 || warp->GetCurrentIteration() == requested ? EXIT_SUCCESS : EXIT_FAILURE;
  }

  const std::string whyNot = edm::WhyNoOffscreenRendering();
  if (!whyNot.empty())
  {
    std::cerr << "No PNG: " << whyNot << "." << std::endl;
    return SkipExitCode;
  }
  window->SetOffScreenRendering(1);
  const int iterations = requested > 0 ? requested : 100;
  warp->SetNumberOfIterations(iterations);
  warp->Update();
  label->SetInput(("iteration " + std::to_string(warp->GetCurrentIteration())).c_str());
  renderer->ResetCamera();
  renderer->GetActiveCamera()->Zoom(1.3);
  if (!WritePNG(window, png.empty() ? "IterativeWarp.png" : png))
  {
    return EXIT_FAILURE;
  }

  const double rms = RootMeanSquareDistance(cloud->GetOutput(), warp->GetOutput());
  const double expected = stepLength * std::sqrt(static_cast<double>(iterations));
  std::cout << "RMS distance walked after " << iterations << " iterations: " << rms << " (expected " << expected << ")"
            << std::endl;
  if (warp->GetCurrentIteration() != iterations || std::abs(rms - expected) > 0.05 * expected)
  {
    std::cerr << "The walk does not have the expected length." << std::endl;
    return EXIT_FAILURE;
  }
  return EXIT_SUCCESS;
}
