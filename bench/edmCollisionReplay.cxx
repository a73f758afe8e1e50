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
// Not built by CMake; compiled against one header or another:
//
//   g++ -O2 -std=gnu++17 -DNDEBUG -I<dir of itkSurfaceCollision.h> -Iinclude -isystem /usr/include/ITK-5.2 \
//     bench/edmCollisionReplay.cxx -o replay <the ITK libraries of edmBenchmark's link line>
//   ./replay record 100000 30 /tmp/t100k.bin && ./replay replay /tmp/t100k.bin 20

#include "itkSurfaceCollision.h"
#include "itkDeformableMeshFilter.h"
#include "itkEllipsoidPhantom.h"
#include "itkExternalForceImageFilter.h"
#include "itkMesh.h"
#include "itkTriangleCell.h"

#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <map>
#include <string>
#include <vector>

namespace
{
constexpr unsigned int Dimension = 3;
using ImageType = itk::Image<float, Dimension>;
using ForceImageType = itk::Image<itk::CovariantVector<float, Dimension>, Dimension>;
using MeshType = itk::Mesh<float, Dimension>;
using ModelType = itk::DeformableMeshFilter<MeshType, ForceImageType>;
using ForceFilterType = itk::ExternalForceImageFilter<ImageType, ForceImageType>;

// The benchmark's case (bench/edmBenchmark.cxx).
constexpr unsigned int MeshImageSize = 128;
constexpr double       PhantomScale = MeshImageSize / 64.0;

itk::EllipsoidPhantom
MakePhantom(double scale)
{
  itk::EllipsoidPhantom::PointType center;
  center.Fill(31.0 * scale);
  itk::EllipsoidPhantom::VectorType radii;
  radii[0] = 18.0 * scale;
  radii[1] = 14.0 * scale;
  radii[2] = 18.0 * scale;
  return itk::EllipsoidPhantom(center, radii);
}

ImageType::Pointer
MakePhantomImage(unsigned int size)
{
  ImageType::SizeType imageSize;
  imageSize.Fill(size);
  ImageType::SpacingType spacing;
  spacing.Fill(1.0);
  ImageType::PointType origin;
  origin.Fill(0.0);
  ImageType::DirectionType direction;
  direction.SetIdentity();
  return MakePhantom(size / 64.0).MakeImage<ImageType>(imageSize, spacing, origin, direction, 100.0f, 0.0f);
}

/** Force field of the mesh benchmarks, computed once. */
const ForceImageType *
MeshForceImage()
{
  static ForceImageType::Pointer field = [] {
    auto forces = ForceFilterType::New();
    forces->SetInput(MakePhantomImage(MeshImageSize));
    forces->SetSigma(1.0);
    forces->Update();
    ForceImageType::Pointer output = forces->GetOutput();
    output->DisconnectPipeline();
    return output;
  }();
  return field;
}

/** Geodesic sphere: the octahedron |i| + |j| + |k| = n on the integer lattice,
 * each face cut into n^2 triangles, projected on the sphere; 4 n^2 + 2
 * vertices, 8 n^2 triangles, outward orientation, vertices numbered face by
 * face so that neighbours are mostly close in memory. */
struct SphereGeometry
{
  std::vector<double>   points;    // x, y, z
  std::vector<uint32_t> triangles; // a, b, c
};

SphereGeometry
MakeGeodesicSphere(unsigned int n, double radius, double centre)
{
  const int64_t         side = 2 * static_cast<int64_t>(n) + 1;
  std::vector<uint32_t> ids(static_cast<std::size_t>(side * side * 2), UINT32_MAX);
  SphereGeometry        sphere;
  auto                  vertex = [&](int64_t i, int64_t j, int64_t k) {
    const std::size_t key = static_cast<std::size_t>(((i + n) * side + (j + n)) * 2 + (k < 0 ? 1 : 0));
    if (ids[key] == UINT32_MAX)
    {
      ids[key] = static_cast<uint32_t>(sphere.points.size() / 3);
      const double length = std::sqrt(static_cast<double>(i * i + j * j + k * k));
      sphere.points.push_back(centre + radius * static_cast<double>(i) / length);
      sphere.points.push_back(centre + radius * static_cast<double>(j) / length);
      sphere.points.push_back(centre + radius * static_cast<double>(k) / length);
    }
    return ids[key];
  };
  const int64_t m = n;
  for (int sz = -1; sz <= 1; sz += 2)
  {
    for (int sy = -1; sy <= 1; sy += 2)
    {
      for (int sx = -1; sx <= 1; sx += 2)
      {
        const bool flip = sx * sy * sz < 0; // a reflection reverses the orientation
        auto       add = [&](int64_t a0, int64_t b0, int64_t a1, int64_t b1, int64_t a2, int64_t b2) {
          const uint32_t p = vertex(sx * a0, sy * b0, sz * (m - a0 - b0));
          const uint32_t q = vertex(sx * a1, sy * b1, sz * (m - a1 - b1));
          const uint32_t r = vertex(sx * a2, sy * b2, sz * (m - a2 - b2));
          sphere.triangles.insert(sphere.triangles.end(), { p, flip ? r : q, flip ? q : r });
        };
        for (int64_t a = 0; a < m; ++a)
        {
          for (int64_t b = 0; a + b < m; ++b)
          {
            add(a, b, a + 1, b, a, b + 1);
            if (a + b + 2 <= m)
            {
              add(a + 1, b, a + 1, b + 1, a, b + 1);
            }
          }
        }
      }
    }
  }
  return sphere;
}

/** Lattice size n of the geodesic sphere with about \a vertices vertices. */
unsigned int
SphereFrequency(int64_t vertices)
{
  return static_cast<unsigned int>(std::lround(std::sqrt((vertices - 2) / 4.0)));
}

template <typename TMesh>
typename TMesh::Pointer
ToITKMesh(const SphereGeometry & sphere)
{
  auto              mesh = TMesh::New();
  const std::size_t numberOfPoints = sphere.points.size() / 3;
  auto              points = TMesh::PointsContainer::New();
  points->Reserve(numberOfPoints);
  for (std::size_t i = 0; i < numberOfPoints; ++i)
  {
    typename TMesh::PointType & p = points->ElementAt(i);
    for (unsigned int d = 0; d < 3; ++d)
    {
      p[d] = static_cast<typename TMesh::CoordRepType>(sphere.points[3 * i + d]);
    }
  }
  mesh->SetPoints(points);
  using CellType = typename TMesh::CellType;
  using TriangleType = itk::TriangleCell<CellType>;
  const std::size_t numberOfTriangles = sphere.triangles.size() / 3;
  for (std::size_t t = 0; t < numberOfTriangles; ++t)
  {
    typename CellType::CellAutoPointer cell;
    cell.TakeOwnership(new TriangleType);
    for (unsigned int k = 0; k < 3; ++k)
    {
      cell->SetPointId(k, sphere.triangles[3 * t + k]);
    }
    mesh->SetCell(t, cell);
  }
  return mesh;
}

constexpr double InitialRadius = 16.0 * PhantomScale;
constexpr double MeshCentre = 31.0 * PhantomScale;

/** Input mesh of our filter, about \a vertices vertices, cached. */
const MeshType *
ModelMesh(int64_t vertices)
{
  static std::map<int64_t, MeshType::Pointer> cache;
  auto &                                      mesh = cache[vertices];
  if (mesh.IsNull())
  {
    mesh = ToITKMesh<MeshType>(MakeGeodesicSphere(SphereFrequency(vertices), InitialRadius, MeshCentre));
  }
  return mesh;
}


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
