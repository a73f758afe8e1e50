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

// Records and replays the collision test's trajectories, so that versions
// of SurfaceCollision can be compared on the motion of the benchmark's
// BM_EDM_SelfIntersection (docs/performance.md), one thread, process CPU
// time:
//
//   record V STEPS FILE  runs DeformableMeshFilter with PreventSelfIntersections
//                        on the benchmark's case (geodesic sphere of about V
//                        vertices in the 128^3 ellipsoid phantom, Elasticity
//                        0.3, Rigidity 0.1, 2 threads) and writes the input
//                        and the points after each of STEPS iterations;
//   replay FILE [STEPS]  calls SurfaceCollision::Constrain(x_k, x_k+1) for
//                        the recorded steps (minimum distance 0) and prints
//                        the CPU time per vertex-step, the rebuilds and the
//                        sums of candidate pairs and tested triangles (equal
//                        sums: the same index decisions).
//
// Built by CMake (bench/CMakeLists.txt registers a short record and
// replay with ctest); to compare two versions of the header, compile it
// against one or the other:
//
//   g++ -O2 -std=gnu++17 -DNDEBUG -I<dir of itkSurfaceCollision.h> -Iinclude -isystem /usr/include/ITK-5.2 \
//     bench/edmCollisionReplay.cxx -o replay <the ITK libraries of edmBenchmark's link line>
//   ./replay record 100000 30 /tmp/t100k.bin && ./replay replay /tmp/t100k.bin 20

#include "itkSurfaceCollision.h"
#include "edmBenchmarkCase.h"

#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <string>
#include <vector>

namespace
{
// The benchmark's case: edmBenchmarkCase.h.
using namespace edm::bench;

struct Frame
{
  std::vector<double>   x;
  std::vector<uint32_t> triangles;
};

void
Write(std::FILE * file, const MeshType * mesh)
{
  Frame frame;
  for (auto it = mesh->GetPoints()->Begin(); it != mesh->GetPoints()->End(); ++it)
  {
    for (unsigned int k = 0; k < 3; ++k)
    {
      frame.x.push_back(it.Value()[k]);
    }
  }
  itk::SurfaceCollision::ExtractTriangles(mesh, frame.triangles);
  const uint64_t sizes[2] = { frame.x.size() / 3, frame.triangles.size() / 3 };
  std::fwrite(sizes, sizeof(uint64_t), 2, file);
  std::fwrite(frame.x.data(), sizeof(double), frame.x.size(), file);
  std::fwrite(frame.triangles.data(), sizeof(uint32_t), frame.triangles.size(), file);
}

bool
Read(std::FILE * file, Frame & frame)
{
  uint64_t sizes[2];
  if (std::fread(sizes, sizeof(uint64_t), 2, file) != 2)
  {
    return false;
  }
  frame.x.resize(3 * sizes[0]);
  frame.triangles.resize(3 * sizes[1]);
  return std::fread(frame.x.data(), sizeof(double), frame.x.size(), file) == frame.x.size() &&
         std::fread(frame.triangles.data(), sizeof(uint32_t), frame.triangles.size(), file) == frame.triangles.size();
}

int
Record(int64_t vertices, unsigned int steps, const char * path)
{
  itk::MultiThreaderBase::SetGlobalDefaultNumberOfThreads(2);
  const MeshType * input = ModelMesh(vertices);
  auto             model = ModelType::New();
  model->SetInput(input);
  model->SetForceImage(MeshForceImage());
  model->SetScaleFactor(0.5);
  model->SetElasticity(0.3);
  model->SetRigidity(0.1);
  model->SetNumberOfWorkUnits(8);
  model->SetPreventSelfIntersections(true);
  model->SetNumberOfIterations(steps);
  std::FILE * file = std::fopen(path, "wb");
  if (file == nullptr)
  {
    std::fprintf(stderr, "cannot write %s\n", path);
    return EXIT_FAILURE;
  }
  Write(file, input);
  model->AddObserver(itk::IterationEvent(), [&](const itk::EventObject &) { Write(file, model->GetOutput()); });
  model->Update();
  std::fclose(file);
  std::printf("%u steps recorded, %lu collisions prevented\n",
              steps,
              static_cast<unsigned long>(model->GetTotalNumberOfCollisionsPrevented()));
  return EXIT_SUCCESS;
}

int
Replay(const char * path, unsigned int maximumSteps)
{
  std::FILE * file = std::fopen(path, "rb");
  Frame       current, next;
  if (file == nullptr || !Read(file, current))
  {
    std::fprintf(stderr, "cannot read a trajectory from %s\n", path);
    if (file != nullptr)
    {
      std::fclose(file);
    }
    return EXIT_FAILURE;
  }
  itk::SurfaceCollision collision;
  collision.SetSurface(current.x.size() / 3, current.triangles.data(), current.triangles.size() / 3);
  double        seconds = 0.0;
  unsigned int  steps = 0, rebuilds = 0;
  unsigned long candidates = 0, tested = 0, violations = 0;
  while (steps < maximumSteps && Read(file, next))
  {
    std::vector<double> y = next.x;
    const std::clock_t  start = std::clock();
    const auto          result = collision.Constrain(current.x.data(), y.data(), 0.0, nullptr, 1);
    seconds += static_cast<double>(std::clock() - start) / CLOCKS_PER_SEC;
    ++steps;
    rebuilds += result.rebuilt ? 1 : 0;
    candidates += collision.GetNumberOfCandidatePairs();
    tested += collision.GetNumberOfTestedTriangles();
    violations += result.violations;
    current.x.swap(next.x);
  }
  std::fclose(file);
  std::printf("%u steps, %u rebuilds, %.1f ns CPU per vertex-step (1 thread); sums: candidate pairs %lu, tested "
              "triangles %lu, violations %lu\n",
              steps,
              rebuilds,
              steps > 0 ? seconds * 1e9 / steps / static_cast<double>(current.x.size() / 3) : 0.0,
              candidates,
              tested,
              violations);
  return EXIT_SUCCESS;
}
} // namespace

int
main(int argc, char * argv[])
{
  const std::string mode = argc > 1 ? argv[1] : "";
  if (mode == "record" && argc == 5)
  {
    return Record(std::atoll(argv[2]), static_cast<unsigned int>(std::atoi(argv[3])), argv[4]);
  }
  if (mode == "replay" && argc >= 3)
  {
    return Replay(argv[2], argc > 3 ? static_cast<unsigned int>(std::atoi(argv[3])) : 1000000u);
  }
  std::fprintf(stderr, "usage: %s record VERTICES STEPS FILE | replay FILE [STEPS]\n", argv[0]);
  return EXIT_FAILURE;
}
