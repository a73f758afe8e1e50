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

// Checks that a PNG written by a rendering example exists and is not blank:
// in the whole image, and with --quadrants in each quarter of it (Figure 1),
// at least 2 % of the pixels differ from the background colour (the corner
// pixel) and at least 16 colours are used.
//
// Usage: edmCheckPNG file.png [--quadrants] [--width W --height H]

#include "vtkImageData.h"
#include "vtkNew.h"
#include "vtkPNGReader.h"

#include <algorithm>
#include <cstdlib>
#include <cstring>
#include <iostream>
#include <set>
#include <string>

namespace
{
bool
CheckRegion(vtkImageData * image, int x0, int x1, int y0, int y1, const char * name)
{
  const int components = image->GetNumberOfScalarComponents();
  auto      pixel = [&](int x, int y) {
    const auto * p = static_cast<const unsigned char *>(image->GetScalarPointer(x, y, 0));
    long         value = 0;
    for (int c = 0; c < std::min(components, 3); ++c)
    {
      value = value * 256 + p[c];
    }
    return value;
  };
  const long     background = pixel(x0, y0);
  long           different = 0;
  std::set<long> colours;
  for (int y = y0; y < y1; ++y)
  {
    for (int x = x0; x < x1; ++x)
    {
      const long value = pixel(x, y);
      different += value != background ? 1 : 0;
      if (colours.size() < 1000)
      {
        colours.insert(value);
      }
    }
  }
  const double fraction = static_cast<double>(different) / ((x1 - x0) * static_cast<double>(y1 - y0));
  std::cout << name << ": " << 100.0 * fraction << " % of the pixels differ from the background, " << colours.size()
            << (colours.size() >= 1000 ? "+" : "") << " colours" << std::endl;
  return fraction >= 0.02 && colours.size() >= 16;
}
} // namespace

int
main(int argc, char * argv[])
{
  if (argc < 2)
  {
    std::cerr << "Usage: " << argv[0] << " file.png [--quadrants]" << std::endl;
    return EXIT_FAILURE;
  }
  vtkNew<vtkPNGReader> reader;
  if (!reader->CanReadFile(argv[1]))
  {
    std::cerr << argv[1] << " does not exist or is not a PNG file." << std::endl;
    return EXIT_FAILURE;
  }
  reader->SetFileName(argv[1]);
  reader->Update();
  vtkImageData * image = reader->GetOutput();
  int            dimensions[3];
  image->GetDimensions(dimensions);
  std::cout << argv[1] << ": " << dimensions[0] << " x " << dimensions[1] << " pixels, "
            << image->GetNumberOfScalarComponents() << " components" << std::endl;
  if (dimensions[0] < 16 || dimensions[1] < 16 || image->GetScalarType() != VTK_UNSIGNED_CHAR)
  {
    std::cerr << "Unexpected image size or type." << std::endl;
    return EXIT_FAILURE;
  }
  bool ok = CheckRegion(image, 0, dimensions[0], 0, dimensions[1], "image");
  if (argc > 2 && std::strcmp(argv[2], "--quadrants") == 0)
  {
    const int w = dimensions[0] / 2;
    const int h = dimensions[1] / 2;
    ok = CheckRegion(image, 0, w, h, 2 * h, "top left") && ok;
    ok = CheckRegion(image, w, 2 * w, h, 2 * h, "top right") && ok;
    ok = CheckRegion(image, 0, w, 0, h, "bottom left") && ok;
    ok = CheckRegion(image, w, 2 * w, 0, h, "bottom right") && ok;
  }
  if (!ok)
  {
    std::cerr << argv[1] << " is blank." << std::endl;
    return EXIT_FAILURE;
  }
  return EXIT_SUCCESS;
}
