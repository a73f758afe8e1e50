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
#ifndef edmRendering_h
#define edmRendering_h

// Rendering shared by the examples and edmodel demo: display detection, PNG
// output of a render window, and the seed's Figure 1 (the mesh over a slice
// of the image at several iterations, one PNG).

#include <string>
#include <vector>

class vtkImageData;
class vtkPolyData;
class vtkRenderWindow;
class vtkRenderer;
class vtkTextActor;

namespace edm
{

/** True when an X display is available (DISPLAY set and not empty). */
bool
HasDisplay();

/** Whether this VTK can render without a display (EGL or OSMesa builds);
 * Debian's VTK renders through X only, offscreen included. */
bool
CanRenderWithoutDisplay(vtkRenderWindow * window);

/** Empty when offscreen rendering is possible here; otherwise one sentence
 * saying why not: no DISPLAY, or (with Xlib) an X display that cannot be
 * opened, for a VTK that renders through X only. */
std::string
WhyNoOffscreenRendering();

/** Renders \a window and writes it as a PNG file; false on failure. */
bool
WriteRenderWindowPNG(vtkRenderWindow * window, const std::string & fileName);

/** One view of Figure 1 in \a renderer: the slice of \a image through its
 * middle across y, looked at along +y with z up, the wireframe of \a mesh
 * (blue) and its cut by the slice plane (red), labelled "iteration N".
 * \a image has an identity direction; grey levels follow its scalar range.
 * Returns the label, for animations. */
vtkTextActor *
AddFigureView(vtkRenderer * renderer, vtkImageData * image, vtkPolyData * mesh, int iteration);

/** Figure 1: one view per mesh (at most four: iterations 0, 10, 50 and the
 * last in the seed) in a 2 x 2 grid, rendered offscreen in a \a size x
 * \a size window and written to \a fileName. False, with the reason in
 * \a error, when it cannot be rendered or written. */
bool
WriteFigurePNG(vtkImageData *                     image,
               const std::vector<vtkPolyData *> & meshes,
               const std::vector<int> &           iterations,
               const std::string &                fileName,
               std::string &                      error,
               int                                size = 1000);

} // namespace edm

#endif
