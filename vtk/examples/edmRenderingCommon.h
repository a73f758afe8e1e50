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
#ifndef edmRenderingCommon_h
#define edmRenderingCommon_h

// Small helpers shared by the rendering examples: command line, and display
// detection and PNG output from edmRendering (vtk/rendering).

#include "edmRendering.h"

#include "vtkNew.h"
#include "vtkRenderWindow.h"

#include <cstdlib>
#include <cstring>
#include <iostream>
#include <string>

namespace edm
{
namespace examples
{

/** Exit code that ctest reads as "skipped" (SKIP_RETURN_CODE). */
constexpr int SkipExitCode = 77;

/** The value following \a name on the command line, or \a fallback. */
inline std::string
Argument(int argc, char * argv[], const char * name, const std::string & fallback)
{
  for (int i = 1; i + 1 < argc; ++i)
  {
    if (std::strcmp(argv[i], name) == 0)
    {
      return argv[i + 1];
    }
  }
  return fallback;
}

inline bool
HasFlag(int argc, char * argv[], const char * name)
{
  for (int i = 1; i < argc; ++i)
  {
    if (std::strcmp(argv[i], name) == 0)
    {
      return true;
    }
  }
  return false;
}

using edm::CanRenderWithoutDisplay;
using edm::HasDisplay;

/** Renders \a window and writes it as a PNG file, with a message; false on
 * failure. */
inline bool
WritePNG(vtkRenderWindow * window, const std::string & fileName)
{
  if (!edm::WriteRenderWindowPNG(window, fileName))
  {
    std::cerr << "Cannot write " << fileName << std::endl;
    return false;
  }
  std::cout << "Wrote " << fileName << std::endl;
  return true;
}

} // namespace examples
} // namespace edm

#endif
