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

// The seed's DeformableMesh example: a sphere deforms onto an ellipsoid.
// Usage: DeformableMesh [output.vtk] [iterations]
// A 64^3 binary ellipsoid of radii (18, 14, 18) voxels centred at voxel
// (31, 31, 31); the initial model is a sphere of radius 16 at the same centre;
// forces from ExternalForceImageFilter. Writes the final mesh and checks that
// its mean distance to the true surface is at most 0.15 voxel (max 0.5).

#include "itkDeformableMeshFilter.h"
#include "itkEllipsoidPhantom.h"
#include "itkExternalForceImageFilter.h"
#include "itkMesh.h"
#include "itkMeshFileWriter.h"

#include <cstdlib>
#include <iostream>

int
main(int argc, char * argv[])
{
  const std::string  output = argc > 1 ? argv[1] : "DeformableMesh.vtk";
  const unsigned int iterations = argc > 2 ? static_cast<unsigned int>(std::atoi(argv[2])) : 500;

  constexpr unsigned int Dimension = 3;
  using ImageType = itk::Image<unsigned char, Dimension>;
  using ForceImageType = itk::Image<itk::CovariantVector<float, Dimension>, Dimension>;
  using MeshType = itk::Mesh<float, Dimension>;

  // The image: unit voxels, identity direction, origin at voxel (0, 0, 0).
  ImageType::SizeType size;
  size.Fill(64);
  ImageType::SpacingType spacing;
  spacing.Fill(1.0);
  ImageType::PointType origin;
  origin.Fill(0.0);
  itk::EllipsoidPhantom::PointType center;
  center.Fill(31.0);
  itk::EllipsoidPhantom::VectorType radii;
  radii[0] = 18.0;
  radii[1] = 14.0;
  radii[2] = 18.0;
  const itk::EllipsoidPhantom ellipsoid(center, radii);
  const auto image = ellipsoid.MakeImage<ImageType>(size, spacing, origin, ImageType::DirectionType::GetIdentity());

  // External forces: grad |grad (G_sigma * I)|, normalised to a largest length of 1.
  using ForceFilterType = itk::ExternalForceImageFilter<ImageType, ForceImageType>;
  auto forces = ForceFilterType::New();
  forces->SetInput(image);
  forces->SetSigma(1.0);

  MeshType::PointType meshCenter;
  meshCenter.CastFrom(center);
  const auto sphere = itk::MakeSphereMesh<MeshType>(meshCenter, 16.0, 4);

  using FilterType = itk::DeformableMeshFilter<MeshType, ForceImageType>;
  auto filter = FilterType::New();
  filter->SetInput(sphere);
  filter->SetForceImage(forces->GetOutput());
  filter->SetScaleFactor(0.5); // at most half a voxel per iteration
  filter->SetNumberOfIterations(iterations);
  try
  {
    filter->Update();
  }
  catch (const itk::ExceptionObject & e)
  {
    std::cerr << "DeformableMesh: " << e.GetDescription() << std::endl;
    return EXIT_FAILURE;
  }

  double meanDistance = 0.0;
  double maximumDistance = 0.0;
  ellipsoid.MeasureDistance(filter->GetOutput(), meanDistance, maximumDistance);
  double initialMean = 0.0;
  double initialMaximum = 0.0;
  ellipsoid.MeasureDistance(sphere.GetPointer(), initialMean, initialMaximum);
  std::cout << "DeformableMesh: " << sphere->GetNumberOfPoints() << " vertices, " << filter->GetCurrentIteration()
            << " iterations; distance to the true ellipsoid: mean " << initialMean << " -> " << meanDistance
            << " voxel, max " << initialMaximum << " -> " << maximumDistance << " voxel" << std::endl;

  auto writer = itk::MeshFileWriter<MeshType>::New();
  writer->SetInput(filter->GetOutput());
  writer->SetFileName(output);
  try
  {
    writer->Update();
  }
  catch (const itk::ExceptionObject & e)
  {
    std::cerr << "DeformableMesh: cannot write " << output << ": " << e.GetDescription() << std::endl;
    return EXIT_FAILURE;
  }
  std::cout << "Wrote " << output << std::endl;

  if (meanDistance > 0.15 || maximumDistance > 0.5)
  {
    std::cerr << "DeformableMesh: the mesh did not reach the ellipsoid" << std::endl;
    return EXIT_FAILURE;
  }
  return EXIT_SUCCESS;
}
