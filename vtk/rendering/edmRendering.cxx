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

#include "edmRendering.h"

#include "vtkActor.h"
#include "vtkCamera.h"
#include "vtkCoordinate.h"
#include "vtkCutter.h"
#include "vtkImageActor.h"
#include "vtkImageData.h"
#include "vtkImageMapper3D.h"
#include "vtkImageProperty.h"
#include "vtkNew.h"
#include "vtkPNGWriter.h"
#include "vtkPlane.h"
#include "vtkPolyData.h"
#include "vtkPolyDataMapper.h"
#include "vtkProperty.h"
#include "vtkRenderWindow.h"
#include "vtkRenderer.h"
#include "vtkTextActor.h"
#include "vtkTextProperty.h"
#include "vtkWindowToImageFilter.h"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <thread>

#ifdef EDM_HAVE_XLIB
// Last: Xlib defines macros (None, Status, Bool) that VTK headers also use.
#  include <X11/Xlib.h>
#endif

namespace edm
{

bool
HasDisplay()
{
  const char * display = std::getenv("DISPLAY");
  return display != nullptr && display[0] != '\0';
}

bool
CanRenderWithoutDisplay(vtkRenderWindow * window)
{
  const std::string name = window->GetClassName();
  return name != "vtkXOpenGLRenderWindow";
}

std::string
WhyNoOffscreenRendering()
{
  vtkNew<vtkRenderWindow> window; // The factory's class; no display is opened.
  if (CanRenderWithoutDisplay(window))
  {
    return std::string();
  }
  if (!HasDisplay())
  {
    return "no X display (DISPLAY is not set) and this VTK renders through X only, offscreen included: run under "
           "xvfb-run -a";
  }
#ifdef EDM_HAVE_XLIB
  // VTK aborts the program when it cannot open the display: try first. A
  // display that xvfb-run has just started may refuse connections for a
  // moment on a loaded machine (seen in CI): retry for up to 10 s.
  Display * display = XOpenDisplay(nullptr);
  for (int attempt = 0; display == nullptr && attempt < 50; ++attempt)
  {
    std::this_thread::sleep_for(std::chrono::milliseconds(200));
    display = XOpenDisplay(nullptr);
  }
  if (display == nullptr)
  {
    return "cannot open the X display '" + std::string(std::getenv("DISPLAY")) +
           "' and this VTK renders through X only, offscreen included: run under xvfb-run -a";
  }
  // The connection stays open until the program exits: an X server started
  // without -noreset (xvfb-run's default) resets when its last client
  // disconnects and drops a client that connects during the reset, which
  // would be VTK's render window right after this probe (VTK then aborts).
  static const std::unique_ptr<Display, int (*)(Display *)> probe(display, XCloseDisplay);
  if (probe.get() != display)
  {
    XCloseDisplay(display); // An earlier probe holds the connection.
  }
#endif
  return std::string();
}

bool
WriteRenderWindowPNG(vtkRenderWindow * window, const std::string & fileName)
{
  std::remove(fileName.c_str()); // No stale image left behind on failure.
  window->Render();
  vtkNew<vtkWindowToImageFilter> grab;
  grab->SetInput(window);
  grab->SetInputBufferTypeToRGB();
  grab->ReadFrontBufferOff();
  grab->Update();
  vtkNew<vtkPNGWriter> writer;
  writer->SetFileName(fileName.c_str());
  writer->SetInputConnection(grab->GetOutputPort());
  writer->Write();
  return writer->GetErrorCode() == 0;
}

vtkTextActor *
AddFigureView(vtkRenderer * renderer, vtkImageData * image, vtkPolyData * mesh, int iteration)
{
  int    extent[6];
  double bounds[6];
  double range[2];
  image->GetExtent(extent);
  image->GetBounds(bounds);
  image->GetScalarRange(range);
  const double center[3] = { 0.5 * (bounds[0] + bounds[1]),
                             0.5 * (bounds[2] + bounds[3]),
                             0.5 * (bounds[4] + bounds[5]) };
  const int    sliceIndex = extent[2] + (extent[3] - extent[2]) / 2;
  const double sliceY = image->GetOrigin()[1] + sliceIndex * image->GetSpacing()[1];
  const double depth = bounds[3] - bounds[2] + image->GetSpacing()[1];
  const double width = std::max(bounds[1] - bounds[0], bounds[5] - bounds[4]);

  vtkNew<vtkImageActor> slice;
  slice->GetMapper()->SetInputData(image);
  slice->SetDisplayExtent(extent[0], extent[1], sliceIndex, sliceIndex, extent[4], extent[5]);
  // The background at a quarter grey, the object at nine tenths.
  const double intensities = range[1] > range[0] ? range[1] - range[0] : 1.0;
  slice->GetProperty()->SetColorWindow(intensities * 400.0 / 255.0);
  slice->GetProperty()->SetColorLevel(range[0] + intensities * 100.0 / 255.0);
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
  plane->SetOrigin(center[0], sliceY, center[2]);
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
  cut->SetPosition(0.0, -depth, 0.0);
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
  // section of the image, the mesh's wireframe (blue) for its shape.
  camera->ParallelProjectionOn();
  camera->SetFocalPoint(center[0], center[1], center[2]);
  camera->SetPosition(center[0], center[1] - 3.0 * depth, center[2]);
  camera->SetViewUp(0.0, 0.0, 1.0);
  renderer->ResetCamera();
  camera->SetParallelScale(0.54 * width);
  return label;
}

bool
WriteFigurePNG(vtkImageData *                     image,
               const std::vector<vtkPolyData *> & meshes,
               const std::vector<int> &           iterations,
               const std::string &                fileName,
               std::string &                      error,
               int                                size)
{
  if (meshes.empty() || meshes.size() > 4 || meshes.size() != iterations.size())
  {
    error = "Figure 1 takes one to four meshes, each with its iteration";
    return false;
  }
  error = WhyNoOffscreenRendering();
  if (!error.empty())
  {
    return false;
  }
  vtkNew<vtkRenderWindow> window;
  window->SetOffScreenRendering(1);
  window->SetSize(size, size);
  // Reading order: top left, top right, bottom left, bottom right.
  const double viewports[4][4] = {
    { 0.0, 0.5, 0.5, 1.0 }, { 0.5, 0.5, 1.0, 1.0 }, { 0.0, 0.0, 0.5, 0.5 }, { 0.5, 0.0, 1.0, 0.5 }
  };
  for (size_t k = 0; k < meshes.size(); ++k)
  {
    vtkNew<vtkRenderer> renderer;
    renderer->SetViewport(viewports[k]);
    AddFigureView(renderer, image, meshes[k], iterations[k]);
    window->AddRenderer(renderer);
  }
  if (!WriteRenderWindowPNG(window, fileName))
  {
    error = "the PNG writer failed on '" + fileName + "'";
    return false;
  }
  return true;
}

} // namespace edm
