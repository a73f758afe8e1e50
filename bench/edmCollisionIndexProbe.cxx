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

// A probe of SurfaceCollision's two costs on a geodesic sphere of radius 40
// (MakeSphereMesh, resolution N: 4^N x 4 + 2 points), one thread: a rebuild
// of the index (best of 5, Invalidate() then Constrain() with y = x) and a
// step that keeps the index (best of 200, every coordinate moved by a
// Gaussian of 0.01 mm, the same displacement each time), in ns of process
// CPU time per point.
// Built by CMake (a ctest runs it at resolution 4); to compare two
// versions of the index (docs/performance.md), compile it against one
// header or the other:
//
//   g++ -O2 -std=c++17 -I<dir of itkSurfaceCollision.h> -Iinclude -I/usr/include/ITK-5.2 \
//     bench/edmCollisionIndexProbe.cxx -o probe -lITKCommon-5.2 && ./probe 7

#include "itkSurfaceCollision.h"
#include "itkEllipsoidPhantom.h"
#include "itkMesh.h"

#include <cstdlib>
#include <ctime>
#include <iostream>
#include <random>

int
main(int argc, char * argv[])
{
  using MeshType = itk::Mesh<double, 3>;
  const unsigned int  resolution = argc > 1 ? static_cast<unsigned int>(std::atoi(argv[1])) : 7;
  MeshType::PointType centre;
  centre.Fill(0.0);
  const auto            mesh = itk::MakeSphereMesh<MeshType>(centre, 40.0, resolution);
  std::vector<double>   x;
  std::vector<uint32_t> triangles;
  for (auto it = mesh->GetPoints()->Begin(); it != mesh->GetPoints()->End(); ++it)
  {
    for (unsigned int k = 0; k < 3; ++k)
    {
      x.push_back(it.Value()[k]);
    }
  }
  itk::SurfaceCollision::ExtractTriangles(mesh.GetPointer(), triangles);
  const auto            points = static_cast<double>(x.size() / 3);
  itk::SurfaceCollision collision;
  collision.SetSurface(x.size() / 3, triangles.data(), triangles.size() / 3);
  // Process CPU time, not wall clock: the machine is shared, and a
  // waiting process would count the others' work.
  const auto seconds = [](std::clock_t start) { return static_cast<double>(std::clock() - start) / CLOCKS_PER_SEC; };

  std::vector<double> y;
  double              rebuild = 1e30;
  for (unsigned int r = 0; r < 5; ++r)
  {
    collision.Invalidate();
    y = x;
    const std::clock_t start = std::clock();
    collision.Constrain(x.data(), y.data(), 0.0, nullptr, 1);
    rebuild = std::min(rebuild, seconds(start));
  }
  std::mt19937                     random(1);
  std::normal_distribution<double> gaussian(0.0, 0.01);
  std::vector<double>              moved = x;
  for (auto & c : moved)
  {
    c += gaussian(random);
  }
  double step = 1e30;
  for (unsigned int r = 0; r < 200; ++r)
  {
    y = moved;
    const std::clock_t start = std::clock();
    const auto         result = collision.Constrain(x.data(), y.data(), 0.0, nullptr, 1);
    if (!result.rebuilt)
    {
      step = std::min(step, seconds(start));
    }
  }
  std::cout << "points " << points << ", candidate pairs " << collision.GetNumberOfCandidatePairs() << ": rebuild "
            << rebuild * 1e9 / points << " ns per point, step keeping the index " << step * 1e9 / points
            << " ns per point (" << collision.GetNumberOfTestedTriangles() << " triangles tested)" << std::endl;
  return EXIT_SUCCESS;
}
