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

// A program of a downstream project, built against the installed module: a
// sphere of radius 9 pulled onto a 32^3 binary ellipsoid of radii (11, 9, 10);
// fails unless the mesh ends within half a voxel of it on average. With the
// VTK module, the result also goes through the ITK to VTK bridge, which must
// keep every point.

#include "itkDeformableMeshFilter.h"
#include "itkEllipsoidPhantom.h"
#include "itkExternalForceImageFilter.h"
#include "itkMesh.h"

#ifdef EDM_DOWNSTREAM_VTK
#  include "edmMeshBridge.h"
#  include "vtkPolyData.h"
#endif

#include <cstdlib>
#include <iostream>

int
main()
{
  constexpr unsigned int Dimension = 3;
  using ImageType = itk::Image<unsigned char, Dimension>;
  using ForceImageType = itk::Image<itk::CovariantVector<float, Dimension>, Dimension>;
  using MeshType = itk::Mesh<float, Dimension>;

  ImageType::SizeType size;
  size.Fill(32);
  ImageType::SpacingType spacing;
  spacing.Fill(1.0);
  ImageType::PointType origin;
  origin.Fill(0.0);
  itk::EllipsoidPhantom::PointType center;
  center.Fill(15.5);
  itk::EllipsoidPhantom::VectorType radii;
  radii[0] = 11.0;
  radii[1] = 9.0;
  radii[2] = 10.0;
  const itk::EllipsoidPhantom ellipsoid(center, radii);
  const auto image = ellipsoid.MakeImage<ImageType>(size, spacing, origin, ImageType::DirectionType::GetIdentity());

  auto forces = itk::ExternalForceImageFilter<ImageType, ForceImageType>::New();
  forces->SetInput(image);
  forces->SetSigma(1.0);

  MeshType::PointType meshCenter;
  meshCenter.CastFrom(center);
  const auto sphere = itk::MakeSphereMesh<MeshType>(meshCenter, 9.0, 3);

  auto filter = itk::DeformableMeshFilter<MeshType, ForceImageType>::New();
  filter->SetInput(sphere);
  filter->SetForceImage(forces->GetOutput());
  filter->SetScaleFactor(0.5);
  filter->SetNumberOfIterations(300);
  try
  {
    filter->Update();
  }
  catch (const itk::ExceptionObject & e)
  {
    std::cerr << "edmDownstream: " << e.GetDescription() << std::endl;
    return EXIT_FAILURE;
  }

  double meanDistance = 0.0;
  double maximumDistance = 0.0;
  ellipsoid.MeasureDistance(filter->GetOutput(), meanDistance, maximumDistance);
  std::cout << "edmDownstream: " << sphere->GetNumberOfPoints() << " vertices, mean distance " << meanDistance
            << " voxel, max " << maximumDistance << " voxel" << std::endl;
  if (meanDistance > 0.5)
  {
    std::cerr << "edmDownstream: the mesh did not reach the ellipsoid" << std::endl;
    return EXIT_FAILURE;
  }

#ifdef EDM_DOWNSTREAM_VTK
  const vtkSmartPointer<vtkPolyData> polyData = edm::MeshToPolyData(filter->GetOutput());
  std::cout << "edmDownstream: vtkPolyData with " << polyData->GetNumberOfPoints() << " points, "
            << polyData->GetNumberOfPolys() << " triangles" << std::endl;
  if (polyData->GetNumberOfPoints() != static_cast<vtkIdType>(sphere->GetNumberOfPoints()))
  {
    std::cerr << "edmDownstream: the bridge lost points" << std::endl;
    return EXIT_FAILURE;
  }
#endif
  return EXIT_SUCCESS;
}
