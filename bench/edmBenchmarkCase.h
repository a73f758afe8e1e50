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
#ifndef edmBenchmarkCase_h
#define edmBenchmarkCase_h

// The case the mesh benchmarks run, in one place for the programs of bench/
// (edmBenchmark, and edmCollisionReplay, which records and replays its
// trajectories): the ellipsoid phantom, its force field, and the geodesic
// spheres of about 10k, 100k and 1M vertices the filter starts from.

#include "itkDeformableMeshFilter.h"
#include "itkEllipsoidPhantom.h"
#include "itkExternalForceImageFilter.h"
#include "itkMesh.h"
#include "itkTriangleCell.h"

#include <cmath>
#include <cstdint>
#include <map>
#include <vector>

namespace edm
{
namespace bench
{
constexpr unsigned int Dimension = 3;
using ImageType = itk::Image<float, Dimension>;
using ForceImageType = itk::Image<itk::CovariantVector<float, Dimension>, Dimension>;
using MeshType = itk::Mesh<float, Dimension>;
using ModelType = itk::DeformableMeshFilter<MeshType, ForceImageType>;
using ForceFilterType = itk::ExternalForceImageFilter<ImageType, ForceImageType>;

// The seed's case (64^3 voxels, ellipsoid of radii (18, 14, 18) centred at
// voxel 31, initial sphere of radius 16), scaled by 2; unit spacing and zero
// origin, which DeformableSimplexMesh3DFilter requires.
constexpr unsigned int MeshImageSize = 128;
constexpr double       PhantomScale = MeshImageSize / 64.0;

inline itk::EllipsoidPhantom
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

inline ImageType::Pointer
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
inline const ForceImageType *
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

inline SphereGeometry
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
inline unsigned int
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
inline const MeshType *
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
} // namespace bench
} // namespace edm

#endif
