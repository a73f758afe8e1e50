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

// The seed's IterativeWarp example: a point cloud under Brownian motion.
// Usage: IterativeWarp [output.vtk] [iterations] [stepLength]
// Writes the cloud after the walk and checks that the root mean square
// displacement is sqrt(iterations) * stepLength (within 5%).

#include "itkBrownianMeshFilter.h"
#include "itkMesh.h"
#include "itkMeshFileWriter.h"

#include <cmath>
#include <cstdlib>
#include <iostream>
#include <random>

int
main(int argc, char * argv[])
{
  const std::string  output = argc > 1 ? argv[1] : "IterativeWarp.vtk";
  const unsigned int iterations = argc > 2 ? static_cast<unsigned int>(std::atoi(argv[2])) : 100;
  const double       stepLength = argc > 3 ? std::atof(argv[3]) : 0.1;

  using MeshType = itk::Mesh<float, 3>;
  using PointType = MeshType::PointType;

  // A cloud of 5000 points uniformly distributed in a ball of radius 10.
  auto                                   cloud = MeshType::New();
  std::mt19937                           generator(2024);
  std::uniform_real_distribution<double> uniform(-10.0, 10.0);
  for (MeshType::PointIdentifier id = 0; id < 5000;)
  {
    PointType p;
    for (unsigned int k = 0; k < 3; ++k)
    {
      p[k] = uniform(generator);
    }
    if (p.EuclideanDistanceTo(PointType(0.0)) <= 10.0)
    {
      cloud->SetPoint(id++, p);
    }
  }

  using FilterType = itk::BrownianMeshFilter<MeshType>;
  auto filter = FilterType::New();
  filter->SetInput(cloud);
  filter->SetStepLength(stepLength);
  filter->SetSeed(1);
  // The seed's render loop: one more iteration per update, never from zero.
  filter->IterateFromZeroOff();
  for (unsigned int n = 1; n <= iterations; ++n)
  {
    filter->SetNumberOfIterations(n);
    filter->Update();
  }

  double sumSquared = 0.0;
  for (MeshType::PointIdentifier id = 0; id < cloud->GetNumberOfPoints(); ++id)
  {
    sumSquared += filter->GetOutput()->GetPoint(id).SquaredEuclideanDistanceTo(cloud->GetPoint(id));
  }
  const double rms = std::sqrt(sumSquared / cloud->GetNumberOfPoints());
  const double expected = std::sqrt(static_cast<double>(iterations)) * stepLength;
  std::cout << "IterativeWarp: " << cloud->GetNumberOfPoints() << " points, " << filter->GetCurrentIteration()
            << " iterations, RMS displacement " << rms << " (expected " << expected << ")" << std::endl;

  auto writer = itk::MeshFileWriter<MeshType>::New();
  writer->SetInput(filter->GetOutput());
  writer->SetFileName(output);
  try
  {
    writer->Update();
  }
  catch (const itk::ExceptionObject & e)
  {
    std::cerr << "IterativeWarp: cannot write " << output << ": " << e.GetDescription() << std::endl;
    return EXIT_FAILURE;
  }
  std::cout << "Wrote " << output << std::endl;

  if (filter->GetCurrentIteration() != iterations || std::abs(rms - expected) > 0.05 * expected)
  {
    std::cerr << "IterativeWarp: unexpected displacement" << std::endl;
    return EXIT_FAILURE;
  }
  return EXIT_SUCCESS;
}
